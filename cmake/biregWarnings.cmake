# Warning (and optional sanitizer) flags for bireg's own targets (tests,
# examples, benchmarks). The library target itself carries no flags:
# consumers choose their own.
#
# BIREG_WERROR (option in the top-level CMakeLists.txt, default OFF, ON in
# CI) adds -Werror (/WX).
#
# BIREG_SANITIZE: a -fsanitize= list such as "address,undefined" for the
# tests, examples and tools (the CI sanitizer stage); empty by default.
# bireg_enable_warnings(target NO_SANITIZERS) leaves a target uninstrumented
# (the benchmarks).
set(BIREG_SANITIZE "" CACHE STRING "Sanitizers for bireg's tests and tools, e.g. address,undefined")

function(bireg_enable_warnings target)
  cmake_parse_arguments(PARSE_ARGV 1 option "NO_SANITIZERS" "" "")
  if(BIREG_SANITIZE AND NOT option_NO_SANITIZERS)
    target_compile_options(${target} PRIVATE -fsanitize=${BIREG_SANITIZE} -fno-sanitize-recover=all
      -fno-omit-frame-pointer)
    target_link_options(${target} PRIVATE -fsanitize=${BIREG_SANITIZE})
  endif()
  if(CMAKE_CXX_COMPILER_ID MATCHES "GNU|Clang")
    target_compile_options(${target} PRIVATE -Wall -Wextra -Wpedantic
      $<$<BOOL:${BIREG_WERROR}>:-Werror>)
  elseif(MSVC)
    target_compile_options(${target} PRIVATE /W4 $<$<BOOL:${BIREG_WERROR}>:/WX>)
  endif()
endfunction()
