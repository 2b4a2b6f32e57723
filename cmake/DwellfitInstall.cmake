# Installation and export.
#
#   <prefix>/include/dwellfit/...    the public headers (DWELLFIT_PUBLIC_HEADERS)
#   <prefix>/lib/libdwellfit_<stage>.a (one archive per stage of the data path)
#   <prefix>/lib/cmake/dwellfit/dwellfit{Config,ConfigVersion,Targets}.cmake
#   <prefix>/bin/dwellfit-<tool>     every command-line tool (tools/*_main.cc)
#
# Outside code: find_package(dwellfit) and link dwellfit::dwellfit. It
# includes the public headers as "dwellfit/estimator/...", "dwellfit/residuals/...";
# every other header is the library's own and is not installed.
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)

set(DWELLFIT_INSTALL_CMAKEDIR "${CMAKE_INSTALL_LIBDIR}/cmake/dwellfit"
    CACHE STRING "Where dwellfitConfig.cmake is installed, relative to the prefix")

get_property(dwellfit_library_targets GLOBAL PROPERTY DWELLFIT_LIBRARY_TARGETS)
install(TARGETS ${dwellfit_library_targets} dwellfit
  EXPORT dwellfitTargets
  ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
  LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
  RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})

# The public headers: what a user includes to load sweeps (sweep_csv.h, with
# jump_detection.h to label them), describe a fit (fit_description.h,
# identification_options.h, initial_guess.h), solve it (identification.h,
# staged_solve.h), read the result with its intervals (parameter_uncertainty.h,
# profile_likelihood.h, block_covariance.h), draw curves (response_curve.h) and simulate dwells
# (dwell_simulator.h); then what those include: the header-only model
# (residuals/model) and the shared small headers. Every one must compile on its
# own against the installed tree, including only headers of this list (the
# find_package_project test checks both, and that there are at most 25).
set(DWELLFIT_PUBLIC_HEADERS
    estimator/analysis/block_covariance.h
    estimator/analysis/parameter_uncertainty.h
    estimator/analysis/profile_likelihood.h
    estimator/common/input_error.h
    estimator/curves/response_curve.h
    estimator/data/jump_detection.h
    estimator/data/sweep.h
    estimator/data/sweep_csv.h
    estimator/fit/fit_description.h
    estimator/fit/identification.h
    estimator/fit/identification_options.h
    estimator/fit/initial_guess.h
    estimator/fit/staged_solve.h
    estimator/simulation/dwell_simulator.h
    residuals/functors/error_measure.h
    residuals/model/amplitude_roots.h
    residuals/model/bracketed_newton.h
    residuals/model/model_form.h
    residuals/model/model_parameters.h
    residuals/model/response_model.h
    residuals/model/stable_root.h
    residuals/model/sweep_vocabulary.h)
foreach(header IN LISTS DWELLFIT_PUBLIC_HEADERS)
  get_filename_component(header_dir "${header}" DIRECTORY)
  install(FILES ${PROJECT_SOURCE_DIR}/${header}
    DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/dwellfit/${header_dir})
endforeach()
list(LENGTH DWELLFIT_PUBLIC_HEADERS DWELLFIT_PUBLIC_HEADER_COUNT)

install(EXPORT dwellfitTargets
  NAMESPACE dwellfit::
  FILE dwellfitTargets.cmake
  DESTINATION ${DWELLFIT_INSTALL_CMAKEDIR})

configure_package_config_file(
  ${PROJECT_SOURCE_DIR}/cmake/dwellfitConfig.cmake.in
  ${PROJECT_BINARY_DIR}/dwellfitConfig.cmake
  INSTALL_DESTINATION ${DWELLFIT_INSTALL_CMAKEDIR})
write_basic_package_version_file(
  ${PROJECT_BINARY_DIR}/dwellfitConfigVersion.cmake
  VERSION ${PROJECT_VERSION}
  COMPATIBILITY SameMajorVersion)
install(FILES
  ${PROJECT_BINARY_DIR}/dwellfitConfig.cmake
  ${PROJECT_BINARY_DIR}/dwellfitConfigVersion.cmake
  DESTINATION ${DWELLFIT_INSTALL_CMAKEDIR})

# The command-line tools (every tools/*_main.cc) keep their build names
# (build/tools/identify) but are installed with a dwellfit- prefix, '_' as '-':
# ImageMagick already installs `identify`.
if(DWELLFIT_BUILD_TOOLS)
  file(GLOB tool_mains CONFIGURE_DEPENDS ${PROJECT_SOURCE_DIR}/tools/*_main.cc)
  foreach(main_source IN LISTS tool_mains)
    get_filename_component(tool "${main_source}" NAME_WE)
    string(REGEX REPLACE "_main$" "" tool "${tool}")
    string(REPLACE "_" "-" installed_name "dwellfit-${tool}")
    install(PROGRAMS $<TARGET_FILE:${tool}>
      DESTINATION ${CMAKE_INSTALL_BINDIR}
      RENAME ${installed_name})
  endforeach()
endif()
