// All-or-nothing output of a run into its output directory.
//
// Protocol (what a reader of the directory can rely on):
//   1. Every file of the run is written and flushed to disk inside a staging
//      folder `.dwellfit-staging-<pid>` of the output directory.
//   2. The previous run's `manifest.yaml` is removed.
//   3. Each file is renamed into the output directory (same file system, so
//      each rename is atomic).
//   4. The files the previous manifest listed that this run does not write
//      (the figures of a run with figures, before one without) are removed.
//   5. `manifest.yaml`, listing every file of the run with its size in bytes,
//      is renamed into place last; then the staging folder is removed.
// So a manifest always lists one run's complete files, and the directory
// holds no file of an earlier run beside them. What a killed process leaves
// (staging folders, `*.partial-<pid>` files) is removed by the next run into
// the same directory.
#ifndef DWELLFIT_ESTIMATOR_RUN_OUTPUT_FILES_H_
#define DWELLFIT_ESTIMATOR_RUN_OUTPUT_FILES_H_

#include <string>
#include <utility>
#include <vector>

namespace dwellfit {

// The file that lists a complete run's files; written last.
inline constexpr char kManifestFileName[] = "manifest.yaml";

// Checks, without writing, that `directory` is or can become a writable
// directory (before a long computation); else throws InputError naming the
// path and `field`, the config key or flag that set it.
void CheckOutputDirectory(const std::string& directory, const std::string& field);

// Creates `directory` if needed and publishes each (file name, content) pair
// into it as the protocol above says. Throws InputError naming the path when
// the directory or a file cannot be written; the directory then holds no file
// of this call, and the previous run's files stay as they were unless the
// failure came while renaming (then no manifest is left).
void WriteFilesAtomically(const std::string& directory,
                          const std::vector<std::pair<std::string, std::string>>& files);

// One report file written beside `path`, flushed, then renamed onto it, so
// `path` holds the old text or the whole new one. Errors name `field`.
void WriteReportAtomically(const std::string& path, const std::string& text,
                           const std::string& field = "--output");

}  // namespace dwellfit

#endif  // DWELLFIT_ESTIMATOR_RUN_OUTPUT_FILES_H_
