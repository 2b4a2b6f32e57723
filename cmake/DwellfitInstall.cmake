# Installation and export.
#
#   <prefix>/include/dwellfit/{residuals,estimator,config}/<stage>/*.h
#   <prefix>/lib/libdwellfit_<stage>.a (one archive per stage of the data path)
#   <prefix>/lib/cmake/dwellfit/dwellfit{Config,ConfigVersion,Targets}.cmake
#   <prefix>/bin/dwellfit-identify, dwellfit-simulate-dwell, dwellfit-simulate-rig,
#   dwellfit-process-traces
#
# Outside code: find_package(dwellfit) and link dwellfit::dwellfit (all of
# the library) or one stage (dwellfit::residuals, the header-only functors;
# dwellfit::fit, ...). Headers are included as "dwellfit/residuals/...",
# "dwellfit/estimator/...", "dwellfit/config/...".
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

# Headers are globbed when `cmake --install` runs, so new ones need no edit here.
foreach(header_dir residuals estimator config)
  install(DIRECTORY ${PROJECT_SOURCE_DIR}/${header_dir}/
    DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/dwellfit/${header_dir}
    FILES_MATCHING PATTERN "*.h")
endforeach()

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

# The command-line tools keep their build names (build/tools/identify) but are
# installed with a dwellfit- prefix: ImageMagick already installs `identify`.
foreach(tool identify simulate_dwell simulate_rig process_traces)
  if(TARGET ${tool})
    string(REPLACE "_" "-" installed_name "dwellfit-${tool}")
    install(PROGRAMS $<TARGET_FILE:${tool}>
      DESTINATION ${CMAKE_INSTALL_BINDIR}
      RENAME ${installed_name})
  endif()
endforeach()
