#include "dwellfit/estimator/common/text_file.h"

#include <filesystem>
#include <fstream>
#include <iterator>

#include "dwellfit/estimator/common/input_error.h"

namespace dwellfit {

std::string ReadTextFile(const std::string& path, const std::string& what_to_give) {
  namespace fs = std::filesystem;
  std::error_code error;
  const fs::file_status status = fs::status(path, error);
  if (!fs::exists(status)) throw InputError(path, 0, "", "no such file; " + what_to_give);
  if (!fs::is_regular_file(status)) {
    const char* what =
        fs::is_directory(status) ? "is a folder" : "is not a regular file (a device or pipe)";
    throw InputError(path, 0, "", std::string(what) + "; " + what_to_give);
  }
  const std::uintmax_t size = fs::file_size(path, error);
  if (!error && size > kMaxTextFileBytes) {
    throw InputError(path, 0, "",
                     "holds " + std::to_string(size) + " bytes, more than an input file of " +
                         std::to_string(kMaxTextFileBytes >> 20) + " MiB; " + what_to_give);
  }
  std::ifstream in(path, std::ios::binary);
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (!in && !in.eof()) throw InputError(path, 0, "", "cannot read the file; " + what_to_give);
  return text;
}

}  // namespace dwellfit
