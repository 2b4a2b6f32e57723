#include "dwellfit/estimator/run/output_files.h"

#include <fcntl.h>
#include <signal.h>
#include <sys/file.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cstring>
#include <filesystem>
#include <memory>
#include <sstream>

#include "dwellfit/estimator/common/input_error.h"
#include "dwellfit/estimator/common/version.h"
#include "yaml-cpp/yaml.h"

namespace dwellfit {
namespace {

namespace fs = std::filesystem;

constexpr char kStagingPrefix[] = ".dwellfit-staging-";
constexpr char kLegacyPartialMarker[] = ".partial-";
constexpr char kLockFileName[] = ".dwellfit-lock";

// `field`: the config key or flag that named the path.
[[noreturn]] void ThrowOutputError(const fs::path& path, const std::string& what,
                                   const std::string& field = "output_dir") {
  throw InputError(path.string(), 0, field,
                   what + "; give " + field + " a path that can be written");
}

// The process id that ends `name` after `marker`, or 0 when there is none.
pid_t PidAfter(const std::string& name, const std::string& marker) {
  const std::size_t at = name.rfind(marker);
  if (at == std::string::npos) return 0;
  const char* begin = name.data() + at + marker.size();
  const char* end = name.data() + name.size();
  pid_t pid = 0;
  const auto [stop, error] = std::from_chars(begin, end, pid);
  return error == std::errc() && stop == end && pid > 0 ? pid : 0;
}

bool ProcessIsGone(pid_t pid) { return ::kill(pid, 0) == -1 && errno == ESRCH; }

// Removes staging folders and partial files whose writing process is gone.
void RemoveStaleStaging(const fs::path& directory) {
  std::error_code error;
  for (const fs::directory_entry& entry : fs::directory_iterator(directory, error)) {
    const std::string name = entry.path().filename().string();
    const bool staging = name.rfind(kStagingPrefix, 0) == 0;
    const pid_t pid = PidAfter(name, staging ? kStagingPrefix : kLegacyPartialMarker);
    if (pid == 0 || pid == ::getpid() || !ProcessIsGone(pid)) continue;
    std::error_code ignored;
    fs::remove_all(entry.path(), ignored);
  }
}

// A file being written: Write() starts writing to the disk without waiting,
// Flush() waits until it is there, so that files flushed together reach the
// disk in one journal commit rather than one each.
class DurableFile {
 public:
  DurableFile(fs::path path, std::string field) : path_(std::move(path)), field_(std::move(field)) {
    fd_ = ::open(path_.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
    if (fd_ < 0) Fail();
  }
  ~DurableFile() {
    if (fd_ >= 0) ::close(fd_);
  }
  DurableFile(const DurableFile&) = delete;
  DurableFile& operator=(const DurableFile&) = delete;

  void Write(const std::string& content) {
    std::size_t done = 0;
    while (done < content.size()) {
      const ssize_t n = ::write(fd_, content.data() + done, content.size() - done);
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0) break;
      done += static_cast<std::size_t>(n);
    }
    if (done != content.size()) Fail();
    // A hint: where the file system cannot start the writing early, Flush()
    // still writes everything.
    ::sync_file_range(fd_, 0, 0, SYNC_FILE_RANGE_WRITE);
  }

  void Flush() {
    if (::fsync(fd_) != 0) Fail();
    const int fd = fd_;
    fd_ = -1;
    if (::close(fd) != 0) Fail();
  }

 private:
  [[noreturn]] void Fail() {
    ThrowOutputError(path_, std::string("cannot write (") + std::strerror(errno) + ")", field_);
  }

