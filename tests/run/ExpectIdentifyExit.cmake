# Runs identify and checks its exit status and, when a result is expected,
# the status recorded in result.yaml.
#   -DIDENTIFY=<program> -DCONFIG=<beam.yaml> -DOUTPUT_DIR=<dir>
#   -DARGS=<;-separated extra arguments> -DEXPECTED_EXIT=<n>
#   [-DEXPECTED_STATUS=<converged|no_convergence|failure|unidentifiable>]
#   [-DEXPECTED_MESSAGE=<regex on stderr>]
file(REMOVE_RECURSE "${OUTPUT_DIR}")
execute_process(
  COMMAND "${IDENTIFY}" --config "${CONFIG}" --output_dir "${OUTPUT_DIR}" ${ARGS}
  RESULT_VARIABLE exit_status
  OUTPUT_VARIABLE out
  ERROR_VARIABLE err)
if(NOT exit_status EQUAL EXPECTED_EXIT)
  message(FATAL_ERROR "identify exited ${exit_status}, expected ${EXPECTED_EXIT}\n${err}")
endif()
if(DEFINED EXPECTED_MESSAGE AND NOT err MATCHES "${EXPECTED_MESSAGE}")
  message(FATAL_ERROR "stderr does not match '${EXPECTED_MESSAGE}':\n${err}")
endif()
if(DEFINED EXPECTED_STATUS)
  file(READ "${OUTPUT_DIR}/result.yaml" result)
  if(NOT result MATCHES "(^|\n)status: ${EXPECTED_STATUS}\n")
    message(FATAL_ERROR "result.yaml does not record status ${EXPECTED_STATUS}")
  endif()
else()
  if(EXISTS "${OUTPUT_DIR}/result.yaml")
    message(FATAL_ERROR "a run without a fit wrote ${OUTPUT_DIR}/result.yaml")
  endif()
endif()
message(STATUS "identify exited ${exit_status} as expected")
