# dwellfit_add_library(NAME <target> [HEADER_ONLY] [SOURCES ...] [PUBLIC ...] [PRIVATE ...])
#
# One stage of the data path as its own target `dwellfit_<target>`, aliased
# `dwellfit::<target>` and exported under that name. Every dwellfit header is
# included with the `dwellfit/` prefix ("dwellfit/estimator/fit/problem_builder.h"),
# in the build tree through ${DWELLFIT_BUILD_INCLUDE_DIR} and when installed
# from <prefix>/include.
function(dwellfit_add_library)
  cmake_parse_arguments(ARG "HEADER_ONLY" "NAME" "SOURCES;PUBLIC;PRIVATE" ${ARGN})
  set(target dwellfit_${ARG_NAME})
  if(ARG_HEADER_ONLY)
    add_library(${target} INTERFACE)
    set(scope INTERFACE)
  else()
    add_library(${target} STATIC ${ARG_SOURCES})
    set(scope PUBLIC)
    set_target_properties(${target} PROPERTIES POSITION_INDEPENDENT_CODE ON)
    if(ARG_PRIVATE)
      target_link_libraries(${target} PRIVATE ${ARG_PRIVATE})
    endif()
  endif()
  add_library(dwellfit::${ARG_NAME} ALIAS ${target})
  set_target_properties(${target} PROPERTIES EXPORT_NAME ${ARG_NAME})
  target_include_directories(${target} ${scope}
    $<BUILD_INTERFACE:${DWELLFIT_BUILD_INCLUDE_DIR}>
    $<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}>)
  target_compile_features(${target} ${scope} cxx_std_17)
  target_link_libraries(${target} ${scope} ${ARG_PUBLIC})
  set_property(GLOBAL APPEND PROPERTY DWELLFIT_LIBRARY_TARGETS ${target})
endfunction()
