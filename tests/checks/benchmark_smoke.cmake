# One benchmark executable run once at its smallest size (issue 43: a benchmark that aborts must
# fail CI, not wait for someone to time it). A smoke: no timing is asserted.
#   cmake -DEXE=<benchmark executable> -DFILTER=<--benchmark_filter regex> -DOUT=<json file>
#         [-DNEEDS=<path below the shared data> -DSHARED_DIR=<../shared>] -P benchmark_smoke.cmake
# Every selected benchmark runs one iteration (--benchmark_min_time=0: Google Benchmark 1.7.1,
# Debian 12's, takes the minimum time as seconds and stops after the first iteration that reaches
# it; a benchmark's own Iterations(n) still holds). Fails when the process does not exit 0 (an
# abort, a crash), selects nothing, or a benchmark reports an error (SkipWithError). Without the
# shared data it NEEDS, prints "skipped: ..." and passes as skipped (SKIP_REGULAR_EXPRESSION);
# FITCAL_SHARED_DIR in the environment replaces SHARED_DIR, as the benchmarks read it.

foreach(var EXE FILTER OUT)
  if(NOT DEFINED ${var})
    message(FATAL_ERROR "benchmark_smoke.cmake: -D${var}=... is required")
  endif()
endforeach()
if(NOT "$ENV{FITCAL_SHARED_DIR}" STREQUAL "")
  set(SHARED_DIR "$ENV{FITCAL_SHARED_DIR}")
endif()
if(DEFINED NEEDS AND NOT EXISTS "${SHARED_DIR}/${NEEDS}")
  message(STATUS "skipped: ${SHARED_DIR}/${NEEDS} is absent")
  return()
endif()

file(REMOVE "${OUT}")
execute_process(
  COMMAND "${EXE}" "--benchmark_filter=${FILTER}" --benchmark_min_time=0
          "--benchmark_out=${OUT}" --benchmark_out_format=json
  RESULT_VARIABLE status)
if(NOT status EQUAL 0)
  message(FATAL_ERROR "${EXE} --benchmark_filter=${FILTER}: exit status ${status}")
endif()
if(NOT EXISTS "${OUT}")
  message(FATAL_ERROR "${EXE}: wrote no results to ${OUT}")
endif()
file(READ "${OUT}" json)
if(json STREQUAL "")
  set(count 0)  # the executable prints "Failed to match any benchmarks" and writes nothing
else()
  string(JSON count LENGTH "${json}" benchmarks)
endif()
if(count EQUAL 0)
  message(FATAL_ERROR "${EXE}: the filter '${FILTER}' selects no benchmark")
endif()
math(EXPR last "${count} - 1")
foreach(i RANGE ${last})
  string(JSON name GET "${json}" benchmarks ${i} name)
  string(JSON failed ERROR_VARIABLE absent GET "${json}" benchmarks ${i} error_occurred)
  if(NOT absent AND failed)
    string(JSON why GET "${json}" benchmarks ${i} error_message)
    message(FATAL_ERROR "${EXE}: ${name} failed: ${why}")
  endif()
  message(STATUS "ran ${name}")
endforeach()
