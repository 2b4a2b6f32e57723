#include "dwellfit/estimator/common/memory_policy.h"

#include <malloc.h>

namespace dwellfit {

namespace {

constexpr int kMiB = 1024 * 1024;
// glibc's largest mmap threshold on 64-bit systems: blocks of this size and
// more (a million dwells' Jacobian) still get their own mapping.
constexpr int kMmapThresholdBytes = 32 * kMiB;
// Freed memory at the top of the heap kept before any is returned.
constexpr int kTrimThresholdBytes = 1024 * kMiB;
// The heap grows by this much more than asked, in one system call.
constexpr int kTopPadBytes = 16 * kMiB;

}  // namespace

bool KeepFreedMemoryForReuse() {
  // mallopt returns 1 on success, 0 on error.
  const bool mmap_threshold = mallopt(M_MMAP_THRESHOLD, kMmapThresholdBytes) == 1;
  const bool trim_threshold = mallopt(M_TRIM_THRESHOLD, kTrimThresholdBytes) == 1;
  const bool top_pad = mallopt(M_TOP_PAD, kTopPadBytes) == 1;
  return mmap_threshold && trim_threshold && top_pad;
}

void ReturnFreedMemory() { malloc_trim(0); }

}  // namespace dwellfit
