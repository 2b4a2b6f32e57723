#include "dwellfit/estimator/fit/problem_builder.h"

#include <cmath>
#include <limits>
#include <memory>
#include <vector>

#include "ceres/manifold_test_utils.h"
#include "ceres/solver.h"
#include "dwellfit/estimator/fit/mapped_cost_function.h"
#include "dwellfit/estimator/fit/scaled_subset_manifold.h"
#include "dwellfit/estimator/fit/staged_solve.h"
#include "gtest/gtest.h"

namespace dwellfit {
namespace {

const ParameterVector kTruth = {100.0, 0.2, 300.0, 1e4, 9e8, HzToRadPerSecond(40.0)};

// A noise-free amplitude sweep at 41.5 Hz on its lower branch (below the
// jump-up level) and a frequency sweep far below resonance.
std::vector<Sweep> TwoSweeps() {
  Sweep amplitude;
  amplitude.id = "A";
  amplitude.kind = SweepKind::kAmplitude;
  for (double a_base = 0.002; a_base < 0.03; a_base += 0.002) {
    DwellPoint point;
    point.drive_frequency_rad_s = HzToRadPerSecond(41.5);
    point.a_base = a_base;
    point.branch = Branch::kLower;
    point.amplitude = ModelAmplitude(kFirstOrderForm, kTruth, point.drive_frequency_rad_s, a_base,
                                     Branch::kLower, 1e-4)
                          .a;
    amplitude.points.push_back(point);
  }
  Sweep frequency;
  frequency.id = "F";
  for (double hz = 36.0; hz < 40.5; hz += 0.5) {
    DwellPoint point;
    point.drive_frequency_rad_s = HzToRadPerSecond(hz);
    point.a_base = 0.01;
    point.amplitude = ModelAmplitude(kFirstOrderForm, kTruth, point.drive_frequency_rad_s, 0.01,
                                     Branch::kOnly, 1e-3)
                          .a;
    frequency.points.push_back(point);
  }
  return {amplitude, frequency};
}

const std::vector<double> kTruthScale(kTruth.begin(), kTruth.end());

TEST(ScaledSubsetManifold, SatisfiesCeresManifoldInvariants) {
  const ScaledSubsetManifold manifold(kTruthScale, {false, false, false, true, false, true});
  EXPECT_EQ(manifold.TangentSize(), 4);
  const Eigen::VectorXd x = Eigen::Map<const Eigen::VectorXd>(kTruth.data(), kNumParameters);
  Eigen::VectorXd y = x;
  y[kEtaE] *= 1.1;
  y[kAlpha] *= 0.9;
  using namespace ceres;  // NOLINT: the macro names ceres' matchers unqualified
  EXPECT_THAT_MANIFOLD_INVARIANTS_HOLD(manifold, x, Eigen::Vector4d(0.1, -0.2, 0.05, 0.3), y,
                                       1e-10);
}

// Any block size: a shared block of one entry, and a block of four with one
// fixed.
TEST(ScaledSubsetManifold, SatisfiesCeresManifoldInvariantsOnABlockOfOne) {
  using namespace ceres;  // NOLINT: the macro names ceres' matchers unqualified
  const ScaledSubsetManifold one({100.0}, {false});
  EXPECT_EQ(one.AmbientSize(), 1);
  EXPECT_EQ(one.TangentSize(), 1);
  const Eigen::VectorXd x = Eigen::VectorXd::Constant(1, 90.0);
  const Eigen::VectorXd delta = Eigen::VectorXd::Constant(1, 0.2);
  const Eigen::VectorXd y = Eigen::VectorXd::Constant(1, 120.0);
  EXPECT_THAT_MANIFOLD_INVARIANTS_HOLD(one, x, delta, y, 1e-10);
}

TEST(ScaledSubsetManifold, SatisfiesCeresManifoldInvariantsOnABlockOfFour) {
  using namespace ceres;  // NOLINT: the macro names ceres' matchers unqualified
  const ScaledSubsetManifold four({0.2, 300.0, 1e4, 9e8}, {false, false, true, false});
  EXPECT_EQ(four.AmbientSize(), 4);
  EXPECT_EQ(four.TangentSize(), 3);
  const Eigen::Vector4d x(0.2, 300.0, 1e4, 9e8);
  const Eigen::Vector4d y(0.25, 280.0, 1e4, 8e8);
  EXPECT_THAT_MANIFOLD_INVARIANTS_HOLD(four, x, Eigen::Vector3d(0.1, -0.2, 0.05), y, 1e-10);
  const double delta[] = {0.5, 0.0, -0.1};
  double moved[4];
  ASSERT_TRUE(four.Plus(x.data(), delta, moved));
  EXPECT_DOUBLE_EQ(moved[0], 0.3);
  EXPECT_EQ(moved[2], 1e4);  // fixed
  EXPECT_DOUBLE_EQ(moved[3], 0.9 * 9e8);
}

TEST(ScaledSubsetManifold, StepsAreRelativeAndFixedEntriesNeverMove) {
  const ScaledSubsetManifold manifold(kTruthScale, {false, false, false, true, false, true});
  const double delta[] = {0.01, 0.0, 0.0, 0.0};  // +1 % of eta_e
  ParameterVector moved;
  ASSERT_TRUE(manifold.Plus(kTruth.data(), delta, moved.data()));
  EXPECT_DOUBLE_EQ(moved[kEtaE], 101.0);
  EXPECT_EQ(moved[kDelta], kTruth[kDelta]);
  EXPECT_EQ(moved[kNaturalFrequency], kTruth[kNaturalFrequency]);
}

// The dwells go onto a problem the caller owns, beside blocks of its own, and
// read the caller's block directly (no adapter for the one-block layout).
TEST(ProblemBuilder, AddsTheDwellsInBatchesOnACallerOwnedProblem) {
  const std::vector<Sweep> sweeps = TwoSweeps();
  const ProblemBuilder builder(ProblemBuilderOptions{});
  ceres::Problem problem;  // the caller's, which may hold other blocks too
  double other_block[1] = {3.0};
  problem.AddParameterBlock(other_block, 1);
  ParameterVector p = kTruth;
  const ParameterLayout layout = LayoutOf(SingleBlockFit({}, {}, &p), IdentityMap(p.data()));
  int dwells = 0;
  int blocks = 0;
  for (const Sweep& sweep : sweeps) {
    dwells += builder.AddSweep(sweep, layout, &problem);
    blocks += builder.ResidualBlocks(sweep);
  }
  EXPECT_EQ(dwells, static_cast<int>(sweeps[0].points.size() + sweeps[1].points.size()));
  EXPECT_EQ(problem.NumResidualBlocks(), blocks);
  EXPECT_EQ(problem.NumResiduals(), dwells);
  EXPECT_EQ(problem.NumParameterBlocks(), 2);
  std::vector<ceres::ResidualBlockId> ids;
  problem.GetResidualBlocks(&ids);
  const ceres::CostFunction* cost = problem.GetCostFunctionForResidualBlock(ids.front());
  EXPECT_EQ(dynamic_cast<const MappedCostFunction*>(cost), nullptr);
  double cost_at_truth = 1.0;
  ASSERT_TRUE(problem.Evaluate(ceres::Problem::EvaluateOptions(), &cost_at_truth, nullptr, nullptr,
                               nullptr));
  EXPECT_LT(cost_at_truth, 1e-25);
}

TEST(ProblemBuilder, PointSigmaWeightsTheVerticalResidual) {
  Sweep sweep = TwoSweeps()[1];
  sweep.points.resize(1);
  sweep.points[0].amplitude *= 1.02;
  sweep.points[0].sigma = 1e-5;
  const ProblemBuilder builder(ProblemBuilderOptions{});
  std::unique_ptr<ceres::CostFunction> weighted(builder.MakeResidual(sweep.points[0]));
  sweep.points[0].sigma.reset();
  std::unique_ptr<ceres::CostFunction> plain(builder.MakeResidual(sweep.points[0]));
  const double* blocks[] = {kTruth.data()};
  double r_weighted, r_plain;
  ASSERT_TRUE(weighted->Evaluate(blocks, &r_weighted, nullptr));
  ASSERT_TRUE(plain->Evaluate(blocks, &r_plain, nullptr));
  EXPECT_NEAR(r_weighted, r_plain / 1e-5, 1e-9 * std::abs(r_weighted));
}

TEST(ReflectDampingIntoPhysicalRange, MapsTheAlgebraicTwinToThePhysicalOne) {
  const auto reflect = [](ParameterVector* p) {
    return ReflectDampingIntoPhysicalRange({&(*p)[kEtaE]}, {&(*p)[kMu1], &(*p)[kMu2]});
  };
  ParameterVector twin = kTruth;
  twin[kEtaE] = -100.0;
  twin[kMu1] = -0.2;
  twin[kMu2] = -300.0;
  EXPECT_TRUE(reflect(&twin));
  EXPECT_EQ(twin, kTruth);
  ParameterVector physical = kTruth;
  EXPECT_FALSE(reflect(&physical));
  ParameterVector mixed = kTruth;
  mixed[kMu2] = -5.0;
  EXPECT_TRUE(reflect(&mixed));
  EXPECT_EQ(mixed[kMu1], 0.2);
  EXPECT_EQ(mixed[kMu2], 0.0);
}

}  // namespace
}  // namespace dwellfit
