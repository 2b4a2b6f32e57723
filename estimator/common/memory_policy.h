// How a dwellfit tool's process asks the C library's allocator to treat
// large blocks.
//
// A fit allocates and frees large blocks again and again; kept in the heap
// rather than mapped afresh each time (glibc's default above 128 KiB), a
// freed block is reused without page faults. What a run has freed is not
// returned before it ends unless it calls ReturnFreedMemory.
#ifndef DWELLFIT_ESTIMATOR_COMMON_MEMORY_POLICY_H_
#define DWELLFIT_ESTIMATOR_COMMON_MEMORY_POLICY_H_

namespace dwellfit {

// Serves blocks below 32 MiB from the heap and keeps what is freed there
// for reuse (mallopt M_MMAP_THRESHOLD, M_TRIM_THRESHOLD, M_TOP_PAD). Call
// once, first thing in a tool's main; a library embedding dwellfit keeps its
// own allocator policy. Returns whether every setting was accepted.
bool KeepFreedMemoryForReuse();

// Returns the pages of the heap's free memory to the kernel (malloc_trim);
// blocks later served from them fault their pages in again.
void ReturnFreedMemory();

}  // namespace dwellfit

#endif  // DWELLFIT_ESTIMATOR_COMMON_MEMORY_POLICY_H_
