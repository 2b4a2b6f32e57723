# Runs a tool and checks its exact exit status and what it prints, so that a
# crash (no exit status, or another one) fails the test.
#   -DPROGRAM=<program> -DARGS=<;-separated arguments> -DEXPECTED_EXIT=<n>
#   [-DEXPECTED_MESSAGE=<regex on stderr>] [-DEXPECTED_OUTPUT=<regex on stdout>]
#   [-DMUST_NOT_EXIST=<path>]
execute_process(
  COMMAND "${PROGRAM}" ${ARGS}
  RESULT_VARIABLE exit_status
  OUTPUT_VARIABLE out
  ERROR_VARIABLE err)
if(NOT exit_status STREQUAL "${EXPECTED_EXIT}")
  message(FATAL_ERROR "${PROGRAM} exited '${exit_status}', expected ${EXPECTED_EXIT}\n${err}")
endif()
if(DEFINED EXPECTED_MESSAGE AND NOT err MATCHES "${EXPECTED_MESSAGE}")
  message(FATAL_ERROR "stderr does not match '${EXPECTED_MESSAGE}':\n${err}")
endif()
if(DEFINED EXPECTED_OUTPUT AND NOT out MATCHES "${EXPECTED_OUTPUT}")
  message(FATAL_ERROR "stdout does not match '${EXPECTED_OUTPUT}':\n${out}")
endif()
if(DEFINED MUST_NOT_EXIST AND EXISTS "${MUST_NOT_EXIST}")
  message(FATAL_ERROR "a failed run wrote ${MUST_NOT_EXIST}")
endif()
message(STATUS "${PROGRAM} exited ${exit_status} and printed what was expected")
