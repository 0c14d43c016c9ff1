# ctest driver: install bireg into a scratch prefix, then build and run the
# consumer project against it (find_package) and against the source tree
# (add_subdirectory). Any failing step fails the test.
file(REMOVE_RECURSE ${WORK_DIR})
file(MAKE_DIRECTORY ${WORK_DIR})

function(run_step)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE result OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT result EQUAL 0)
    message(FATAL_ERROR "step failed (${result}): ${ARGN}\n${out}\n${err}")
  endif()
endfunction()

run_step(${CMAKE_COMMAND} --install ${BIREG_BINARY_DIR} --prefix ${WORK_DIR}/prefix)

foreach(mode find_package subdirectory subdirectory_own_eigen)
  set(build ${WORK_DIR}/build_${mode})
  run_step(${CMAKE_COMMAND} -S ${CONSUMER_SOURCE_DIR} -B ${build} -G ${GENERATOR}
    -DCMAKE_CXX_COMPILER=${CXX_COMPILER}
    -DBIREG_CONSUMER_MODE=${mode}
    -DBIREG_SOURCE_DIR=${BIREG_SOURCE_DIR}
    -DCMAKE_PREFIX_PATH=${WORK_DIR}/prefix
    -DBIREG_CONSUMER_PRECOMPILED=${PRECOMPILED})
  run_step(${CMAKE_COMMAND} --build ${build})
  run_step(${build}/consumer)
  if(PRECOMPILED AND mode STREQUAL "find_package")
    run_step(${build}/consumer_precompiled)
  endif()
  message(STATUS "consumer via ${mode}: ok")
endforeach()
