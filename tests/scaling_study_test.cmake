# The scaling study end to end, on a small scene: cellrt_scaling's tables and JSON for both dispatch
# modes at 1 and 2 workers (AO shading, which every row records), then bench/scaling_tables.py and bench/plot_scaling.py on that JSON, as
# docs/SCALING.md runs them. Arguments: SCALING (the program), PYTHON, SOURCE, WORK.
file(REMOVE_RECURSE ${WORK})
file(MAKE_DIRECTORY ${WORK})
execute_process(
  COMMAND ${SCALING} --scenes builtin:city?tris=3000 --configs kd+auto bih:branched auto --dispatch pull mailbox
          --packets 8 --workers 1 2 --repeats 3 --size 40x24 --shading ao --ao-samples 2
          --json ${WORK}/scaling.json --csv ${WORK}/scaling.csv
  OUTPUT_VARIABLE tables ERROR_VARIABLE log RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "cellrt_scaling failed (${rc}): ${log}")
endif()
foreach(expected "### kd+auto, mailbox dispatch, 8x8 packets, ao shading, 2 AO rays per hit" "Where the 2 workers' time went" "| city |")
  string(FIND "${tables}" "${expected}" at)
  if(at EQUAL -1)
    message(FATAL_ERROR "cellrt_scaling's tables lack '${expected}':\n${tables}")
  endif()
endforeach()

# Every point: 3 configurations x 2 dispatch modes x 2 worker counts, each with its schedule's account,
# listed a configuration at a time (their frames were interleaved); `auto`'s with its route.
file(READ ${WORK}/scaling.json json)
string(JSON points LENGTH "${json}")
if(NOT points EQUAL 12)
  message(FATAL_ERROR "expected 12 points, found ${points}")
endif()
set(configs kd+auto bih:branched auto)
foreach(i 0 3 4 7 8 11)
  string(JSON config GET "${json}" ${i} config)
  math(EXPR expected "${i} / 4")
  list(GET configs ${expected} want)
  string(JSON routed ERROR_VARIABLE no_route GET "${json}" ${i} routed)
  set(has_route 0)
  if(no_route STREQUAL "NOTFOUND")
    set(has_route 1)
  endif()
  set(wants_route 0)
  if(want STREQUAL "auto")
    set(wants_route 1)
  endif()
  if(NOT config STREQUAL want OR NOT has_route EQUAL wants_route)
    message(FATAL_ERROR "point ${i} is ${config} (routed: ${routed}), expected ${want}")
  endif()
  if(want STREQUAL "auto" AND NOT routed MATCHES "^closest packets ")
    message(FATAL_ERROR "point ${i}'s route: ${routed}")
  endif()
endforeach()
math(EXPR last "${points} - 1")
foreach(i RANGE ${last})
  string(JSON seconds GET "${json}" ${i} seconds)
  string(JSON busy GET "${json}" ${i} busy_seconds)
  string(JSON started GET "${json}" ${i} started_seconds)
  string(JSON waiting GET "${json}" ${i} waiting_seconds)
  string(JSON rays GET "${json}" ${i} rays)
  string(JSON efficiency GET "${json}" ${i} efficiency)
  string(JSON packet_time GET "${json}" ${i} packet_time_ratio)
  string(JSON workers GET "${json}" ${i} workers)
  string(JSON shading GET "${json}" ${i} shading)
  string(JSON ao_samples GET "${json}" ${i} ao_samples)
  # The time shares are of one round, so that they and the rest make the whole (shares of the parts'
  # medians added up to 1.03): each in [0, 1], and the three leave a rest (between packets) of at
  # least -0.001, the clocks' rounding.
  foreach(share tracing_share waking_share waiting_share)
    string(JSON ${share} GET "${json}" ${i} ${share})
    if(${share} LESS 0 OR ${share} GREATER 1)
      message(FATAL_ERROR "point ${i}: ${share} ${${share}} is not in [0, 1]")
    endif()
  endforeach()
  execute_process(COMMAND ${PYTHON} -c "import sys; sys.exit(0 if ${tracing_share} + ${waking_share} + ${waiting_share} <= 1.001 else 1)"
                  RESULT_VARIABLE over)
  if(NOT over EQUAL 0)
    message(FATAL_ERROR "point ${i}: shares ${tracing_share} + ${waking_share} + ${waiting_share} pass 1")
  endif()
  if(NOT shading STREQUAL "ao" OR NOT ao_samples EQUAL 2)
    message(FATAL_ERROR "point ${i} records shading '${shading}' with ${ao_samples} AO samples, not ao with 2")
  endif()
  if(NOT seconds GREATER 0 OR NOT busy GREATER 0 OR started LESS 0 OR waiting LESS 0 OR NOT rays GREATER 960
     OR NOT efficiency GREATER 0 OR NOT packet_time GREATER 0)
    message(FATAL_ERROR "point ${i} is implausible: ${seconds} s, busy ${busy}, started ${started}, waiting ${waiting}, "
                        "${rays} rays, efficiency ${efficiency}, packet time ratio ${packet_time}")
  endif()
  # Against the fewest workers (1 here), a point of 1 worker is its own reference.
  if(workers EQUAL 1 AND (NOT efficiency EQUAL 1 OR NOT packet_time EQUAL 1))
    message(FATAL_ERROR "point ${i} (1 worker) has efficiency ${efficiency} and packet time ratio ${packet_time}, not 1")
  endif()
