// The valley polish: a quasi-Newton finish for a trust-region solve that
// creeps along a weakly determined direction.
//
// Levenberg-Marquardt steps with the Gauss-Newton model H = J^T J of the
// Hessian of F = (1/2) sum r^2, whose full Hessian is J^T J + sum r_i
// d2r_i/dp2. Along a weakly determined direction (docs/model.md,
// Identifiability) the second term cancels much of the first, so each step
// is a fraction of the way to the minimum and the cost falls about twice as
// much as the model predicts (rho = actual / predicted decrease near 2).
//
// CreepWatcher stops a trust-region solve after `steps` successful steps in
// a row with rho above `min_ratio`. PolishAlongValley then minimises the
// cost with BFGS (ceres::GradientProblemSolver), which learns the curvature
// J^T J leaves out from the gradients it meets, in coordinates whitened by
// the Gauss-Newton model at the start: u = R (x [-] x0) with R^T R = J^T J
// (jacobian_factor.h). There the model's Hessian is the identity, BFGS's
// first step is the Gauss-Newton step. Bounds (eta_e, mu1, mu2 >= 0) are not
// constraints of the polish: a point past one is an evaluation that fails,
// and the line search steps back. The trust-region solve then resumes from
// the polished point.
//
// Deterministic: the same evaluations in the same order on any thread count.
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
  // Stops after `steps` (>= 1) successful steps in a row whose step-quality
  // ratio exceeds `min_ratio` (> 1).
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

// The defaults of the stages: four steps in a row above 1.5 (the measured
// beam's and the bundled datasets' solves never reach it; the simulated
// sweeps of 1e5 and more dwells do within ten steps).
inline constexpr int kCreepSteps = 4;
inline constexpr double kCreepRatio = 1.5;

struct ValleyPolish {
  bool improved = false;  // the blocks moved to a lower cost
  int iterations = 0;     // BFGS iterations
  double initial_cost = 0.0;
  double final_cost = 0.0;
  std::string message;  // why it did not run or what ended it
};

// Polishes the blocks `blocks` of `problem` (all of its residual blocks; the
// other parameter blocks held) from their current values. Leaves them where
// the cost is lowest of the start and the polish's end; `settings` gives the
// iteration limit and the function tolerance. Never aborts: a Jacobian that
// cannot be evaluated or factored leaves the blocks untouched.
ValleyPolish PolishAlongValley(ceres::Problem* problem, const std::vector<double*>& blocks,
                               const SolverSettings& settings);

}  // namespace dwellfit

#endif  // DWELLFIT_ESTIMATOR_FIT_VALLEY_POLISH_H_
