// Checks a cost function's Jacobian against ceres::GradientChecker's finite
// differences, in the solver's units.
#ifndef DWELLFIT_TESTS_FUNCTORS_JACOBIAN_CHECK_H_
#define DWELLFIT_TESTS_FUNCTORS_JACOBIAN_CHECK_H_

#include <algorithm>
#include <cmath>
#include <vector>

#include "ceres/gradient_checker.h"
#include "dwellfit/residuals/model/model_parameters.h"
#include "gtest/gtest.h"

namespace dwellfit {

// Each row r of the Jacobian J at `p` against the finite differences F:
// |J_rj - F_rj| |p_j| <= tolerance max_j |J_rj p_j| (column j scaled by
// |p_j|, relative to the row's largest scaled entry), so that an entry that
// is exactly zero (a branch end that does not move with eta_e) is compared
// with the finite difference's round-off, not divided by it. GradientChecker
// differentiates by Ridders' extrapolation; its default first step (a large
// fraction of each parameter) crosses folds and changes branches, while a
// residual is a local function of the parameters near a jump, so the steps
// start at 1e-6 relative. A Jacobian that is zero throughout fails: nothing
// would be compared (a penalty's inactive rows may be zero).
inline void ExpectJacobianMatchesFiniteDifferences(const ceres::CostFunction& cost,
                                                   ParameterVector p, double tolerance) {
  ceres::NumericDiffOptions numeric;
  numeric.ridders_relative_initial_step_size = 1e-6;
  const std::vector<const ceres::Manifold*>* euclidean = nullptr;
  ceres::GradientChecker checker(&cost, euclidean, numeric);
  ceres::GradientChecker::ProbeResults results;
  std::vector<double*> blocks = {p.data()};
  checker.Probe(blocks.data(), tolerance, &results);
  ASSERT_TRUE(results.return_value);
  const Eigen::MatrixXd& user = results.jacobians[0];
  const Eigen::MatrixXd& fd = results.numeric_jacobians[0];
  bool any_nonzero = false;
  for (int row = 0; row < user.rows(); ++row) {
    double largest = 0.0;
    for (int j = 0; j < kNumParameters; ++j) {
      largest = std::max(largest, std::abs(user(row, j) * p[j]));
    }
    any_nonzero = any_nonzero || largest > 0.0;
    for (int j = 0; j < kNumParameters; ++j) {
      EXPECT_LE(std::abs(user(row, j) - fd(row, j)) * std::abs(p[j]), tolerance * largest)
          << "row " << row << " " << ParameterName(j) << ": autodiff " << user(row, j)
          << " finite differences " << fd(row, j);
    }
  }
  EXPECT_TRUE(any_nonzero) << "the Jacobian is zero: nothing was compared";
}

}  // namespace dwellfit

#endif  // DWELLFIT_TESTS_FUNCTORS_JACOBIAN_CHECK_H_
