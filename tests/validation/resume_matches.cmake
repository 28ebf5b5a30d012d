# A run killed (SIGKILL, right after a checkpoint, as a power cut would) or stopped (SIGTERM, as
# a batch system or Ctrl-C would) and resumed with `caplab run --resume` must end with outputs
# identical, bit for bit, to an uninterrupted run.
#   CAPLAB   the caplab binary
#   ARGS     the arguments of `caplab run` after the case (case file first), as a list
#   OUT      a scratch directory (replaced)
#   KILLS    after how many checkpoints each process kills itself, e.g. "2,1": the first run is
#            killed after its 2nd checkpoint, the first resume after its 1st, the next resume
#            runs to the end
#   SIGTERM_AT  (instead of KILLS) the step during which the run receives SIGTERM: it must
#            write a checkpoint, finish "failed" with an "interrupted" entry, and resume
file(REMOVE_RECURSE ${OUT})
string(REPLACE "," ";" KILLS "${KILLS}")
function(caplab_run label expect_killed)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  message("${label}: exit ${rc}")
  if(expect_killed AND rc EQUAL 0)
    message(FATAL_ERROR "${label} was not killed:\n${out}${err}")
  elseif(NOT expect_killed AND NOT rc EQUAL 0)
    message(FATAL_ERROR "${label} failed with ${rc}:\n${out}${err}")
  endif()
endfunction()

caplab_run("uninterrupted run" FALSE ${CAPLAB} run ${ARGS} --out ${OUT}/uninterrupted)
if(DEFINED SIGTERM_AT)
  caplab_run("run stopped by SIGTERM at step ${SIGTERM_AT}" TRUE
             ${CMAKE_COMMAND} -E env CAPLAB_TEST_SIGTERM_AT_STEP=${SIGTERM_AT} ${CAPLAB} run ${ARGS} --out ${OUT}/resumed)
  file(READ ${OUT}/resumed/manifest.json manifest)
  if(NOT manifest MATCHES "\"status\": \"failed\"" OR NOT manifest MATCHES "\"signal\": \"SIGTERM\""
     OR NOT manifest MATCHES "\"step\": ${SIGTERM_AT}" OR NOT EXISTS ${OUT}/resumed/checkpoint.h5
     OR EXISTS ${OUT}/resumed/series.h5)
    message(FATAL_ERROR "a stopped run must keep a checkpoint, no finished series, and say it was interrupted:\n${manifest}")
  endif()
  execute_process(COMMAND ${CAPLAB} list ${OUT} OUTPUT_VARIABLE listed ERROR_VARIABLE err)
  if(NOT listed MATCHES "stopped by SIGTERM after step ${SIGTERM_AT} \\(resumable: caplab run --resume")
    message(FATAL_ERROR "caplab list must show the stopped run and how to resume it:\n${listed}${err}")
  endif()
  set(later "")
else()
  list(GET KILLS 0 first)
  caplab_run("run killed after checkpoint ${first}" TRUE
             ${CMAKE_COMMAND} -E env CAPLAB_TEST_KILL_AFTER_CHECKPOINT=${first} ${CAPLAB} run ${ARGS} --out ${OUT}/resumed)
  file(READ ${OUT}/resumed/manifest.json manifest)
  if(NOT manifest MATCHES "\"status\": \"running\"")
    message(FATAL_ERROR "a killed run must stay marked running (incomplete):\n${manifest}")
  endif()
  list(SUBLIST KILLS 1 -1 later)
endif()
foreach(k ${later})
  caplab_run("resume killed after checkpoint ${k}" TRUE
             ${CMAKE_COMMAND} -E env CAPLAB_TEST_KILL_AFTER_CHECKPOINT=${k} ${CAPLAB} run --resume ${OUT}/resumed)
endforeach()
caplab_run("resume to the end" FALSE ${CAPLAB} run --resume ${OUT}/resumed)
execute_process(COMMAND ${CAPLAB} compare ${OUT}/uninterrupted ${OUT}/resumed RESULT_VARIABLE rc OUTPUT_VARIABLE out
                ERROR_VARIABLE err)
message("${out}${err}")
if(NOT rc EQUAL 0 OR NOT out MATCHES "identical")
  message(FATAL_ERROR "the resumed run differs from the uninterrupted one")
endif()
