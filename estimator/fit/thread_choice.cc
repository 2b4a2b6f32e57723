#include "dwellfit/estimator/fit/thread_choice.h"

#include <algorithm>

#include "glog/logging.h"

namespace dwellfit {

ThreadChoiceHistory& ThreadChoiceHistory::ForKind(int kind) {
  static ThreadChoiceHistory histories[kKinds];
  CHECK(kind >= 0 && kind < kKinds);
  return histories[kind];
}

ThreadChoice::ThreadChoice(ThreadChoiceHistory* history) : history_(history) {
  const int way = history->preferred_way.load(std::memory_order_relaxed);
  if (way == 0) return;  // a new history: threads first, a trial after three
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

bool ThreadChoice::Next() {
  bool trial = false;
  // A trial is measured against the median of three of the preferred way
  // taken by this choice.
  const RecentTimes& preferred = prefer_threaded_ ? threaded_times_ : alone_times_;
  if (confirm_left_ == 0 && ++since_trial_ >= trial_interval_ &&
      preferred.count >= kTimesCompared) {
    since_trial_ = 0;
    trial = true;
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
      trial_interval_ = std::clamp(2 * trial_interval_, kTrialInterval, kMaxTrialInterval);
    }
  } else if (confirm_left_ > 0 && --confirm_left_ == 0 &&
             !Faster(threaded, times.Typical(), other.Typical())) {
    prefer_threaded_ = !threaded;  // the switch did not hold
    trial_interval_ = 2 * kTrialInterval;
    since_trial_ = 0;
  }
  Publish();
}

void ThreadChoice::Publish() {
  history_->preferred_way.store(prefer_threaded_ ? 1 : 2, std::memory_order_relaxed);
  history_->trial_interval.store(trial_interval_, std::memory_order_relaxed);
  history_->since_trial.store(since_trial_, std::memory_order_relaxed);
}

}  // namespace dwellfit
