// BoundRestWatcher: notices a parameter that rests on its lower bound, so that
// the solve can hold it there as an equality (an active set).
//
// Ceres projects a step that crosses a bound back onto it but rates it by
// the decrease predicted for the unprojected step: while the cost pulls a
// parameter through its bound every step rates poorly and the solve creeps.
// Held at its bound, the model is exact again.
//
// After every successful step (needs update_state_every_iteration) the
// watcher stops the solve, with SOLVER_TERMINATE_SUCCESSFULLY, once an entry
// has sat exactly on its bound for `steps` successful steps in a row, in the
// caller's block or, where given, in the solver's iterate (they differ with
// non-monotonic steps, where Ceres writes only the best point so far).
#ifndef DWELLFIT_ESTIMATOR_FIT_BOUND_REST_WATCHER_H_
#define DWELLFIT_ESTIMATOR_FIT_BOUND_REST_WATCHER_H_

#include <optional>
#include <vector>

#include "ceres/iteration_callback.h"

namespace dwellfit {

class BoundRestWatcher : public ceres::IterationCallback {
 public:
  // One watched entry of any block the solver updates.
  struct Entry {
    const double* value = nullptr;  // owned by the caller
    double lower = 0.0;             // its bound
    int id = 0;                     // what resting() reports
    // The entry in the solver's current iterate (owned by the caller), or
    // none: the caller's block shows the iterate.
    const double* iterate = nullptr;
  };

  BoundRestWatcher(std::vector<Entry> watched, int steps);

  ceres::CallbackReturnType operator()(const ceres::IterationSummary& summary) override;

  // The id of the entry that stopped the solve by resting on its bound, if any.
  std::optional<int> resting() const { return resting_; }
  // Whether it rested in the iterate while the best point did not: the
  // solve is best continued from the iterate.
  bool resting_at_iterate() const { return resting_at_iterate_; }

 private:
  const std::vector<Entry> watched_;
  const int steps_;
  std::vector<int> steps_at_bound_;          // per watched parameter, best point
  std::vector<int> iterate_steps_at_bound_;  // per watched parameter, iterate
  std::optional<int> resting_;
  bool resting_at_iterate_ = false;
};

}  // namespace dwellfit

#endif  // DWELLFIT_ESTIMATOR_FIT_BOUND_REST_WATCHER_H_
