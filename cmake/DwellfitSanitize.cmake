# Sanitizer and fuzzer builds, included from the top CMakeLists.txt before any
# target is defined.
#
#   DWELLFIT_SANITIZE=ON       every target (library, tools, tests, benchmarks)
#                              with AddressSanitizer and UndefinedBehaviorSanitizer;
#                              any report aborts the program, so it fails its test.
#   DWELLFIT_BUILD_FUZZERS=ON  (Clang only) also the libFuzzer targets of
#                              tests/fuzz; implies DWELLFIT_SANITIZE.
#
# The flags are in DWELLFIT_SANITIZE_CXX_FLAGS and DWELLFIT_SANITIZE_LINK_FLAGS
# (strings, empty when off), for builds outside this tree that link the
# instrumented library (the find_package_project test).
option(DWELLFIT_SANITIZE "Build with AddressSanitizer and UndefinedBehaviorSanitizer" OFF)
option(DWELLFIT_BUILD_FUZZERS "Build the libFuzzer targets in tests/fuzz (Clang only)" OFF)

set(DWELLFIT_SANITIZE_CXX_FLAGS "")
set(DWELLFIT_SANITIZE_LINK_FLAGS "")

if(DWELLFIT_BUILD_FUZZERS)
  if(NOT CMAKE_CXX_COMPILER_ID STREQUAL "Clang")
    message(FATAL_ERROR "DWELLFIT_BUILD_FUZZERS needs Clang (libFuzzer); configure with "
                        "-DCMAKE_CXX_COMPILER=clang++-14 (Debian packages clang-14, "
                        "libclang-rt-14-dev)")
  endif()
  set(DWELLFIT_SANITIZE ON CACHE BOOL
      "Build with AddressSanitizer and UndefinedBehaviorSanitizer" FORCE)
endif()

if(DWELLFIT_SANITIZE)
  if(NOT CMAKE_CXX_COMPILER_ID MATCHES "^(GNU|Clang)$")
    message(FATAL_ERROR "DWELLFIT_SANITIZE needs GCC or Clang, not ${CMAKE_CXX_COMPILER_ID}")
  endif()
  # -fno-sanitize-recover: an UndefinedBehaviorSanitizer report aborts like an
  # AddressSanitizer one, so no report can pass unnoticed in a passing test.
  set(sanitize -fsanitize=address,undefined -fno-sanitize-recover=all)
  # Eigen picks its allocator by a macro: with glibc on x86-64 it takes malloc
  # as already 16-byte aligned (EIGEN_MALLOC_ALREADY_ALIGNED 1) unless the
  # compiler defines __SANITIZE_ADDRESS__, and then it over-allocates and
  # stores the malloc'ed pointer in front of the block (handmade_aligned_malloc).
  # Debian's libceres is not instrumented, so it frees with plain free() what
  # our instrumented code allocated the other way, and the reverse (bad-free,
  # heap-buffer-overflow). Setting the macro to 1 restores the choice libceres
  # was compiled with; it is right because the sanitizer's malloc aligns to 16
  # bytes as glibc does (checked by tests/fit/eigen_allocation_test.cc).
  # (glibc's 16-byte rule is for 64-bit targets: elsewhere the macro differs.)
  if(NOT CMAKE_SIZEOF_VOID_P EQUAL 8)
    message(FATAL_ERROR "DWELLFIT_SANITIZE assumes a 64-bit glibc target (Eigen allocator)")
  endif()
  set(eigen_abi -DEIGEN_MALLOC_ALREADY_ALIGNED=1)
  set(compile_flags ${sanitize} -fno-omit-frame-pointer ${eigen_abi})
  if(DWELLFIT_BUILD_FUZZERS)
    # Coverage instrumentation for libFuzzer in every object; the fuzzer
    # executables add -fsanitize=fuzzer (libFuzzer's main) themselves.
    list(APPEND compile_flags -fsanitize=fuzzer-no-link)
  endif()
  add_compile_options(${compile_flags})
  add_link_options(${sanitize})
  list(JOIN compile_flags " " DWELLFIT_SANITIZE_CXX_FLAGS)
  list(JOIN sanitize " " DWELLFIT_SANITIZE_LINK_FLAGS)
  message(STATUS "dwellfit: sanitizers on: ${DWELLFIT_SANITIZE_CXX_FLAGS}")
endif()
