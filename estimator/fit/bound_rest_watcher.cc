#include "dwellfit/estimator/fit/bound_rest_watcher.h"

#include <utility>

#include "glog/logging.h"

namespace dwellfit {

BoundRestWatcher::BoundRestWatcher(std::vector<Entry> watched, int steps)
    : watched_(std::move(watched)),
      steps_(steps),
      steps_at_bound_(watched_.size(), 0),
      iterate_steps_at_bound_(watched_.size(), 0) {
  for (const Entry& entry : watched_) CHECK(entry.value != nullptr);
  CHECK_GE(steps, 1);
}

ceres::CallbackReturnType BoundRestWatcher::operator()(const ceres::IterationSummary& summary) {
  if (!summary.step_is_successful || summary.iteration == 0) return ceres::SOLVER_CONTINUE;
  for (size_t i = 0; i < watched_.size(); ++i) {
    const Entry& entry = watched_[i];
    steps_at_bound_[i] = *entry.value == entry.lower ? steps_at_bound_[i] + 1 : 0;
    const double* iterate = entry.iterate != nullptr ? entry.iterate : entry.value;
    iterate_steps_at_bound_[i] = *iterate == entry.lower ? iterate_steps_at_bound_[i] + 1 : 0;
    if (steps_at_bound_[i] >= steps_ || iterate_steps_at_bound_[i] >= steps_) {
      resting_ = entry.id;
      resting_at_iterate_ = steps_at_bound_[i] < steps_;
      return ceres::SOLVER_TERMINATE_SUCCESSFULLY;
    }
  }
  return ceres::SOLVER_CONTINUE;
}

}  // namespace dwellfit
