# ctest fuzz_scenario: runs the fuzzer over the seed corpus with a fixed seed, a run count and a
# time cap. New inputs go to WORK/corpus and reproducers to WORK/, never into the source tree.
file(REMOVE_RECURSE ${WORK})
file(MAKE_DIRECTORY ${WORK}/corpus)
execute_process(COMMAND ${FUZZER} -runs=${RUNS} -max_total_time=${SECONDS} -seed=1 -timeout=10 -rss_limit_mb=2048
                        -print_final_stats=1 -dict=${DICT} -artifact_prefix=${WORK}/ ${WORK}/corpus ${CORPUS}
                RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "fuzz_scenario failed (exit ${rc}). The reproducer is in ${WORK}/: replay it with "
                      "`${FUZZER} <file>`, fix src/io/scenario.cpp or params.cpp, and add the file to tests/fuzz/corpus/.")
endif()
