# Installs the build tree into a fresh prefix, then configures, builds and runs tests/consumer (C++,
# cellrt::cellrt) and tests/consumer_c (C99, cellrt::cellrt_c; without TBB or CUDA to find) against it,
# as users would.
# Arguments: SOURCE, BUILD, WORK.
file(REMOVE_RECURSE ${WORK})
execute_process(COMMAND ${CMAKE_COMMAND} --install ${BUILD} --prefix ${WORK}/prefix RESULT_VARIABLE rc OUTPUT_QUIET)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "cmake --install failed")
endif()
# The C project is not made to find what only the C++ library needs (TBB stands for them all).
set(consumer_options "")
set(consumer_c_options -DCMAKE_DISABLE_FIND_PACKAGE_TBB=ON -DCMAKE_DISABLE_FIND_PACKAGE_CUDAToolkit=ON)
foreach(project consumer consumer_c)
  execute_process(COMMAND ${CMAKE_COMMAND} -S ${SOURCE}/tests/${project} -B ${WORK}/${project} -G Ninja
                          -DCMAKE_PREFIX_PATH=${WORK}/prefix ${${project}_options} RESULT_VARIABLE rc)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "configuring ${project} with find_package(cellrt) failed")
  endif()
  execute_process(COMMAND ${CMAKE_COMMAND} --build ${WORK}/${project} RESULT_VARIABLE rc)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "building ${project} against the installed cellrt failed")
  endif()
endforeach()
foreach(program consumer/app consumer_c/app_c)
  execute_process(COMMAND ${WORK}/${program} ${WORK}/${program}.png RESULT_VARIABLE rc)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "the user's program ${program} did not hit the scene or write its image")
  endif()
endforeach()
