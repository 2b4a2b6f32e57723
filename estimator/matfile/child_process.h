// Running a piece of work in a child process, so that a library that is not
// memory-safe on damaged input cannot take the caller down with it. HDF5
// 1.10.8 (Debian's), which parses a MAT v7.3 file before libmatio sees a
// value, reads out of bounds and after free on damaged files: LoadSweepsMat
// reads v7.3 files this way, and a crash, a hang or an exhausted memory
// becomes a message about the file.
#ifndef DWELLFIT_ESTIMATOR_MATFILE_CHILD_PROCESS_H_
#define DWELLFIT_ESTIMATOR_MATFILE_CHILD_PROCESS_H_

#include <chrono>
#include <functional>
#include <string>

namespace dwellfit {

struct ChildOutcome {
  bool completed = false;  // `work` returned and the child exited normally
  std::string bytes;       // what `work` returned (when completed)
  std::string failure;     // why not completed, in words ("stopped by signal 11 ...")
};

// Forks; the child runs `work` on its only thread, with the crash signals'
// default actions and its standard error sent to /dev/null (a damaged file's
// HDF5 error stack is not the user's to read), hands the returned bytes back
// through a pipe and exits with _exit. The caller waits at most `limit` for
// the child's bytes and end; past it the child is killed. An exception
// thrown by `work` is a failure ("failed"); `work` reports the input's
// errors in its bytes.
//
// The child inherits the caller's memory as it was at the fork; `work` must
// not need another thread of the caller (a lock one holds stays held).
ChildOutcome RunInChildProcess(const std::function<std::string()>& work,
                               std::chrono::milliseconds limit);

}  // namespace dwellfit

#endif  // DWELLFIT_ESTIMATOR_MATFILE_CHILD_PROCESS_H_
