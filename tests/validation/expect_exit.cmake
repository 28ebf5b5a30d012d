# Runs CMD with ARGS and fails unless it exits with EXPECTED_EXIT and its output contains
# EXPECTED_TEXT (so a check that must fail is seen failing for the right reason). With ABSENT
# set, that path is removed first and must not exist afterwards (a refused run leaves nothing).
if(DEFINED ABSENT)
  file(REMOVE_RECURSE "${ABSENT}")
endif()
execute_process(COMMAND ${CMD} ${ARGS} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
message("${out}${err}")
if(NOT rc EQUAL EXPECTED_EXIT)
  message(FATAL_ERROR "expected exit code ${EXPECTED_EXIT}, got ${rc}")
endif()
string(FIND "${out}${err}" "${EXPECTED_TEXT}" pos)
if(pos EQUAL -1)
  message(FATAL_ERROR "output does not mention '${EXPECTED_TEXT}'")
endif()
if(DEFINED ABSENT AND EXISTS "${ABSENT}")
  message(FATAL_ERROR "the command left '${ABSENT}' behind")
endif()
