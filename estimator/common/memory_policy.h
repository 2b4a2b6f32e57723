// How a dwellfit tool's process asks the C library's allocator to treat
// large blocks.
//
// By default glibc serves every block of 128 KiB and more (growing with use
// up to 32 MiB) with its own mmap, and hands it back to the kernel when it is
// freed; memory freed at the top of the heap beyond 128 KiB goes back too.
// A fit allocates and frees blocks of that size again and again (each stage's
// problem, Ceres' Jacobian and its QR copies, the output text), and every
// time the kernel must map fresh zeroed pages in on first touch: one page
// fault per 4 KiB, some 10 microseconds each on a virtual machine. Kept in
// the heap instead, a freed block is reused as it is.
//
// What a run has freed is not returned before it ends. That can raise the
// peak resident memory where a phase that frees much is followed by one whose
// blocks do not fit in the freed space (blocks of 32 MiB and more are still
// mapped afresh): a run calls ReturnFreedMemory between the two.
#ifndef DWELLFIT_ESTIMATOR_COMMON_MEMORY_POLICY_H_
#define DWELLFIT_ESTIMATOR_COMMON_MEMORY_POLICY_H_

namespace dwellfit {

// Serves blocks below 32 MiB from the heap and keeps what is freed there
// for reuse (mallopt M_MMAP_THRESHOLD, M_TRIM_THRESHOLD, M_TOP_PAD). Call
// once, first thing in a tool's main; a library embedding dwellfit keeps its
// own allocator policy. Returns whether every setting was accepted.
bool KeepFreedMemoryForReuse();

// Returns the pages of the heap's free memory to the kernel (malloc_trim);
// blocks later served from them fault their pages in again. On a
// million-dwell identify run, called after the fit: 15 ms, and the run's
// peak 435 -> 336 MB resident.
void ReturnFreedMemory();

}  // namespace dwellfit

#endif  // DWELLFIT_ESTIMATOR_COMMON_MEMORY_POLICY_H_