  fs::path path_;
  std::string field_;
  int fd_ = -1;
};

// Writes each (name, content) of `files` and the manifest into `directory`,
// then flushes them all.
void WriteDurably(const fs::path& directory,
                  const std::vector<std::pair<std::string, std::string>>& files,
                  const std::string& manifest) {
  std::vector<std::unique_ptr<DurableFile>> written;
  written.reserve(files.size() + 1);
  const auto write = [&](const std::string& name, const std::string& content) {
    written.push_back(std::make_unique<DurableFile>(directory / name, "output_dir"));
    written.back()->Write(content);
  };
  for (const auto& [name, content] : files) write(name, content);
  write(kManifestFileName, manifest);
  for (const std::unique_ptr<DurableFile>& file : written) file->Flush();
}

std::string Manifest(const std::vector<std::pair<std::string, std::string>>& files) {
  std::ostringstream out;
  out << "# The files of one complete dwellfit run; written after all of them.\n"
      << "dwellfit_version: " << DwellfitVersion() << "\nfiles:\n";
  for (const auto& [name, content] : files) {
    out << "  - {name: " << name << ", bytes: " << content.size() << "}\n";
  }
  return out.str();
}

// Holds an exclusive lock on the directory's lock file while alive, so that
// two runs into one directory publish one after the other.
class DirectoryLock {
 public:
  explicit DirectoryLock(const fs::path& directory) {
    const fs::path path = directory / kLockFileName;
    fd_ = ::open(path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
    if (fd_ < 0 || ::flock(fd_, LOCK_EX) != 0) {
      const std::string reason = std::strerror(errno);
      if (fd_ >= 0) ::close(fd_);
      ThrowOutputError(path, "cannot lock the output directory (" + reason + ")");
    }
  }
  ~DirectoryLock() { ::close(fd_); }
  DirectoryLock(const DirectoryLock&) = delete;
  DirectoryLock& operator=(const DirectoryLock&) = delete;

 private:
  int fd_ = -1;
};

// The files the previous run's manifest in `directory` lists that this run's
// `files` do not hold (figures of a run with figures, before one without):
// plain names only, never a path out of the directory. None without a
// readable manifest.
std::vector<std::string> PreviousRunsOtherFiles(
    const fs::path& directory, const std::vector<std::pair<std::string, std::string>>& files) {
  std::vector<std::string> stale;
  try {
    const YAML::Node manifest = YAML::LoadFile((directory / kManifestFileName).string());
    for (const YAML::Node& entry : manifest["files"]) {
      const std::string name = entry["name"].as<std::string>();
      const bool kept = std::any_of(files.begin(), files.end(),
                                    [&name](const auto& file) { return file.first == name; });
      if (!kept && fs::path(name) == fs::path(name).filename() && name != ".." && name != ".") {
        stale.push_back(name);
      }
    }
  } catch (const YAML::Exception&) {
  }
  return stale;
}

void MoveIntoPlace(const fs::path& staging, const fs::path& directory,
                   const std::vector<std::pair<std::string, std::string>>& files) {
  std::error_code error;
  const std::vector<std::string> stale = PreviousRunsOtherFiles(directory, files);
  fs::remove(directory / kManifestFileName, error);
  if (error)
    ThrowOutputError(directory / kManifestFileName, "cannot replace (" + error.message() + ")");
  const auto move = [&](const std::string& name, const std::string& what) {
    fs::rename(staging / name, directory / name, error);
    if (error) {
      ThrowOutputError(directory / name,
                       "cannot move the " + what + " into place (" + error.message() + ")");
    }
  };
  for (const auto& [name, content] : files) move(name, "result");
  for (const std::string& name : stale) fs::remove(directory / name, error);
  move(kManifestFileName, "manifest");
}

}  // namespace

void CheckOutputDirectory(const std::string& directory, const std::string& field) {
  std::error_code error;
  fs::path path = fs::absolute(directory, error);
  if (error) path = directory;
  const fs::path requested = path;
  while (!fs::exists(path, error) && path.has_relative_path()) path = path.parent_path();
  const auto fail = [&](const std::string& what) {
    throw InputError(requested.string(), 0, field, what + "; choose another output_dir");
  };
  if (!fs::is_directory(path, error)) {
    fail("'" + path.string() + "' is not a directory, so the results cannot be written there");
  }
  if (::access(path.c_str(), W_OK | X_OK) != 0) {
    fail("the directory '" + path.string() + "' is not writable (" + std::strerror(errno) + ")");
  }
}

void WriteFilesAtomically(const std::string& directory,
                          const std::vector<std::pair<std::string, std::string>>& files) {
  std::error_code error;
  fs::create_directories(directory, error);
  if (error || !fs::is_directory(directory)) {
    ThrowOutputError(directory, "cannot create the output directory (" +
                                    (error ? error.message() : "not a directory") + ")");
  }
  const fs::path dir(directory);
  RemoveStaleStaging(dir);
  const fs::path staging = dir / (kStagingPrefix + std::to_string(::getpid()));
  fs::remove_all(staging, error);
  fs::create_directory(staging, error);
  if (error) ThrowOutputError(staging, "cannot create a staging folder (" + error.message() + ")");
  try {
    WriteDurably(staging, files, Manifest(files));
    const DirectoryLock lock(dir);
    MoveIntoPlace(staging, dir, files);
  } catch (...) {
    fs::remove_all(staging, error);
    throw;
  }
  fs::remove_all(staging, error);
}

void WriteReportAtomically(const std::string& path, const std::string& text,
                           const std::string& field) {
  const fs::path target(path);
  const fs::path staged = target.string() + kLegacyPartialMarker + std::to_string(::getpid());
  {
    DurableFile file(staged, field);
    file.Write(text);
    file.Flush();
  }
  std::error_code error;
  fs::rename(staged, target, error);
  if (error) {
    fs::remove(staged, error);
    ThrowOutputError(target, "cannot move the report into place", field);
  }
}

}  // namespace dwellfit
