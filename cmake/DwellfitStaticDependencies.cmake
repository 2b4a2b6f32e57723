# Links the dependencies that Debian ships as static archives from those
# archives, included from the top CMakeLists.txt after the find_package calls.
#
#   DWELLFIT_STATIC_DEPENDENCIES=ON (default at top level)  glog, gflags, yaml-cpp, SuiteSparse,
#       CXSparse and ATLAS' LAPACK and BLAS (with the GCC runtime archives they need)
#       are linked from their .a files; libstdc++, libc, TBB, METIS and libunwind
#       stay shared.
#
# Why: a run of identify on a small dataset takes a few milliseconds of
# arithmetic, and the dynamic loader mapping and relocating 27 shared libraries
# took some 2 ms more of every process (docs/performance.md). Linked this way
# a tool loads 8. When an archive is missing the build says which and links
# everything shared, as before.
#
# Off by default when dwellfit is built inside a host project (add_subdirectory):
# the imported targets it changes are the host's too.
option(DWELLFIT_STATIC_DEPENDENCIES
       "Link glog, gflags, yaml-cpp, SuiteSparse and LAPACK/BLAS from their static archives"
       ${DWELLFIT_IS_TOP_LEVEL})

# Sets `out_var` to the full path of the archive `file_name` (e.g. libglog.a)
# in the system library folders or, for GCC's runtime archives, the compiler's
# own folder; to NOTFOUND when neither has it.
function(dwellfit_find_archive out_var file_name)
  find_library(DWELLFIT_ARCHIVE_${file_name} NAMES ${file_name} NO_CACHE)
  set(path "${DWELLFIT_ARCHIVE_${file_name}}")
  if(NOT path)
    execute_process(COMMAND ${CMAKE_CXX_COMPILER} -print-file-name=${file_name}
                    OUTPUT_VARIABLE path OUTPUT_STRIP_TRAILING_WHITESPACE)
    if(NOT IS_ABSOLUTE "${path}" OR NOT EXISTS "${path}")
      set(path NOTFOUND)
    endif()
  endif()
  set(${out_var} "${path}" PARENT_SCOPE)
endfunction()

# Points the imported target `target` at `archive` whatever its build type.
function(dwellfit_use_archive target archive)
  if(NOT TARGET ${target})
    return()
  endif()
  get_target_property(aliased ${target} ALIASED_TARGET)
  if(aliased)
    set(target ${aliased})
  endif()
  set_target_properties(${target} PROPERTIES IMPORTED_LOCATION "${archive}")
  get_target_property(configurations ${target} IMPORTED_CONFIGURATIONS)
  if(configurations)
    foreach(configuration IN LISTS configurations)
      set_target_properties(${target} PROPERTIES IMPORTED_LOCATION_${configuration} "${archive}")
    endforeach()
  endif()
endfunction()

function(dwellfit_link_dependencies_statically)
  set(names yaml-cpp glog gflags spqr cholmod amd camd ccolamd colamd suitesparseconfig cxsparse
            lapack blas f77blas cblas atlas gfortran quadmath gomp)
  foreach(name IN LISTS names)
    dwellfit_find_archive(archive_${name} lib${name}.a)
    if(NOT archive_${name})
      message(STATUS "dwellfit: lib${name}.a not found; linking the dependencies shared")
      return()
    endif()
  endforeach()
  find_library(DWELLFIT_UNWIND_LIBRARY NAMES unwind)
  # Debian ships METIS without its development link (libmetis.so).
  find_library(DWELLFIT_METIS_LIBRARY NAMES metis libmetis.so.5)
  if(NOT DWELLFIT_UNWIND_LIBRARY OR NOT DWELLFIT_METIS_LIBRARY)
    message(STATUS "dwellfit: libunwind or libmetis not found; linking the dependencies shared")
    return()
  endif()

  dwellfit_use_archive(yaml-cpp "${archive_yaml-cpp}")
  dwellfit_use_archive(glog::glog "${archive_glog}")
  set_property(TARGET glog::glog APPEND PROPERTY INTERFACE_LINK_LIBRARIES
                                                 "${DWELLFIT_UNWIND_LIBRARY}")
  foreach(target IN ITEMS gflags gflags_shared)
    dwellfit_use_archive(${target} "${archive_gflags}")
  endforeach()
  # SuiteSparse and CXSparse as Ceres' find modules import them.
  dwellfit_use_archive(SuiteSparse::SPQR "${archive_spqr}")
  dwellfit_use_archive(SuiteSparse::CHOLMOD "${archive_cholmod}")
  foreach(component IN ITEMS AMD CAMD CCOLAMD COLAMD)
    string(TOLOWER ${component} lower)
    dwellfit_use_archive(SuiteSparse::${component} "${archive_${lower}}")
  endforeach()
  dwellfit_use_archive(SuiteSparse::Config "${archive_suitesparseconfig}")
  dwellfit_use_archive(CXSparse::CXSparse "${archive_cxsparse}")
  set(blas_archives "${archive_blas}" "${archive_f77blas}" "${archive_cblas}" "${archive_atlas}"
                    "${archive_gfortran}" "${archive_quadmath}")
  if(TARGET BLAS::BLAS)
    set_target_properties(BLAS::BLAS PROPERTIES INTERFACE_LINK_LIBRARIES "${blas_archives}")
  endif()
  if(TARGET LAPACK::LAPACK)
    set_target_properties(LAPACK::LAPACK PROPERTIES INTERFACE_LINK_LIBRARIES
                                                    "${archive_lapack};${blas_archives}")
  endif()

  # Ceres names LAPACK and BLAS by the paths of their shared objects; the
  # archives come in link order, with what they in turn need after them.
  get_target_property(ceres_links Ceres::ceres INTERFACE_LINK_LIBRARIES)
  list(FILTER ceres_links EXCLUDE REGEX "/lib(lapack|blas|f77blas|cblas|atlas)\\.so$")
  list(APPEND ceres_links
       # cholmod and spqr, each a static archive now, need these in turn.
       "${archive_cholmod}" "${archive_amd}" "${archive_camd}" "${archive_ccolamd}"
       "${archive_colamd}" "${archive_suitesparseconfig}" "${DWELLFIT_METIS_LIBRARY}"
       "${archive_lapack}" ${blas_archives} "${archive_gomp}" ${CMAKE_DL_LIBS})
  set_target_properties(Ceres::ceres PROPERTIES INTERFACE_LINK_LIBRARIES "${ceres_links}")
  message(STATUS "dwellfit: glog, gflags, yaml-cpp, SuiteSparse and LAPACK/BLAS linked statically")
endfunction()

if(DWELLFIT_STATIC_DEPENDENCIES)
  dwellfit_link_dependencies_statically()
endif()
