// A private directory for the fuzz bodies' files, in /dev/shm (memory) when
// it can be written, else the system temp directory. One per process,
// created on first use and removed at exit.
#ifndef DWELLFIT_TESTS_FUZZ_SCRATCH_DIR_H_
#define DWELLFIT_TESTS_FUZZ_SCRATCH_DIR_H_

#include <cstddef>
#include <string>

namespace dwellfit::fuzz {

// The directory's absolute path.
const std::string& ScratchDir();

// Writes `size` bytes to the file `name` in ScratchDir(), replacing it, and
// returns the file's path. Aborts if it cannot (not an input's fault).
std::string WriteScratchFile(const std::string& name, const void* data, std::size_t size);
std::string WriteScratchFile(const std::string& name, const std::string& text);

}  // namespace dwellfit::fuzz

#endif  // DWELLFIT_TESTS_FUZZ_SCRATCH_DIR_H_
