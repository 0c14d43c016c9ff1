# ctest: the compiled part's explicit instantiation declarations (the
# "extern template ...;" statements of include/bireg/regression/
# precompiled.hpp and include/bireg/statistics/precompiled/*.hpp) and its
# definitions (the "template ...;" statements of src/precompiled/*.cpp) are
# the same list, statement for statement, whitespace aside.
#
#   cmake -DROOT=<bireg checkout> -P check_lists.cmake

# statements(<out> <keyword regex> <files...>): the statements, whitespace
# collapsed, sorted.
function(statements out keyword)
  set(found)
  foreach(file IN LISTS ARGN)
    file(READ ${file} text)
    string(REGEX REPLACE "//[^\n]*" "" text "${text}")   # comments
    string(REGEX REPLACE "[ \t\r\n]+" " " text "${text}")
    string(REPLACE ";" "@SEMICOLON@" text "${text}")
    string(REGEX MATCHALL "${keyword} [^@]*@SEMICOLON@" matches "${text}")
    foreach(statement IN LISTS matches)
      string(REGEX REPLACE "^${keyword} " "" statement "${statement}")
      string(REPLACE "( " "(" statement "${statement}")
      list(APPEND found "${statement}")
    endforeach()
  endforeach()
  list(SORT found)
  set(${out} "${found}" PARENT_SCOPE)
endfunction()

file(GLOB declaring ${ROOT}/include/bireg/regression/precompiled.hpp
  ${ROOT}/include/bireg/statistics/precompiled/*.hpp)
file(GLOB defining ${ROOT}/src/precompiled/*.cpp)
statements(declared "extern template" ${declaring})
statements(defined "template" ${defining})
list(LENGTH declared n_declared)
list(LENGTH defined n_defined)
if(n_declared EQUAL 0)
  message(FATAL_ERROR "no extern template declarations found under ${ROOT}/include")
endif()
set(missing ${declared})
list(REMOVE_ITEM missing ${defined})
set(extra ${defined})
list(REMOVE_ITEM extra ${declared})
if(missing OR extra OR NOT n_declared EQUAL n_defined)
  string(REPLACE "@SEMICOLON@" ";\n  " missing "${missing}")
  string(REPLACE "@SEMICOLON@" ";\n  " extra "${extra}")
  message(FATAL_ERROR "compiled part: ${n_declared} declarations, ${n_defined} definitions\n"
    "declared, never defined:\n  ${missing}\ndefined, never declared:\n  ${extra}")
endif()
message(STATUS "compiled part: ${n_declared} instantiations declared and defined")
