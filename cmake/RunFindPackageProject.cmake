# CTest driver for the tests that build an outside project against an
# installed dwellfit (cmake -P): installs the built dwellfit into a fresh
# prefix, checks what was installed, configures and builds the outside project
# (tests/find_package_project, examples/01_identify, examples/02_two_beams)
# against it with find_package(dwellfit), and runs its program. Any failing
# step fails the test with that step's name and output.
#
# Required -D variables:
#   DWELLFIT_BINARY_DIR  the dwellfit build tree to install from
#   PROJECT_SOURCE       the outside project's source directory
#   WORK_DIR             build directory of the outside project (wiped first)
#   PREFIX               install prefix (wiped first)
# Optional: PROGRAM (the program to run, default embed_dwellfit), ARGS (its
# arguments, a ;-list), NAME (in messages, default find_package_project),
# MAX_HEADERS (fail when more headers are installed, or any outside
# include/dwellfit/), TOOLS (a ;-list of programs that must be installed in
# <prefix>/bin), GENERATOR, CXX_COMPILER, BUILD_TYPE,
# and CXX_FLAGS and LINKER_FLAGS (the sanitizer flags of a DWELLFIT_SANITIZE
# build: an instrumented library links only into an instrumented program).
cmake_minimum_required(VERSION 3.16)

foreach(var DWELLFIT_BINARY_DIR PROJECT_SOURCE WORK_DIR PREFIX)
  if(NOT ${var})
    message(FATAL_ERROR "RunFindPackageProject: -D${var}=... is required")
  endif()
endforeach()
if(NOT BUILD_TYPE)
  set(BUILD_TYPE Release)
endif()
if(NOT PROGRAM)
  set(PROGRAM embed_dwellfit)
endif()
if(NOT NAME)
  set(NAME find_package_project)
endif()

# Lists come comma-separated (a ';' would split the ctest command's argument).
string(REPLACE "," ";" ARGS "${ARGS}")
string(REPLACE "," ";" TOOLS "${TOOLS}")

function(run_step name)
  list(JOIN ARGN " " command_line)
  message(STATUS "${NAME}: ${name}: ${command_line}")
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE result)
  if(NOT result EQUAL 0)
    message(FATAL_ERROR "${NAME}: step '${name}' failed (${result}): ${command_line}")
  endif()
endfunction()

file(REMOVE_RECURSE "${PREFIX}" "${WORK_DIR}")

run_step(install
  "${CMAKE_COMMAND}" --install "${DWELLFIT_BINARY_DIR}" --prefix "${PREFIX}"
  --config "${BUILD_TYPE}")

# What the install put in the prefix: the public headers only, every tool.
if(MAX_HEADERS)
  file(GLOB_RECURSE headers RELATIVE "${PREFIX}/include" "${PREFIX}/include/*")
  list(LENGTH headers header_count)
  message(STATUS "${NAME}: ${header_count} installed headers (at most ${MAX_HEADERS})")
  if(header_count GREATER MAX_HEADERS)
    list(JOIN headers "\n  " listed)
    message(FATAL_ERROR "${NAME}: ${header_count} headers are installed, more than the "
                        "${MAX_HEADERS} of the public API:\n  ${listed}")
  endif()
  foreach(header IN LISTS headers)
    if(NOT header MATCHES "^dwellfit/.*\\.h$")
      message(FATAL_ERROR "${NAME}: ${PREFIX}/include/${header} is installed outside "
                          "include/dwellfit/ or is not a header")
    endif()
  endforeach()
endif()
foreach(tool IN LISTS TOOLS)
  find_program(installed_${tool} ${tool} PATHS "${PREFIX}/bin" NO_DEFAULT_PATH)
  if(NOT installed_${tool})
    message(FATAL_ERROR "${NAME}: the tool ${tool} is not installed in ${PREFIX}/bin")
  endif()
endforeach()
if(TOOLS)
  list(LENGTH TOOLS tool_count)
  message(STATUS "${NAME}: all ${tool_count} tools installed in ${PREFIX}/bin")
endif()

set(configure_args -S "${PROJECT_SOURCE}" -B "${WORK_DIR}"
  "-DCMAKE_PREFIX_PATH=${PREFIX}" "-DCMAKE_BUILD_TYPE=${BUILD_TYPE}")
if(GENERATOR)
  list(APPEND configure_args -G "${GENERATOR}")
endif()
if(CXX_COMPILER)
  list(APPEND configure_args "-DCMAKE_CXX_COMPILER=${CXX_COMPILER}")
endif()
if(CXX_FLAGS)
  list(APPEND configure_args "-DCMAKE_CXX_FLAGS=${CXX_FLAGS}")
endif()
if(LINKER_FLAGS)
  list(APPEND configure_args "-DCMAKE_EXE_LINKER_FLAGS=${LINKER_FLAGS}")
endif()
run_step(configure "${CMAKE_COMMAND}" ${configure_args})
run_step(build "${CMAKE_COMMAND}" --build "${WORK_DIR}" --config "${BUILD_TYPE}")

find_program(program ${PROGRAM}
  PATHS "${WORK_DIR}" "${WORK_DIR}/${BUILD_TYPE}" NO_DEFAULT_PATH)
if(NOT program)
  message(FATAL_ERROR "${NAME}: the built program ${PROGRAM} is missing in ${WORK_DIR}")
endif()
run_step(run "${program}" ${ARGS})
