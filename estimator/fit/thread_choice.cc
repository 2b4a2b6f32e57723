#include "dwellfit/estimator/fit/thread_choice.h"

#include <fcntl.h>
#include <sys/sysinfo.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>

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

int IdleProcessors() {
  // "0.38 0.48 1.02 1/78 7400": the fourth field is runnable/all tasks.
  const int fd = open("/proc/loadavg", O_RDONLY | O_CLOEXEC);
  if (fd < 0) return -1;
  char text[128];
  const ssize_t length = read(fd, text, sizeof(text) - 1);
  close(fd);
  if (length <= 0) return -1;
  text[length] = '\0';
  int runnable = 0;
  if (std::sscanf(text, "%*s %*s %*s %d/", &runnable) != 1 || runnable < 1) return -1;
  return std::max(0, get_nprocs() - runnable);
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
  if (idle_probe_() == 0) {
    prefer_threaded_ = false;
    trial_interval_ = kFirstTrialAfter;
  }
}

bool ThreadChoice::Next() {
  if (new_history_) StartNewHistory();
  bool trial = false;
  // A trial is measured against the median of three of the preferred way
  // taken by this choice.
  const RecentTimes& preferred = prefer_threaded_ ? threaded_times_ : alone_times_;
  if (confirm_left_ == 0 && ++since_trial_ >= trial_interval_ &&
      preferred.count >= kTimesCompared) {
    since_trial_ = 0;
    // Threads with no idle processor to run on: put off, the wait doubled
    // as after a trial lost.
    trial = prefer_threaded_ || idle_probe_() != 0;
    if (!trial) {
      LengthenTheWait();
      history_->trial_interval.store(trial_interval_, std::memory_order_relaxed);
    }
  }
  history_->since_trial.store(since_trial_, std::memory_order_relaxed);
  return trial ? !prefer_threaded_ : prefer_threaded_;
}

bool ThreadChoice::Faster(bool threaded, double seconds, double other_seconds) {
  return threaded ? kThreadedMargin * seconds <= other_seconds
                  : seconds < kThreadedMargin * other_seconds;
}

void ThreadChoice::Record(bool threaded, double seconds) {
  if (!timed_first_) {  // the first evaluation of a solve: cold, not timed
    timed_first_ = true;
    return;
  }
  history_->timed.fetch_add(1, std::memory_order_relaxed);
  RecentTimes& times = threaded ? threaded_times_ : alone_times_;
  const RecentTimes& other = threaded ? alone_times_ : threaded_times_;
  times.Add(seconds);
  if (threaded != prefer_threaded_) {  // a trial
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
