# Runs one libFuzzer target for SECONDS on a fresh work folder seeded from SEEDS (the committed
# corpus is never written to). Fails when the fuzzer finds a crash, leak, timeout or OOM, whose
# reproducer libFuzzer writes to ${WORK}-artifacts: kept from run to run (emptying it with the work
# folder lost the only copy of a failure when the test was rerun), so it must be deleted by hand.
file(REMOVE_RECURSE ${WORK})
file(MAKE_DIRECTORY ${WORK}/new ${WORK}-artifacts)
execute_process(
  COMMAND ${FUZZER} ${WORK}/new ${SEEDS} -max_total_time=${SECONDS} -timeout=10 -rss_limit_mb=2048
          -max_len=65536 -artifact_prefix=${WORK}-artifacts/ -print_final_stats=1
  RESULT_VARIABLE rc
  OUTPUT_VARIABLE out ERROR_VARIABLE err)
string(REGEX MATCH "stat::number_of_executed_units: *[0-9]+" runs "${err}")
message(STATUS "${FUZZER}: ${runs}")
if(NOT rc EQUAL 0)
  string(LENGTH "${err}" n)
  if(n GREATER 6000)
    math(EXPR start "${n} - 6000")
    string(SUBSTRING "${err}" ${start} 6000 err)
  endif()
  message(FATAL_ERROR "fuzzer failed (exit ${rc}); reproducer saved under ${WORK}-artifacts/\n${err}")
endif()
