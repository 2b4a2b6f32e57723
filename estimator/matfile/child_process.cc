#include "dwellfit/estimator/matfile/child_process.h"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <exception>

#include "dwellfit/estimator/common/string_printf.h"

// Built with a sanitizer (GCC defines the first, Clang answers the second).
#if defined(__SANITIZE_ADDRESS__)
#define DWELLFIT_SANITIZED 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define DWELLFIT_SANITIZED 1
#endif
#endif
#ifdef DWELLFIT_SANITIZED
#include <sanitizer/common_interface_defs.h>
#endif

namespace dwellfit {
namespace {

// Exit codes of the child besides 0.
constexpr int kWorkThrew = 101;
constexpr int kPipeFailed = 102;

bool WriteAll(int fd, const std::string& bytes) {
  std::size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t n = write(fd, bytes.data() + done, bytes.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return false;
    done += static_cast<std::size_t>(n);
  }
  return true;
}

[[noreturn]] void RunChild(const std::function<std::string()>& work, int out) {
  // The caller's handlers (a fuzzer's, a sanitizer's) would report the
  // child's crash as the caller's: a fuzzer would write the caller's input as
  // a crash of its own.
  for (int signal_number : {SIGSEGV, SIGBUS, SIGABRT, SIGFPE, SIGILL, SIGPIPE}) {
    signal(signal_number, SIG_DFL);
  }
#ifdef DWELLFIT_SANITIZED
  __sanitizer_set_death_callback(nullptr);
#endif
  const int null = open("/dev/null", O_WRONLY | O_CLOEXEC);
  if (null >= 0) dup2(null, STDERR_FILENO);
  int code = 0;
  try {
    code = WriteAll(out, work()) ? 0 : kPipeFailed;
  } catch (...) {
    code = kWorkThrew;
  }
  _exit(code);
}

// Reads `fd` to its end into `bytes`, until `deadline`; false when the
// deadline passed first.
bool ReadUntil(int fd, std::chrono::steady_clock::time_point deadline, std::string* bytes) {
  char buffer[65536];
  for (;;) {
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(
        deadline - std::chrono::steady_clock::now());
    if (left.count() <= 0) return false;
    pollfd poll_fd{fd, POLLIN, 0};
    const int ready = poll(&poll_fd, 1, static_cast<int>(std::min<long long>(left.count(), 1000)));
    if (ready < 0 && errno != EINTR) return true;  // the pipe is gone: the child's status tells
    if (ready <= 0) continue;
    const ssize_t n = read(fd, buffer, sizeof(buffer));
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return true;
    bytes->append(buffer, static_cast<std::size_t>(n));
  }
}

std::string DescribeStatus(int status) {
  if (WIFSIGNALED(status)) {
    const int number = WTERMSIG(status);
    const char* name = strsignal(number);
    return "stopped by signal " + std::to_string(number) +
           (name ? std::string(" (") + name + ")" : "");
  }
  if (WIFEXITED(status)) {
    const int code = WEXITSTATUS(status);
    if (code == kWorkThrew) return "failed";
    if (code == kPipeFailed) return "could not hand its result back";
    return "ended with exit code " + std::to_string(code);
  }
  return "ended abnormally";
}

}  // namespace

ChildOutcome RunInChildProcess(const std::function<std::string()>& work,
                               std::chrono::milliseconds limit) {
  ChildOutcome outcome;
  int fds[2];
  if (pipe2(fds, O_CLOEXEC) != 0) {
    outcome.failure = std::string("could not start: pipe: ") + std::strerror(errno);
    return outcome;
  }
  const pid_t pid = fork();
  if (pid < 0) {
    outcome.failure = std::string("could not start: fork: ") + std::strerror(errno);
    close(fds[0]);
    close(fds[1]);
    return outcome;
  }
  if (pid == 0) {
    close(fds[0]);
    RunChild(work, fds[1]);
  }
  close(fds[1]);
  const bool in_time = ReadUntil(fds[0], std::chrono::steady_clock::now() + limit, &outcome.bytes);
  close(fds[0]);
  if (!in_time) kill(pid, SIGKILL);
  int status = 0;
  while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  if (!in_time) {
    outcome.failure = StringPrintf("took longer than %.3g s", limit.count() / 1000.0);
  } else if (WIFEXITED(status) && WEXITSTATUS(status) == 0) {
    outcome.completed = true;
    return outcome;
  } else {
    outcome.failure = DescribeStatus(status);
  }
  outcome.bytes.clear();
  return outcome;
}

}  // namespace dwellfit
