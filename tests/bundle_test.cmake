# tools/bundle.sh end to end: the bundle holds the programs and the libraries they need beyond the C
# and C++ runtimes, its `run` starts a program with them, and an existing folder is never replaced.
# Arguments: SOURCE, BUILD, WORK, and WITH_MPI (whether this build makes the MPI programs).
file(REMOVE_RECURSE ${WORK})
file(MAKE_DIRECTORY ${WORK})
set(ENV{CELLRT_BUILD} ${BUILD})
execute_process(COMMAND ${SOURCE}/tools/bundle.sh ${WORK}/bundle OUTPUT_VARIABLE out ERROR_VARIABLE err RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "tools/bundle.sh failed (${rc}): ${out}${err}")
endif()
# With the MPI programs where they were built, and mpirun with them.
set(programs cellrt cellrt_scaling cellrt_bench)
if(WITH_MPI)
  list(APPEND programs cellrt-mpi cellrt_bench-mpi cellrt_scaling-mpi mpirun orted)
endif()
foreach(program ${programs})
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
foreach(program ${programs})
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

# The bundle's mpirun runs its cellrt-mpi: a frame over 2 ranks, the plain program's bytes. Where this
# machine allows a private mount namespace (root), the installed Open MPI's components, help texts,
# settings and PMIx are covered by an empty folder there, so that only the bundle's can be found.
# Sanitized builds have no MPI programs (CMakeLists.txt), so this runs in the Release stage.
if(WITH_MPI)
  set(frame builtin:city?tris=300 --size 32x24 -o)
  execute_process(COMMAND ${WORK}/bundle/run cellrt render ${frame} ${WORK}/plain.pfm RESULT_VARIABLE rc)
  file(WRITE ${WORK}/hidden.sh [=[
set -e
mkdir -p "$EMPTY"
dirs="$(ompi_info --path all --parsable | sed -n 's/^path:\(pkglibdir\|pkgdatadir\|sysconfdir\)://p' | sort -u)"
pmix="$(ompi_info --config --parsable | grep -o "'--with-pmix=[^']*'" | sed "s/'--with-pmix=\(.*\)'/\1/")"
for d in $dirs $pmix; do mount --bind "$EMPTY" "$d"; done
exec "$@"
]=])
  set(mpirun ${WORK}/bundle/run mpirun --allow-run-as-root --oversubscribe -np 2 cellrt-mpi render ${frame} ${WORK}/mpi.pfm)
  execute_process(COMMAND unshare -m true RESULT_VARIABLE private OUTPUT_QUIET ERROR_QUIET)
  if(private EQUAL 0)
    execute_process(COMMAND ${CMAKE_COMMAND} -E env EMPTY=${WORK}/empty unshare -m sh ${WORK}/hidden.sh ${mpirun}
                    RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  else()
    message(STATUS "no private mount namespace here: the bundle's mpirun runs beside the installed Open MPI")
    execute_process(COMMAND ${mpirun} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  endif()
  file(READ ${WORK}/plain.pfm plain HEX)
  if(EXISTS ${WORK}/mpi.pfm)
    file(READ ${WORK}/mpi.pfm mpi HEX)
  endif()
  if(NOT rc EQUAL 0 OR NOT plain STREQUAL mpi)
    message(FATAL_ERROR "the bundle's mpirun with cellrt-mpi failed (${rc}) or drew another frame: ${out}${err}")
  endif()
endif()

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
