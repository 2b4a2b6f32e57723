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

// A block Eigen allocates is one that plain free() accepts, and the reverse,
// as when a matrix is built on one side and destroyed on the other.
TEST(EigenAllocationTest, EigenBlocksAndMallocBlocksAreInterchangeable) {
  void* from_eigen = Eigen::internal::aligned_malloc(10 * sizeof(double));
  static_cast<double*>(from_eigen)[9] = 1.5;
  std::free(from_eigen);
  void* from_malloc = std::malloc(10 * sizeof(double));
  static_cast<double*>(from_malloc)[9] = 2.5;
  Eigen::internal::aligned_free(from_malloc);
  SUCCEED();
}

}  // namespace
