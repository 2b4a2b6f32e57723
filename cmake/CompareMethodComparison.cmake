# Regenerates docs/method-comparison.md into the build tree and fails unless
# it equals the committed copy: the report stays reproducible by one command.
# Arguments: TOOL (method_comparison), SOURCE_DIR, OUTPUT.
execute_process(
  COMMAND ${TOOL} --numerical datasets/thesis-numerical/beam.yaml
          --truth_plan datasets/thesis-numerical/plan.yaml
          --measured datasets/clamped-beam-27C/beam.yaml --output ${OUTPUT}
  WORKING_DIRECTORY ${SOURCE_DIR}
  RESULT_VARIABLE status)
if(NOT status EQUAL 0)
  message(FATAL_ERROR "method_comparison failed (${status})")
endif()
execute_process(COMMAND ${CMAKE_COMMAND} -E compare_files ${OUTPUT}
                        ${SOURCE_DIR}/docs/method-comparison.md
                RESULT_VARIABLE differs)
if(differs)
  message(FATAL_ERROR "docs/method-comparison.md is stale: regenerate it with "
                      "build/tools/method_comparison (from the repository root)")
endif()