endforeach()

file(STRINGS ${WORK}/scaling.csv csv)
list(GET csv 0 header)
list(GET csv 1 row)
if(NOT header MATCHES "^scene,config,dispatch,packet,shading,ao_samples,workers," OR NOT row MATCHES ",8,ao,2,")
  message(FATAL_ERROR "the CSV lacks the shading: ${header}\n${row}")
endif()

# A bad shading is the user's error, under the option's name, before any frame.
execute_process(COMMAND ${SCALING} --shading glossy ERROR_VARIABLE log RESULT_VARIABLE rc)
string(FIND "${log}" "cellrt_scaling: error: --shading: " at)
if(NOT rc EQUAL 1 OR at EQUAL -1)
  message(FATAL_ERROR "cellrt_scaling --shading glossy: ${rc}, ${log}")
endif()

execute_process(COMMAND ${PYTHON} ${SOURCE}/bench/scaling_tables.py ${WORK}/scaling.json
                OUTPUT_VARIABLE table ERROR_VARIABLE log RESULT_VARIABLE rc)
string(FIND "${table}" "| city |" at)
if(NOT rc EQUAL 0 OR at EQUAL -1)
  message(FATAL_ERROR "bench/scaling_tables.py failed (${rc}): ${log}${table}")
endif()
# A table per dispatch mode: keyed without it, the last mode's figures stood for both (2026-12-07).
foreach(mode pull mailbox)
  string(FIND "${table}" "${mode} dispatch," at)
  if(at EQUAL -1)
    message(FATAL_ERROR "bench/scaling_tables.py has no table of ${mode} dispatch: ${table}")
  endif()
endforeach()
execute_process(COMMAND ${PYTHON} ${SOURCE}/bench/plot_scaling.py ${WORK}/scaling.json ${WORK}/plots
                ERROR_VARIABLE log RESULT_VARIABLE rc)
if(NOT rc EQUAL 0 OR NOT EXISTS ${WORK}/plots/scaling_city.png)
  message(FATAL_ERROR "bench/plot_scaling.py failed (${rc}), needs python3-matplotlib: ${log}")
endif()
# A file that is not JSON, or holds no rows, is refused naming it: json's message named no file, and
# an empty list printed nothing with status 0 (2026-12-08).
file(WRITE ${WORK}/cut.json "[{\"scene\":")
file(WRITE ${WORK}/empty.json "[]")
foreach(case "cut.json: not JSON: " "empty.json: holds no rows")
  string(REGEX REPLACE ":.*" "" input "${case}")
  execute_process(COMMAND ${PYTHON} ${SOURCE}/bench/scaling_tables.py ${WORK}/${input}
                  OUTPUT_VARIABLE table ERROR_VARIABLE log RESULT_VARIABLE rc)
  string(FIND "${log}" "scaling_tables: error: ${WORK}/${case}" at)
  if(NOT rc EQUAL 1 OR NOT at EQUAL 0 OR NOT table STREQUAL "")
    message(FATAL_ERROR "bench/scaling_tables.py ${input}: status ${rc}, printed '${table}${log}'")
  endif()
endforeach()
