#include "estimator/output_files.h"

#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>

#include "estimator/input_error.h"

namespace dwellfit {

void WriteFilesAtomically(const std::string& directory,
                          const std::vector<std::pair<std::string, std::string>>& files) {
  namespace fs = std::filesystem;
  std::error_code error;
  fs::create_directories(directory, error);
  if (error) {
    throw InputError(directory, 0, "output_dir",
                     "cannot create the output directory (" + error.message() +
                         "); choose a writable output_dir");
  }
  const std::string suffix = ".partial-" + std::to_string(::getpid());
  std::vector<fs::path> written;
  auto remove_written = [&written]() {
    std::error_code ignored;
    for (const fs::path& path : written) fs::remove(path, ignored);
  };
  for (const auto& [name, content] : files) {
    const fs::path temporary = fs::path(directory) / (name + suffix);
    std::ofstream out(temporary, std::ios::binary | std::ios::trunc);
    if (out) written.push_back(temporary);
    out << content;
    out.close();
    if (!out) {
      const std::string reason = std::strerror(errno);
      remove_written();
      throw InputError(temporary.string(), 0, "output_dir",
                       "cannot write (" + reason + "); choose a writable output_dir");
    }
  }
  for (size_t i = 0; i < files.size(); ++i) {
    const fs::path final_path = fs::path(directory) / files[i].first;
    fs::rename(written[i], final_path, error);
    if (error) {
      remove_written();
      throw InputError(final_path.string(), 0, "output_dir",
                       "cannot move the result into place (" + error.message() + ")");
    }
  }
}

}  // namespace dwellfit
