// Reading an input file whole, refusing what is not one: a folder, a device
// such as /dev/zero, a pipe that would block, or a file too large to be one.
#ifndef DWELLFIT_ESTIMATOR_COMMON_TEXT_FILE_H_
#define DWELLFIT_ESTIMATOR_COMMON_TEXT_FILE_H_

#include <cstdint>
#include <string>

namespace dwellfit {

// The largest input file read whole (configs, results, study files): 256 MiB.
inline constexpr std::uintmax_t kMaxTextFileBytes = std::uintmax_t{256} << 20;

// The bytes of the regular file `path`. Throws InputError naming the path
// and ending in `what_to_give` ("give the result.yaml an identify run wrote")
// when it does not exist, is not a regular file, holds more than
// kMaxTextFileBytes or cannot be read.
std::string ReadTextFile(const std::string& path, const std::string& what_to_give);

}  // namespace dwellfit

#endif  // DWELLFIT_ESTIMATOR_COMMON_TEXT_FILE_H_
