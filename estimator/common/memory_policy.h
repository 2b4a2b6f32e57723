// How a dwellfit tool asks the C library's allocator to treat large blocks:
// a fit allocates and frees them again and again, and one kept in the heap
// (rather than mapped afresh, glibc's default above 128 KiB) is reused
// without page faults.
#ifndef DWELLFIT_ESTIMATOR_COMMON_MEMORY_POLICY_H_
#define DWELLFIT_ESTIMATOR_COMMON_MEMORY_POLICY_H_

namespace dwellfit {

// Serves blocks below 32 MiB from the heap and keeps what is freed there
// (mallopt). Call first thing in a tool's main, never from the library.
// Returns whether every setting was accepted.
bool KeepFreedMemoryForReuse();

// Returns the heap's free pages to the kernel (malloc_trim).
void ReturnFreedMemory();

}  // namespace dwellfit

#endif  // DWELLFIT_ESTIMATOR_COMMON_MEMORY_POLICY_H_
