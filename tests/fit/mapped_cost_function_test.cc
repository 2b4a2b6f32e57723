// MappedCostFunction: the six parameters gathered from the caller's blocks
// and the Jacobian scattered back, checked by ceres::GradientChecker.
#include "dwellfit/estimator/fit/mapped_cost_function.h"

#include <memory>
#include <vector>

#include "ceres/gradient_checker.h"
#include "dwellfit/residuals/functors/algebraic_residual.h"
#include "dwellfit/residuals/functors/vertical_error_residual.h"
#include "gtest/gtest.h"
#include "tests/fit_test_support.h"

namespace dwellfit {
namespace {

// The model's Jacobian (1 x 6) at `p` and the mapped one, per block.
struct Jacobians {
  double model[kNumParameters];
  std::vector<std::vector<double>> mapped;
};

// Blocks in their own order: x = {w, eta_e}, y = {alpha, delta, mu2, mu1}.
struct PermutedBlocks {
  double x[2];
  double y[4];
  explicit PermutedBlocks(const ParameterVector& p)
      : x{p[kNaturalFrequency], p[kEtaE]}, y{p[kAlpha], p[kDelta], p[kMu2], p[kMu1]} {}
  ParameterLayout Layout() {
    FitDescription fit;
    fit.blocks = {{x, 2, "x"}, {y, 4, "y"}};
    const ParameterMap map = {{{x, 1}, {y, 3}, {y, 2}, {y, 1}, {y, 0}, {x, 0}}};
    return LayoutOf(fit, map);
  }
};

// A dwell on the up-sweep's upper branch just below its jump-down (42.2 Hz).
ceres::CostFunction* UpperBranchDwell() {
  const double omega = HzToRadPerSecond(42.2);
  const double a =
      ModelAmplitude(kFirstOrderForm, kThesisTruth, omega, 0.01, Branch::kUpper, 4.7e-3).a;
  return VerticalErrorResidual::Create(kFirstOrderForm, omega, 0.01, 1.003 * a, Branch::kUpper,
                                       ErrorMeasure::kRelative, 1.0);
}

TEST(MappedCostFunction, GathersTheParametersAndScattersTheJacobian) {
  PermutedBlocks blocks(kThesisTruth);
  const ParameterLayout layout = blocks.Layout();
  ASSERT_EQ(layout.blocks.size(), 2u);
  EXPECT_FALSE(layout.IsIdentity());
  const MappedCostFunction mapped(UpperBranchDwell(), layout);
  const std::unique_ptr<ceres::CostFunction> model(UpperBranchDwell());
  EXPECT_EQ(mapped.parameter_block_sizes(), (std::vector<int32_t>{2, 4}));

  double model_jacobian[kNumParameters];
  double* model_jacobians[] = {model_jacobian};
  const double* model_blocks[] = {kThesisTruth.data()};
  double model_residual = 0.0;
  ASSERT_TRUE(model->Evaluate(model_blocks, &model_residual, model_jacobians));
  double jx[2], jy[4];
  double* jacobians[] = {jx, jy};
  const double* parameters[] = {blocks.x, blocks.y};
  double residual = 0.0;
  ASSERT_TRUE(mapped.Evaluate(parameters, &residual, jacobians));
  EXPECT_EQ(residual, model_residual);
  EXPECT_EQ(jx[0], model_jacobian[kNaturalFrequency]);
  EXPECT_EQ(jx[1], model_jacobian[kEtaE]);
  EXPECT_EQ(jy[0], model_jacobian[kAlpha]);
  EXPECT_EQ(jy[3], model_jacobian[kMu1]);
}

// GradientChecker's finite differences agree with the scattered Jacobian, in
// relative units (each column times the entry's magnitude).
void ExpectJacobianMatchesFiniteDifferences(const ceres::CostFunction& cost,
                                            std::vector<double*> blocks) {
  ceres::NumericDiffOptions numeric;
  numeric.ridders_relative_initial_step_size = 1e-6;  // stay on the dwell's branch
  const std::vector<const ceres::Manifold*>* euclidean = nullptr;
  ceres::GradientChecker checker(&cost, euclidean, numeric);
  ceres::GradientChecker::ProbeResults results;
  checker.Probe(blocks.data(), 1e-6, &results);
  ASSERT_TRUE(results.return_value);
  double largest = 0.0;
  for (size_t b = 0; b < blocks.size(); ++b) {
    for (int j = 0; j < results.jacobians[b].cols(); ++j) {
      largest = std::max(largest, std::abs(results.jacobians[b](0, j) * blocks[b][j]));
    }
  }
  ASSERT_GT(largest, 0.0);
  for (size_t b = 0; b < blocks.size(); ++b) {
    for (int j = 0; j < results.jacobians[b].cols(); ++j) {
      EXPECT_LE(std::abs(results.jacobians[b](0, j) - results.numeric_jacobians[b](0, j)) *
                    std::abs(blocks[b][j]),
                1e-6 * largest)
          << "block " << b << " entry " << j;
    }
  }
}

TEST(MappedCostFunction, GradientCheckerPassesOnPermutedBlocks) {
  PermutedBlocks blocks(kThesisTruth);
  const MappedCostFunction mapped(UpperBranchDwell(), blocks.Layout());
  ExpectJacobianMatchesFiniteDifferences(mapped, {blocks.x, blocks.y});
}

// Two parameters in one entry: their derivatives add up (the chain rule).
TEST(MappedCostFunction, GradientCheckerPassesWhenTwoParametersShareAnEntry) {
  double shared[5] = {100.0, 7.0, 1e4, 9e8, HzToRadPerSecond(40.0)};  // entry 1 unused
  double ratio[1] = {0.2};
  FitDescription fit;
  fit.blocks = {{shared, 5, "shared"}, {ratio, 1, "ratio"}};
  // mu1 and mu2 both read ratio[0] (a made-up tie, to exercise the sum).
  const ParameterMap map = {
      {{shared, 0}, {ratio, 0}, {ratio, 0}, {shared, 2}, {shared, 3}, {shared, 4}}};
  const ParameterLayout layout = LayoutOf(fit, map);
  const MappedCostFunction mapped(
      AlgebraicResidual::Create(kFirstOrderForm, HzToRadPerSecond(41.0), 0.01, 2e-3, 1.0), layout);
  ExpectJacobianMatchesFiniteDifferences(mapped, {shared, ratio});
}

}  // namespace
}  // namespace dwellfit
