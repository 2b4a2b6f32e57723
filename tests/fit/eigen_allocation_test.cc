// Eigen's heap blocks cross between dwellfit and the system's libceres, which
// was compiled without sanitizers: each side must allocate and free them the
// same way. With glibc on a 64-bit target Eigen uses plain malloc/free
// (EIGEN_MALLOC_ALREADY_ALIGNED 1) unless __SANITIZE_ADDRESS__ is defined;
// cmake/DwellfitSanitize.cmake sets the macro so that sanitizer builds keep
// the uninstrumented choice. These tests hold in every build.
#include <Eigen/Core>
#include <cstdint>
#include <cstdlib>
#include <vector>

#include "gtest/gtest.h"

namespace {

TEST(EigenAllocationTest, UsesPlainMallocLikeTheUninstrumentedLibceres) {
#if defined(__GLIBC__) && defined(__LP64__) && EIGEN_DEFAULT_ALIGN_BYTES == 16
  EXPECT_EQ(EIGEN_MALLOC_ALREADY_ALIGNED, 1);
#else
  GTEST_SKIP() << "not a 64-bit glibc target with 16-byte Eigen alignment";
#endif
}

// Plain malloc is only right for Eigen when it returns blocks aligned to
// EIGEN_DEFAULT_ALIGN_BYTES, with or without the sanitizer's allocator.
TEST(EigenAllocationTest, MallocAlignsBlocksAsEigenNeeds) {
  std::vector<void*> blocks;
  for (std::size_t size = 16; size <= 4096; size += 8) {
    void* block = std::malloc(size);
    ASSERT_NE(block, nullptr);
    blocks.push_back(block);
    EXPECT_EQ(reinterpret_cast<std::uintptr_t>(block) % EIGEN_DEFAULT_ALIGN_BYTES, 0u)
        << "malloc(" << size << ")";
  }
  for (void* block : blocks) std::free(block);
}

// Eigen hands out the very block malloc gave it. Checked in every build by
// glibc's per-thread cache, which gives a freed block back to the next
// request of its size: a block Eigen frees with plain free() comes back from
// plain malloc() at the same address. Eigen's hand-made aligned allocator
// would return malloc's block plus an offset (and free the original), so the
// addresses would differ. AddressSanitizer holds freed blocks back, so there
// the free() of the next test is the check: it reports a block freed that
// malloc did not hand out.
#if defined(__SANITIZE_ADDRESS__)
#define DWELLFIT_ASAN 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define DWELLFIT_ASAN 1
#endif
#endif

TEST(EigenAllocationTest, EigenHandsOutTheBlockMallocGave) {
#if defined(DWELLFIT_ASAN)
  GTEST_SKIP() << "AddressSanitizer holds freed blocks back; the next test checks the frees";
#elif defined(__GLIBC__)
  constexpr std::size_t kBytes = 11 * sizeof(double);  // 88 bytes: one 96-byte chunk
  void* from_eigen = Eigen::internal::aligned_malloc(kBytes);
  Eigen::internal::aligned_free(from_eigen);
  void* from_malloc = std::malloc(kBytes);
  EXPECT_EQ(from_malloc, from_eigen)
      << "Eigen's aligned_malloc did not return malloc's own block: it allocates with its "
         "hand-made aligned allocator, which libceres' plain free() cannot release";
  std::free(from_malloc);
#else
  GTEST_SKIP() << "not a glibc target";
#endif
}

// A block Eigen allocates is one that plain free() accepts, and the reverse,
// as when a matrix is built on one side and destroyed on the other. Under
// AddressSanitizer a mismatched free is reported and fails the test; in
// other builds glibc's free() aborts on most pointers it did not hand out.
TEST(EigenAllocationTest, EigenBlocksAndMallocBlocksAreInterchangeable) {
  void* from_eigen = Eigen::internal::aligned_malloc(10 * sizeof(double));
  static_cast<double*>(from_eigen)[9] = 1.5;
  std::free(from_eigen);
  void* from_malloc = std::malloc(10 * sizeof(double));
  static_cast<double*>(from_malloc)[9] = 2.5;
  Eigen::internal::aligned_free(from_malloc);
}

}  // namespace
