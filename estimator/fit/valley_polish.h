// The valley polish: a quasi-Newton finish for a trust-region solve that
// creeps along a weakly determined direction.
//
// Levenberg-Marquardt models the Hessian of F = (1/2) sum r^2 by J^T J,
// leaving out sum r_i d2r_i/dp2. Along a weakly determined direction
// (docs/model.md, Identifiability) that term cancels much of J^T J, so each
// step goes a fraction of the way and the cost falls about twice as much as
// predicted (step-quality ratio rho near 2).
//
// CreepWatcher stops a trust-region solve after `steps` successful steps in
// a row with rho above `min_ratio`. PolishAlongValley then minimises with
// BFGS (ceres::GradientProblemSolver), which learns the missing curvature,
// in coordinates whitened at the start: u = R (x [-] x0), R^T R = J^T J
// (jacobian_factor.h), so its first step is the Gauss-Newton step. A point
// past a bound is an evaluation that fails, and the line search steps back.
// Deterministic on any thread count.
#ifndef DWELLFIT_ESTIMATOR_FIT_VALLEY_POLISH_H_
#define DWELLFIT_ESTIMATOR_FIT_VALLEY_POLISH_H_

#include <string>
#include <vector>

#include "ceres/iteration_callback.h"
#include "ceres/problem.h"
#include "dwellfit/estimator/fit/identification_options.h"

namespace dwellfit {

class CreepWatcher : public ceres::IterationCallback {
 public:
  // `steps` >= 1, `min_ratio` > 1.
  CreepWatcher(int steps, double min_ratio);

  ceres::CallbackReturnType operator()(const ceres::IterationSummary& summary) override;

  // Whether it stopped the solve.
  bool creeping() const { return creeping_; }

 private:
  const int steps_;
  const double min_ratio_;
  int in_a_row_ = 0;
  bool creeping_ = false;
};

// The stages' setting: the bundled datasets' solves never reach it, the
// simulated sweeps of 1e5 and more dwells within ten steps.
inline constexpr int kCreepSteps = 4;
inline constexpr double kCreepRatio = 1.5;

struct ValleyPolish {
  bool improved = false;  // the blocks moved to a lower cost
  int iterations = 0;     // BFGS iterations
  double initial_cost = 0.0;
  double final_cost = 0.0;
  std::string message;  // why it did not run or what ended it
};

// Polishes `blocks` of `problem` (the others held) from their values,
// leaving them at the lower cost of the start and the end; `settings` give
// the iteration limit and function tolerance. A Jacobian that cannot be
// evaluated or factored leaves the blocks untouched.
ValleyPolish PolishAlongValley(ceres::Problem* problem, const std::vector<double*>& blocks,
                               const SolverSettings& settings);

}  // namespace dwellfit

#endif  // DWELLFIT_ESTIMATOR_FIT_VALLEY_POLISH_H_
