# Regenerates docs/chapter-tables.md into the build tree and fails unless it
# equals the committed copy: the report stays reproducible by one command.
# Arguments: TOOL (chapter_tables), SOURCE_DIR, OUTPUT.
execute_process(
  COMMAND ${TOOL} --numerical datasets/thesis-numerical/beam.yaml
          --truth_plan datasets/thesis-numerical/plan.yaml
          --measured datasets/clamped-beam-27C/beam.yaml --output ${OUTPUT}
  WORKING_DIRECTORY ${SOURCE_DIR}
  RESULT_VARIABLE status)
if(NOT status EQUAL 0)
  message(FATAL_ERROR "chapter_tables failed (${status})")
endif()
execute_process(COMMAND ${CMAKE_COMMAND} -E compare_files ${OUTPUT}
                        ${SOURCE_DIR}/docs/chapter-tables.md
                RESULT_VARIABLE differs)
if(differs)
  message(FATAL_ERROR "docs/chapter-tables.md is stale: regenerate it with "
                      "build/tools/chapter_tables (from the repository root)")
endif()
