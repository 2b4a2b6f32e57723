#include "dwellfit/estimator/fit/bound_rest_watcher.h"

#include <utility>

#include "glog/logging.h"

namespace dwellfit {

BoundRestWatcher::BoundRestWatcher(const double* parameters, std::vector<Bound> watched, int steps)
    : parameters_(parameters),
      watched_(std::move(watched)),
      steps_(steps),
      steps_at_bound_(watched_.size(), 0) {
  CHECK(parameters != nullptr);
  CHECK_GE(steps, 1);
}

ceres::CallbackReturnType BoundRestWatcher::operator()(const ceres::IterationSummary& summary) {
  if (!summary.step_is_successful || summary.iteration == 0) return ceres::SOLVER_CONTINUE;
  for (size_t i = 0; i < watched_.size(); ++i) {
    const Bound& bound = watched_[i];
    steps_at_bound_[i] = parameters_[bound.index] == bound.lower ? steps_at_bound_[i] + 1 : 0;
    if (steps_at_bound_[i] >= steps_) {
      resting_ = bound.index;
      return ceres::SOLVER_TERMINATE_SUCCESSFULLY;
    }
  }
  return ceres::SOLVER_CONTINUE;
}

}  // namespace dwellfit
