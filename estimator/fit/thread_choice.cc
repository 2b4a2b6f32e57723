#include "dwellfit/estimator/fit/thread_choice.h"

#include <dirent.h>
#include <fcntl.h>
#include <sys/sysinfo.h>
#include <unistd.h>

#include <algorithm>
#include <cstddef>
#include <cstdio>
#include <cstring>

#include "glog/logging.h"

namespace dwellfit {

namespace {
std::atomic<int> last_preferred_way{0};
}  // namespace

int ThreadChoiceHistory::LastPreferredWay() {
  return last_preferred_way.load(std::memory_order_relaxed);
}

ThreadChoiceHistory& ThreadChoiceHistory::ForKind(int kind) {
  static ThreadChoiceHistory histories[kKinds];
  static const bool marked = [] {
    for (ThreadChoiceHistory& history : histories) history.shared = true;
    return true;
  }();
  (void)marked;
  CHECK(kind >= 0 && kind < kKinds);
  return histories[kind];
}

namespace {

// Reads the small file `path` (a /proc file) into `text`, ending it with a
// NUL; false where it cannot be read.
template <std::size_t kSize>
bool ReadSmallFile(const char* path, char (&text)[kSize]) {
  const int fd = open(path, O_RDONLY | O_CLOEXEC);
  if (fd < 0) return false;
  const ssize_t length = read(fd, text, kSize - 1);
  close(fd);
  if (length <= 0) return false;
  text[length] = '\0';
  return true;
}

// The runnable tasks of the machine (/proc/loadavg's "runnable/all": "0.38
// 0.48 1.02 1/78 7400"), the caller among them; -1 where it cannot be read.
int RunnableTasks() {
  char text[128];
  if (!ReadSmallFile("/proc/loadavg", text)) return -1;
  int runnable = 0;
  if (std::sscanf(text, "%*s %*s %*s %d/", &runnable) != 1 || runnable < 1) return -1;
  return runnable;
}

// Whether the thread `tid` of this process is running or runnable (state R
// in /proc/self/task/<tid>/stat, after the name in parentheses).
bool ThreadRunnable(const char* tid) {
  char path[64];
  std::snprintf(path, sizeof(path), "/proc/self/task/%s/stat", tid);
  char text[512];
  if (!ReadSmallFile(path, text)) return false;
  const char* name_end = std::strrchr(text, ')');
  return name_end != nullptr && name_end[1] == ' ' && name_end[2] == 'R';
}

}  // namespace

int OwnRunnableThreads() {
  DIR* tasks = opendir("/proc/self/task");
  if (tasks == nullptr) return 1;
  int runnable = 0;
  while (const dirent* entry = readdir(tasks)) {
    if (entry->d_name[0] != '.' && ThreadRunnable(entry->d_name)) ++runnable;
  }
  closedir(tasks);
  return std::max(runnable, 1);
}

int IdleProcessors() {
  const int runnable = RunnableTasks();
  if (runnable < 0) return -1;
  // Besides the caller's: the processors less the other programs' tasks
  // (none where the caller is the only task runnable).
  const int others = runnable == 1 ? 0 : std::max(0, runnable - OwnRunnableThreads());
  return std::max(0, get_nprocs() - 1 - others);
}

ThreadChoice::ThreadChoice(ThreadChoiceHistory* history, IdleProbe idle_probe)
    : history_(history), idle_probe_(idle_probe) {
  const int way = history->preferred_way.load(std::memory_order_relaxed);
  if (way == 0) {  // a new history: its start waits for the first Next
    new_history_ = true;
    return;
  }
  prefer_threaded_ = way == 1;
  trial_interval_ = history->trial_interval.load(std::memory_order_relaxed);
  since_trial_ = history->since_trial.load(std::memory_order_relaxed);
}

double ThreadChoice::RecentTimes::Typical() const {
  if (count == 0) return 0.0;
  if (count < static_cast<int>(seconds.size())) {
    return *std::min_element(seconds.begin(), seconds.begin() + count);
  }
  std::array<double, 3> sorted = seconds;
  std::sort(sorted.begin(), sorted.end());
  return sorted[1];
}

void ThreadChoice::StartNewHistory() {
  new_history_ = false;
  favour_threads_ = idle_probe_() != 0;
  if (!favour_threads_) {
    prefer_threaded_ = false;
    trial_interval_ = kFirstTrialAfter;
  }
}

bool ThreadChoice::Next() {
  if (new_history_) StartNewHistory();
  if (last_ == Evaluation::kWarmUp) {  // the trial the warm-up woke the workers for
    last_ = Evaluation::kTrial;
    return true;
  }
  bool trial = false;
  // A trial is measured against the median of three of the preferred way
  // taken by this choice.
  const RecentTimes& preferred = prefer_threaded_ ? threaded_times_ : alone_times_;
  if (confirm_left_ == 0 && ++since_trial_ >= trial_interval_ &&
      preferred.count >= kTimesCompared) {
    since_trial_ = 0;
    // The machine decides which way the margin favours; threads with no
    // idle processor to run on are not tried: put off, the wait doubled as
    // after a trial lost.
    favour_threads_ = idle_probe_() != 0;
    trial = prefer_threaded_ || favour_threads_;
    if (!trial) {
      LengthenTheWait();
      history_->trial_interval.store(trial_interval_, std::memory_order_relaxed);
    }
  }
  history_->since_trial.store(since_trial_, std::memory_order_relaxed);
  // A trial of the threads starts with an evaluation that wakes the workers.
  last_ = !trial             ? Evaluation::kPreferred
          : prefer_threaded_ ? Evaluation::kTrial
                             : Evaluation::kWarmUp;
  return trial ? !prefer_threaded_ : prefer_threaded_;
}

bool ThreadChoice::Faster(bool threaded, double seconds, double other_seconds) const {
  // The favoured way wins unless it takes kThreadedMargin times as long;
  // the other must be kThreadedMargin times faster.
  return threaded == favour_threads_ ? seconds < kThreadedMargin * other_seconds
                                     : kThreadedMargin * seconds <= other_seconds;
}

void ThreadChoice::Record(bool threaded, double seconds) {
  if (!timed_first_) {  // the first evaluation of a solve: cold, not timed
    timed_first_ = true;
    return;
  }
  if (last_ == Evaluation::kWarmUp) return;  // the workers just woken: not timed
  history_->timed.fetch_add(1, std::memory_order_relaxed);
  RecentTimes& times = threaded ? threaded_times_ : alone_times_;
  const RecentTimes& other = threaded ? alone_times_ : threaded_times_;
  times.Add(seconds);
  if (last_ == Evaluation::kTrial) {
    if (other.count > 0 && Faster(threaded, seconds, other.Typical())) {
      prefer_threaded_ = threaded;
      trial_interval_ = kTrialInterval;
      since_trial_ = 0;
      confirm_left_ = kConfirmations;
    } else {
      LengthenTheWait();
    }
  } else if (confirm_left_ > 0 && --confirm_left_ == 0 &&
             !Faster(threaded, times.Typical(), other.Typical())) {
    prefer_threaded_ = !threaded;  // the switch did not hold
    trial_interval_ = 2 * kTrialInterval;
    since_trial_ = 0;
  }
  Publish();
}

void ThreadChoice::LengthenTheWait() {
  trial_interval_ = std::clamp(2 * trial_interval_, kTrialInterval, kMaxTrialInterval);
}

void ThreadChoice::Publish() {
  history_->preferred_way.store(prefer_threaded_ ? 1 : 2, std::memory_order_relaxed);
  if (history_->shared)
    last_preferred_way.store(prefer_threaded_ ? 1 : 2, std::memory_order_relaxed);
  history_->trial_interval.store(trial_interval_, std::memory_order_relaxed);
  history_->since_trial.store(since_trial_, std::memory_order_relaxed);
}

}  // namespace dwellfit
