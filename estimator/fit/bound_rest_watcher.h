// BoundRestWatcher: notices a parameter that rests on its lower bound, so that
// the solve can hold it there as an equality (an active set).
//
// Ceres projects a trust-region step that crosses a bound back onto it, but
// rates the step by the decrease its linear model predicted for the
// unprojected step. While the cost pulls a parameter through its bound every
// step therefore rates poorly, the trust region shrinks and the solve
// creeps. With the parameter held at its bound the model is exact again.
//
// The watcher reads the watched entries after every successful step (needs
// ceres::Solver::Options::update_state_every_iteration) and stops the solve,
// with SOLVER_TERMINATE_SUCCESSFULLY, once one watched entry has sat exactly
// on its bound for `steps` successful steps in a row. It reads each entry
// twice: in the caller's block, and, where given, in the solver's iterate.
// The two differ with non-monotonic steps, where Ceres writes only the best
// point so far into the caller's blocks. resting_at_iterate() says that the
// iterate rested there and the best point did not.
#ifndef DWELLFIT_ESTIMATOR_FIT_BOUND_REST_WATCHER_H_
#define DWELLFIT_ESTIMATOR_FIT_BOUND_REST_WATCHER_H_

#include <optional>
#include <vector>

#include "ceres/iteration_callback.h"

namespace dwellfit {

class BoundRestWatcher : public ceres::IterationCallback {
 public:
  struct Bound {
    int index = 0;       // into the parameter block
    double lower = 0.0;  // the bound
  };
  // One watched entry of any block the solver updates.
  struct Entry {
    const double* value = nullptr;  // owned by the caller
    double lower = 0.0;             // its bound
    int id = 0;                     // what resting() reports
    // The entry in the solver's current iterate (owned by the caller), or
    // none: the caller's block shows the iterate.
    const double* iterate = nullptr;
  };

  // Entries of the one block `parameters` (owned by the caller); resting()
  // reports a Bound's index.
  BoundRestWatcher(const double* parameters, const std::vector<Bound>& watched, int steps);
  BoundRestWatcher(std::vector<Entry> watched, int steps);

  ceres::CallbackReturnType operator()(const ceres::IterationSummary& summary) override;

  // The id of the entry that stopped the solve by resting on its bound, if any.
  std::optional<int> resting() const { return resting_; }
  // Whether that entry rested on its bound in the iterate while the best
  // point (the caller's block) did not: the solve is best continued from
  // the iterate.
  bool resting_at_iterate() const { return resting_at_iterate_; }

 private:
  static std::vector<Entry> EntriesOf(const double* parameters, const std::vector<Bound>& watched);

  const std::vector<Entry> watched_;
  const int steps_;
  std::vector<int> steps_at_bound_;          // per watched parameter, best point
  std::vector<int> iterate_steps_at_bound_;  // per watched parameter, iterate
  std::optional<int> resting_;
  bool resting_at_iterate_ = false;
};

}  // namespace dwellfit

#endif  // DWELLFIT_ESTIMATOR_FIT_BOUND_REST_WATCHER_H_
