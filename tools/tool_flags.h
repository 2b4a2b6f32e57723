// The flag every tool has (--verbose), and what reaches the user's terminal
// from glog (tool_main.h parses the command line).
//
// Ceres logs through glog:
// a residual that cannot be evaluated at a trial step (a fold the step
// jumped past) prints its 25-line "Error in evaluating the ResidualBlock"
// dump as a WARNING, though the solver merely rejects the step. So glog
// itself writes nothing but FATAL to stderr and no log files, and a
// ToolLogSink prints the run's own warnings and errors (the library's
// LOG(WARNING) lines: dropped CSV rows, weak jump evidence, failed starts)
// as "<tool>: warning: <text>", and nothing from Ceres' files. `--verbose`
// or `--v=N` (N > 0) shows everything: Ceres' lines and the fit's VLOG
// trace. glog's own flags still work as documented (`--logtostderr`,
// `--stderrthreshold=0`, `--log_dir`): these are only defaults, set before
// the command line is parsed.
//
// Each tool is one translation unit (tools/CMakeLists.txt), so the flag
// below is defined once per program.
#ifndef DWELLFIT_TOOLS_TOOL_FLAGS_H_
#define DWELLFIT_TOOLS_TOOL_FLAGS_H_

#include <cstring>
#include <iostream>
#include <mutex>
#include <string>
#include <utility>
#include <vector>

#include "gflags/gflags.h"
#include "glog/logging.h"

DEFINE_bool(verbose, false,
            "Shows every log line, Ceres' internal messages included (as --v=1 does, with the "
            "fit's trace)");

namespace dwellfit {

// True for a log line from Ceres' own sources (internal/ceres/..., include/ceres/...).
inline bool FromCeres(const char* full_filename) {
  return full_filename != nullptr && std::strstr(full_filename, "ceres/") != nullptr;
}

// Prints glog's messages that the user should see on stderr, in the tool's
// words (see the top of this file). glog calls send() from whichever thread
// logs, so lines are written under a mutex, each whole.
class ToolLogSink : public google::LogSink {
 public:
  explicit ToolLogSink(std::string tool) : tool_(std::move(tool)) {}

  void send(google::LogSeverity severity, const char* full_filename, const char* base_filename,
            int line, const google::LogMessageTime& /*time*/, const char* message,
            size_t message_len) override {
    // glog prints these itself (--logtostderr, --alsologtostderr, --stderrthreshold).
    if (FLAGS_logtostderr || FLAGS_alsologtostderr || severity >= FLAGS_stderrthreshold) return;
    const bool verbose = FLAGS_verbose || FLAGS_v > 0;
    if (!verbose && (severity < google::GLOG_WARNING || FromCeres(full_filename))) return;
    const std::lock_guard<std::mutex> lock(mutex_);
    std::cerr << tool_ << ": ";
    if (severity >= google::GLOG_ERROR) {
      std::cerr << "error: ";
    } else if (severity == google::GLOG_WARNING) {
      std::cerr << "warning: ";
    }
    if (verbose) std::cerr << "[" << base_filename << ":" << line << "] ";
    std::cerr.write(message, static_cast<std::streamsize>(message_len));
    std::cerr << "\n";
  }

 private:
  std::string tool_;
  std::mutex mutex_;
};

// Routes glog as the top of this file says: no log files, stderr from glog
// only for FATAL, a ToolLogSink for the rest. Call before parsing the flags
// (they may change these defaults).
inline void QuietLibraryLogging(const char* tool) {
  FLAGS_logtostderr = false;
  FLAGS_alsologtostderr = false;
  FLAGS_stderrthreshold = google::GLOG_FATAL;
  for (google::LogSeverity severity = google::GLOG_INFO; severity < google::NUM_SEVERITIES;
       ++severity) {
    google::SetLogDestination(severity, "");  // an empty name: no log file
  }
  // Added once, however often this is called; lives as long as the program.
  static ToolLogSink* const sink = [tool] {
    auto* added = new ToolLogSink(tool);
    google::AddLogSink(added);
    return added;
  }();
  (void)sink;
}

}  // namespace dwellfit

#endif  // DWELLFIT_TOOLS_TOOL_FLAGS_H_
