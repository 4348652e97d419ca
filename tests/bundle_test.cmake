# tools/bundle.sh end to end: the bundle holds the programs and the libraries they need beyond the C
# and C++ runtimes, its `run` starts a program with them, and an existing folder is never replaced.
# Arguments: SOURCE, BUILD, WORK.
file(REMOVE_RECURSE ${WORK})
file(MAKE_DIRECTORY ${WORK})
set(ENV{CELLRT_BUILD} ${BUILD})
execute_process(COMMAND ${SOURCE}/tools/bundle.sh ${WORK}/bundle OUTPUT_VARIABLE out ERROR_VARIABLE err RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "tools/bundle.sh failed (${rc}): ${out}${err}")
endif()
foreach(program cellrt cellrt_scaling cellrt_bench)
  if(NOT EXISTS ${WORK}/bundle/bin/${program})
    message(FATAL_ERROR "the bundle lacks ${program}")
  endif()
endforeach()
file(GLOB libs ${WORK}/bundle/lib/*)
foreach(lib ${libs})
  if(lib MATCHES "/(libc|libm|libstdc\\+\\+|libgcc_s|ld-linux[^/]*)\\.so")
    message(FATAL_ERROR "the bundle carries a runtime library the other machine must provide: ${lib}")
  endif()
endforeach()

# `run` starts a bundled program ...
execute_process(COMMAND ${WORK}/bundle/run cellrt info builtin:city?tris=300 OUTPUT_VARIABLE out RESULT_VARIABLE rc)
string(FIND "${out}" "triangles" at)
if(NOT rc EQUAL 0 OR at EQUAL -1)
  message(FATAL_ERROR "bundle/run cellrt info failed (${rc}): ${out}")
endif()
# ... and with the bundle's library folder on the path (as `run` sets it), every library the programs
# load is the bundle's or a runtime one.
foreach(program cellrt cellrt_scaling cellrt_bench)
  execute_process(COMMAND ${CMAKE_COMMAND} -E env LD_LIBRARY_PATH=${WORK}/bundle/lib ldd ${WORK}/bundle/bin/${program}
                  OUTPUT_VARIABLE deps RESULT_VARIABLE rc)
  string(REGEX MATCHALL "=> /[^ ]+" resolved "${deps}")
  foreach(r ${resolved})
    string(REPLACE "=> " "" lib "${r}")
    if(NOT lib MATCHES "^${WORK}/bundle/lib/" AND NOT lib MATCHES "/(libc|libm|libstdc\\+\\+|libgcc_s|ld-linux[^/]*)\\.so")
      message(FATAL_ERROR "${program} from the bundle loads ${lib} from outside it")
    endif()
  endforeach()
  string(FIND "${deps}" "not found" missing)
  if(NOT missing EQUAL -1)
    message(FATAL_ERROR "${program} from the bundle misses a library:\n${deps}")
  endif()
endforeach()

execute_process(COMMAND ${WORK}/bundle/run no_such_program RESULT_VARIABLE rc ERROR_VARIABLE err)
if(rc EQUAL 0)
  message(FATAL_ERROR "bundle/run accepted a program it does not hold")
endif()

# A second bundle into the same folder is refused and leaves the first as it was.
file(WRITE ${WORK}/bundle/mine.txt "the user's")
execute_process(COMMAND ${SOURCE}/tools/bundle.sh ${WORK}/bundle RESULT_VARIABLE rc ERROR_VARIABLE err)
file(READ ${WORK}/bundle/mine.txt kept)
if(rc EQUAL 0 OR NOT kept STREQUAL "the user's")
  message(FATAL_ERROR "tools/bundle.sh replaced an existing folder (${rc}): ${err}")
endif()
