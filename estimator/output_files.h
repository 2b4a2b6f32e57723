// All-or-nothing output: every file of a run is written beside its final
// name first and renamed into place only when all were written, so a failed
// run leaves no half-written result.
#ifndef DWELLFIT_ESTIMATOR_OUTPUT_FILES_H_
#define DWELLFIT_ESTIMATOR_OUTPUT_FILES_H_

#include <string>
#include <utility>
#include <vector>

namespace dwellfit {

// Creates `directory` if needed and writes each (file name, content) pair
// into it. Throws InputError naming the path when the directory or a file
// cannot be written; nothing of this call is left behind then.
void WriteFilesAtomically(const std::string& directory,
                          const std::vector<std::pair<std::string, std::string>>& files);

}  // namespace dwellfit

#endif  // DWELLFIT_ESTIMATOR_OUTPUT_FILES_H_
