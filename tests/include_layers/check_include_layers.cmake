# Include-graph check: every header under <ROOT>/bireg may include (with
# #include "bireg/..." or <bireg/...>) only headers of its own layer or an
# earlier one. Run by ctest:
#
#   cmake -DROOT=<dir that holds bireg/> -P check_include_layers.cmake
#
# Exits with an error listing every violation, and every header (including
# or included) that belongs to no layer.

# ---- The layers, earliest first ---------------------------------------------
# One entry per layer; an entry lists its members separated by spaces. A
# member ending in "/" is a directory under bireg/ (with everything below
# it), any other member is a single file under bireg/. A header may include
# headers of its own layer and of earlier layers only.
set(BIREG_LAYERS
  "math/ version.hpp"               # scalar numerics; the generated version header
  "groups/"                         # one header per group
  "concept.hpp"                     # what a group must provide
  "geodesic.hpp spline.hpp"         # the curves: the geodesic, Exp/Log at a point; the spline
  "regression/ regression.hpp spline_regression.hpp"  # the estimators and their facades
  "statistics/"                     # built on the estimator
  "io/"                             # trajectory formats
)
# Headers outside the order: "<members> : <members they must not include>".
# They may include any layered header except those listed (an entry with
# nothing listed may include everything, other side entries too), and no
# layered header may include them.
set(BIREG_SIDE_HEADERS
  "testing/ : io/"                  # test helpers for users (group laws, ...)
  "bireg.hpp :"                     # the umbrella header: everything
)
# -----------------------------------------------------------------------------

if(NOT ROOT)
  message(FATAL_ERROR "usage: cmake -DROOT=<dir holding bireg/> -P ${CMAKE_CURRENT_LIST_FILE}")
endif()
get_filename_component(ROOT "${ROOT}" ABSOLUTE)
if(NOT IS_DIRECTORY "${ROOT}/bireg")
  message(FATAL_ERROR "include graph: no directory ${ROOT}/bireg")
endif()

# member_matches(<out> <path relative to bireg/> <member>)
function(member_matches out path member)
  set(${out} FALSE PARENT_SCOPE)
  if(member MATCHES "/$")
    string(LENGTH "${member}" n)
    string(SUBSTRING "${path}" 0 ${n} head)
    if(head STREQUAL member)
      set(${out} TRUE PARENT_SCOPE)
    endif()
  elseif(path STREQUAL member)
    set(${out} TRUE PARENT_SCOPE)
  endif()
endfunction()

# members_match(<out> <path> <space-separated members>)
function(members_match out path members)
  set(${out} FALSE PARENT_SCOPE)
  string(REPLACE " " ";" list "${members}")
  foreach(member IN LISTS list)
    if(member)
      member_matches(hit "${path}" "${member}")
      if(hit)
        set(${out} TRUE PARENT_SCOPE)
        return()
      endif()
    endif()
  endforeach()
endfunction()

# classify(<path>): sets kind (layer, side or none), rank (the layer's index),
# label (its entry's members) and forbidden (a side header's exclusions).
macro(classify path)
  set(kind none)
  set(rank -1)
  set(label "")
  set(forbidden "")
  set(index 0)
  foreach(entry IN LISTS BIREG_LAYERS)
    members_match(hit "${path}" "${entry}")
    if(hit AND kind STREQUAL "none")
      set(kind layer)
      set(rank ${index})
      set(label "${entry}")
    endif()
    math(EXPR index "${index} + 1")
  endforeach()
  foreach(entry IN LISTS BIREG_SIDE_HEADERS)
    string(FIND "${entry}" ":" colon)
    string(SUBSTRING "${entry}" 0 ${colon} members)
    math(EXPR after "${colon} + 1")
    string(SUBSTRING "${entry}" ${after} -1 excluded)
    string(STRIP "${members}" members)
    string(STRIP "${excluded}" excluded)
    members_match(hit "${path}" "${members}")
    if(hit AND kind STREQUAL "none")
      set(kind side)
      set(label "${members}")
      set(forbidden "${excluded}")
    endif()
  endforeach()
endmacro()

file(GLOB_RECURSE headers RELATIVE "${ROOT}/bireg" LIST_DIRECTORIES false
  "${ROOT}/bireg/*.hpp" "${ROOT}/bireg/*.h" "${ROOT}/bireg/*.hh" "${ROOT}/bireg/*.ipp"
  "${ROOT}/bireg/*.inl" "${ROOT}/bireg/*.tpp")
list(SORT headers)

set(problems "")
set(n_headers 0)
set(n_includes 0)
foreach(header IN LISTS headers)
  math(EXPR n_headers "${n_headers} + 1")
  classify("${header}")
  if(kind STREQUAL "none")
    string(APPEND problems "  header in no layer: bireg/${header}\n")
    continue()
  endif()
  set(from_kind ${kind})
  set(from_rank ${rank})
  set(from_label "${label}")
  set(from_forbidden "${forbidden}")

  # One list element per line (for line numbers). Characters that are
  # special in CMake lists (; \ [ ]) cannot matter on an #include line:
  # replace them so that they cannot merge or split lines.
  file(READ "${ROOT}/bireg/${header}" text)
  string(REPLACE "\\" "/" text "${text}")
  string(REPLACE ";" "," text "${text}")
  string(REPLACE "[" "(" text "${text}")
  string(REPLACE "]" ")" text "${text}")
  string(REPLACE "\n" ";" all_lines "${text}")
  set(line_number 0)
  foreach(line IN LISTS all_lines)
    math(EXPR line_number "${line_number} + 1")
    if(NOT line MATCHES "^[ \t]*#[ \t]*include[ \t]*[<\"]bireg/([^\">]+)[\">]")
      continue()
    endif()
    set(target "${CMAKE_MATCH_1}")
    math(EXPR n_includes "${n_includes} + 1")
    set(where "bireg/${header}:${line_number}: includes bireg/${target}")
    classify("${target}")
    if(kind STREQUAL "none")
      string(APPEND problems "  ${where}, a header in no layer\n")
    elseif(kind STREQUAL "side")
      # Allowed within one side entry, and from a side entry with no
      # exclusions (the umbrella).
      if(NOT (from_kind STREQUAL "side" AND
              (from_label STREQUAL label OR from_forbidden STREQUAL "")))
        string(APPEND problems
          "  ${where}: [${label}] is outside the layers; no other header may include it\n")
      endif()
    elseif(from_kind STREQUAL "layer")
      if(rank GREATER from_rank)
        string(APPEND problems
          "  ${where}: layer [${from_label}] (${from_rank}) may not include the later layer [${label}] (${rank})\n")
      endif()
    else()  # a side header including a layered one
      members_match(hit "${target}" "${from_forbidden}")
      if(hit)
        string(APPEND problems
          "  ${where}: [${from_label}] may not include [${from_forbidden}]\n")
      endif()
    endif()
  endforeach()
endforeach()

string(REPLACE ";" "\n  " layer_text "${BIREG_LAYERS}")
if(problems)
  message(FATAL_ERROR "include graph: violations under ${ROOT}/bireg\n${problems}"
    "Layers, earliest first (a header may include its own layer and earlier ones):\n"
    "  ${layer_text}\n"
    "(table at the top of ${CMAKE_CURRENT_LIST_FILE})")
endif()
message(STATUS "include graph: ${n_headers} headers, ${n_includes} bireg includes, all within the layers")
