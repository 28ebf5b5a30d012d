# The same case with 1 and 2 OpenMP threads: outputs agree to round-off (`caplab compare
# --tolerance 1e-12`; it also prints whether they are bit for bit identical).
#   CAPLAB, ARGS (the arguments of `caplab run` after the case, case file first), OUT (scratch)
file(REMOVE_RECURSE ${OUT})
foreach(n 1 2)
  execute_process(COMMAND ${CAPLAB} run ${ARGS} --threads ${n} --out ${OUT}/threads${n} RESULT_VARIABLE rc
                  OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "the run with ${n} threads failed with ${rc}:\n${out}${err}")
  endif()
endforeach()
execute_process(COMMAND ${CAPLAB} compare ${OUT}/threads1 ${OUT}/threads2 --tolerance 1e-12 RESULT_VARIABLE rc
                OUTPUT_VARIABLE out ERROR_VARIABLE err)
message("${out}${err}")
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "1 and 2 threads disagree beyond round-off")
endif()
