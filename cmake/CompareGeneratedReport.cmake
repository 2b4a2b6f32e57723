# Regenerates a committed report into the build tree and fails unless the
# tool succeeds and its output equals the committed copy: each generated
# report stays reproducible by one command.
# Arguments: TOOL, ARGS (;-separated, run from SOURCE_DIR), OUTPUT (the
# tool's --output), COMMITTED (path of the committed copy under SOURCE_DIR).
get_filename_component(output_dir ${OUTPUT} DIRECTORY)
file(MAKE_DIRECTORY ${output_dir})
execute_process(
  COMMAND ${TOOL} ${ARGS} --output ${OUTPUT}
  WORKING_DIRECTORY ${SOURCE_DIR}
  RESULT_VARIABLE status)
if(NOT status EQUAL 0)
  message(FATAL_ERROR "${TOOL} failed (${status})")
endif()
execute_process(COMMAND ${CMAKE_COMMAND} -E compare_files ${OUTPUT} ${SOURCE_DIR}/${COMMITTED}
                RESULT_VARIABLE differs)
if(differs)
  get_filename_component(tool_name ${TOOL} NAME)
  message(FATAL_ERROR "${COMMITTED} is stale: regenerate it with build/tools/${tool_name} "
                      "(from the repository root)")
endif()
