#include "tests/fuzz/scratch_dir.h"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <system_error>
#include <vector>

namespace dwellfit::fuzz {
namespace {

[[noreturn]] void Fail(const std::string& what) {
  std::fprintf(stderr, "fuzz scratch directory: %s: %s\n", what.c_str(), std::strerror(errno));
  std::abort();
}

class OwnedDirectory {
 public:
  OwnedDirectory() {
    std::error_code error;
    std::filesystem::path base = "/dev/shm";
    if (access(base.c_str(), W_OK) != 0) base = std::filesystem::temp_directory_path(error);
    std::string pattern = (base / "dwellfit-fuzz-XXXXXX").string();
    std::vector<char> buffer(pattern.begin(), pattern.end());
    buffer.push_back('\0');
    if (mkdtemp(buffer.data()) == nullptr) Fail("cannot create " + pattern);
    path_ = buffer.data();
  }
  ~OwnedDirectory() {
    std::error_code ignored;
    std::filesystem::remove_all(path_, ignored);
  }
  OwnedDirectory(const OwnedDirectory&) = delete;
  OwnedDirectory& operator=(const OwnedDirectory&) = delete;

  const std::string& path() const { return path_; }

 private:
  std::string path_;
};

}  // namespace

const std::string& ScratchDir() {
  static const OwnedDirectory directory;
  return directory.path();
}

std::string WriteScratchFile(const std::string& name, const void* data, std::size_t size) {
  const std::string path = ScratchDir() + "/" + name;
  const int fd = open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0600);
  if (fd < 0) Fail("cannot open " + path);
  const char* bytes = static_cast<const char*>(data);
  while (size > 0) {
    const ssize_t written = write(fd, bytes, size);
    if (written < 0 && errno == EINTR) continue;
    if (written <= 0) Fail("cannot write " + path);
    bytes += written;
    size -= static_cast<std::size_t>(written);
  }
  if (close(fd) != 0) Fail("cannot close " + path);
  return path;
}

std::string WriteScratchFile(const std::string& name, const std::string& text) {
  return WriteScratchFile(name, text.data(), text.size());
}

}  // namespace dwellfit::fuzz
