# Self-test of check_include_layers.cmake: runs it on scratch trees, one
# clean and several with a deliberate violation each, and checks that it
# passes the clean one and fails each bad one with the expected message (so
# that a checker that fails on everything, or for another reason, fails
# this test).
#
#   cmake -DCHECKER=<check_include_layers.cmake> -DWORK_DIR=<scratch> -P selftest.cmake
file(REMOVE_RECURSE "${WORK_DIR}")

# write(<tree> <path under bireg/> <lines>...)
function(write tree path)
  string(REPLACE ";" "\n" text "${ARGN}")
  file(WRITE "${WORK_DIR}/${tree}/bireg/${path}" "${text}\n")
endfunction()

set(failures "")
# expect(<tree> pass|fail <substring>...)
function(expect tree outcome)
  execute_process(COMMAND ${CMAKE_COMMAND} -DROOT=${WORK_DIR}/${tree} -P ${CHECKER}
    RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  set(all "${out}${err}")
  # FATAL_ERROR text is reflowed; compare with whitespace runs collapsed.
  string(REGEX REPLACE "[ \t\n]+" " " flat "${all}")
  if(outcome STREQUAL "pass" AND NOT rc EQUAL 0)
    set(failures "${failures}tree '${tree}' should pass, checker failed:\n${all}\n" PARENT_SCOPE)
    return()
  endif()
  if(outcome STREQUAL "fail" AND rc EQUAL 0)
    set(failures "${failures}tree '${tree}' should fail, checker passed:\n${all}\n" PARENT_SCOPE)
    return()
  endif()
  foreach(needle IN LISTS ARGN)
    string(FIND "${flat}" "${needle}" at)
    if(at EQUAL -1)
      set(failures "${failures}tree '${tree}': output lacks \"${needle}\":\n${all}\n" PARENT_SCOPE)
      return()
    endif()
  endforeach()
  message(STATUS "tree '${tree}': ${outcome}ed as expected")
endfunction()

# A clean tree using every layer and both side entries; with lines that a
# naive reader would trip on (a commented-out include of a later layer, an
# unbalanced bracket, a line continuation).
foreach(tree good upward unknown testing_io includes_side)
  write(${tree} math/a.hpp "#pragma once" "// #include \"bireg/io/f.hpp\" (a comment)"
    "int a[3" "#define A_MACRO \\" "  1")
  write(${tree} groups/g.hpp "#pragma once" "#include \"bireg/math/a.hpp\""
    "#include <bireg/version.hpp>")
  write(${tree} concept.hpp "#include \"bireg/groups/g.hpp\"")
  write(${tree} geodesic.hpp "#include \"bireg/concept.hpp\"")
  write(${tree} regression/step.hpp "#include \"bireg/geodesic.hpp\"")
  write(${tree} regression.hpp "#include \"bireg/regression/step.hpp\"")
  write(${tree} statistics/inference/mean.hpp "  #  include \"bireg/regression.hpp\"")
  write(${tree} io/f.hpp "#include \"bireg/groups/g.hpp\"")
  write(${tree} testing/laws.hpp "#include \"bireg/statistics/inference/mean.hpp\""
    "#include \"bireg/testing/more.hpp\"")
  write(${tree} testing/more.hpp "#include \"bireg/concept.hpp\"")
  write(${tree} bireg.hpp "#include \"bireg/io/f.hpp\"" "#include \"bireg/testing/laws.hpp\"")
endforeach()
expect(good pass "all within the layers")

# An earlier layer including a later one, reported with its line number.
write(upward math/bad.hpp "#pragma once" "int b[2" "#include \"bireg/groups/g.hpp\"")
expect(upward fail
  "bireg/math/bad.hpp:3: includes bireg/groups/g.hpp: layer [math/ version.hpp] (0) may not include the later layer [groups/] (1)")

# A directory the table does not know (e.g. the old core/).
write(unknown core/concept.hpp "#pragma once")
write(unknown geodesic.hpp "#include \"bireg/core/concept.hpp\"")
expect(unknown fail "header in no layer: bireg/core/concept.hpp"
  "bireg/geodesic.hpp:1: includes bireg/core/concept.hpp, a header in no layer")

# testing/ must not use io/.
write(testing_io testing/more.hpp "#include \"bireg/io/f.hpp\"")
expect(testing_io fail "bireg/testing/more.hpp:1: includes bireg/io/f.hpp: [testing/] may not include [io/]")

# A layered header must not include testing/ or the umbrella.
write(includes_side regression.hpp "#include \"bireg/regression/step.hpp\""
  "#include \"bireg/testing/laws.hpp\"")
write(includes_side io/f.hpp "#include <bireg/bireg.hpp>")
# Nor testing/ the umbrella (which includes io/).
write(includes_side testing/more.hpp "#include \"bireg/bireg.hpp\"")
expect(includes_side fail
  "bireg/regression.hpp:2: includes bireg/testing/laws.hpp: [testing/] is outside the layers"
  "bireg/io/f.hpp:1: includes bireg/bireg.hpp: [bireg.hpp] is outside the layers"
  "bireg/testing/more.hpp:1: includes bireg/bireg.hpp: [bireg.hpp] is outside the layers")

if(failures)
  message(FATAL_ERROR "include-graph checker self-test:\n${failures}")
endif()
