# ctest driver for one compile-fail test: builds the EXCLUDE_FROM_ALL target
# made from SOURCE and passes only if the build fails AND a static_assert
# failure with the message on SOURCE's "// expect-error: " line appears in
# the compiler's output (another error, e.g. a typo in the test, fails).
#
#   cmake -DBUILD_DIR=<build tree> -DTARGET=<target> -DCONFIG=<config>
#         -DSOURCE=<file.cpp> -P expect_compile_error.cmake
file(STRINGS "${SOURCE}" expect_lines REGEX "^// expect-error: ")
list(LENGTH expect_lines n)
if(NOT n EQUAL 1)
  message(FATAL_ERROR "${SOURCE}: needs exactly one '// expect-error: <message>' line")
endif()
string(REGEX REPLACE "^// expect-error: " "" expected "${expect_lines}")

execute_process(
  COMMAND ${CMAKE_COMMAND} --build ${BUILD_DIR} --target ${TARGET} --config ${CONFIG}
  RESULT_VARIABLE result OUTPUT_VARIABLE out ERROR_VARIABLE err)
set(output "${out}${err}")
string(ASCII 27 escape)
string(REGEX REPLACE "${escape}\\[[0-9;]*[mK]" "" output "${output}")  # colours

if(result EQUAL 0)
  message(FATAL_ERROR "${SOURCE} compiled, but must fail with\n  ${expected}\n${output}")
endif()
# The message on the static_assert's own line: GCC "static assertion failed:
# <msg>", Clang "static_assert failed due to requirement '...' \"<msg>\"" or
# (Clang 16+) "static assertion failed due to requirement '...': <msg>".
string(REGEX REPLACE "([][\\\\.*+?^$()|])" "\\\\\\1" expected_regex "${expected}")
if(NOT output MATCHES "static.assert[^\n]*failed[^\n]*${expected_regex}")
  message(FATAL_ERROR "${SOURCE} failed to compile, but without the expected "
    "static_assert message\n  ${expected}\ncompiler output:\n${output}")
endif()
message(STATUS "${SOURCE}: fails to compile with \"${expected}\"")
