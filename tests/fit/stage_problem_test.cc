// StageProblem, the one assembly of a ceres::Problem from a description:
// bounds on the entries holding eta_e, mu1, mu2 (shared or not), fixed and
// held entries, scaling per block, the cost gradient with the caller's
// residual blocks, and one problem rating several points and solving again
// with other entries held as problems assembled for each would.
#include "dwellfit/estimator/fit/stage_problem.h"

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "ceres/normal_prior.h"
#include "ceres/sized_cost_function.h"
#include "ceres/solver.h"
#include "gtest/gtest.h"
#include "tests/fit_test_support.h"

namespace dwellfit {
namespace {

constexpr double kNoBound = -std::numeric_limits<double>::max();

StageSetup SetupFor(const FitDescription& fit, ResidualKind kind) {
  StageSetup setup;
  setup.residuals.residual = kind;
  for (double value : fit.Values()) setup.scale.push_back(std::abs(value));
  setup.bound_damping = kind == ResidualKind::kVertical;
  return setup;
}

// The dwells' residual blocks of a stage problem: each sweep's dwells in
// batches of ProblemBuilder::kDwellsPerBatch.
int Batches(const FitDescription& fit) {
  const size_t size = ProblemBuilder::kDwellsPerBatch;
  int batches = 0;
  for (const FitDataset& dataset : fit.datasets) {
    for (const Sweep* sweep : dataset.sweeps) {
      batches += static_cast<int>((sweep->points.size() + size - 1) / size);
    }
  }
  return batches;
}

TEST(StageProblem, OneBlockGetsBoundsFixedEntriesAndScaling) {
  const std::vector<Sweep> sweeps = SimulateDataset(kThesisTruth, 0.0, 0);
  ParameterVector p = kThesisTruth;
  const FitDescription fit =
      SingleBlockFit(Pointers(sweeps), {false, false, false, true, false, true}, &p);
  StageProblem vertical(fit, SetupFor(fit, ResidualKind::kVertical));
  vertical.Configure();
  ceres::Problem& problem = *vertical.problem();
  EXPECT_EQ(vertical.dwells(), fit.NumDwells());
  // The solver sees the dwells compressed: one block of 6 + 1 rows; their
  // own batches are in the dwell problem.
  EXPECT_EQ(problem.NumResidualBlocks(), 1);
  EXPECT_EQ(problem.NumResiduals(), kNumParameters + 1);
  EXPECT_EQ(vertical.dwell_problem()->NumResiduals(), fit.NumDwells());
  EXPECT_EQ(vertical.dwell_problem()->NumResidualBlocks(), Batches(fit));
  EXPECT_EQ(static_cast<int>(vertical.dwell_blocks().size()), Batches(fit));
  EXPECT_EQ(problem.ParameterBlockTangentSize(p.data()), 4);
  for (int i : {kEtaE, kMu1, kMu2}) EXPECT_EQ(problem.GetParameterLowerBound(p.data(), i), 0.0);
  EXPECT_EQ(problem.GetParameterLowerBound(p.data(), kDelta), kNoBound);
  std::vector<BoundRestWatcher::Entry> watched = vertical.WatchedBounds();
  ASSERT_EQ(watched.size(), 3u);
  EXPECT_EQ(watched[1].id, kMu1);
  EXPECT_EQ(watched[1].value, &p[kMu1]);

  // The algebraic stage leaves the damping unbounded; a held entry leaves
  // the tangent space and the watcher.
  StageProblem algebraic(fit, SetupFor(fit, ResidualKind::kAlgebraic));
  algebraic.Hold({true, false, false, false, false, false});
  algebraic.Configure();
  EXPECT_EQ(algebraic.problem()->GetParameterLowerBound(p.data(), kMu1), kNoBound);
  EXPECT_EQ(algebraic.problem()->ParameterBlockTangentSize(p.data()), 3);
  EXPECT_TRUE(algebraic.WatchedBounds().empty());

  // Every entry fixed: the block is held constant.
  ParameterVector q = kThesisTruth;
  std::array<bool, kNumParameters> all;
  all.fill(true);
  const FitDescription fixed = SingleBlockFit(Pointers(sweeps), all, &q);
  StageProblem constant(fixed, SetupFor(fixed, ResidualKind::kVertical));
  constant.Configure();
  EXPECT_TRUE(constant.problem()->IsParameterBlockConstant(q.data()));
}

TEST(StageProblem, SharedEntriesAreBoundedAndEachBlockIsScaled) {
  ParameterVector truth_b = kThesisTruth;
  truth_b[kNaturalFrequency] = HzToRadPerSecond(43.0);
  const std::vector<Sweep> a = SimulateDataset(kThesisTruth, 0.0, 0);
  const std::vector<Sweep> b = SimulateDataset(truth_b, 0.0, 0);
  SharedModel model(kThesisTruth, truth_b[kNaturalFrequency]);
  const FitDescription fit = model.Describe(Pointers(a), Pointers(b));
  StageProblem stage(fit, SetupFor(fit, ResidualKind::kVertical));
  stage.Configure();
  ceres::Problem& problem = *stage.problem();
  EXPECT_EQ(problem.NumParameterBlocks(), 3);
  // One compressed block over every described entry (3 blocks, 5 + 1 + 1).
  EXPECT_EQ(problem.NumResidualBlocks(), 1);
  EXPECT_EQ(problem.NumResiduals(), 7 + 1);
  EXPECT_EQ(stage.dwell_problem()->NumResiduals(), fit.NumDwells());
  EXPECT_EQ(stage.dwell_problem()->NumResidualBlocks(), Batches(fit));
  EXPECT_EQ(problem.ParameterBlockTangentSize(model.shared), 5);
  EXPECT_EQ(problem.ParameterBlockTangentSize(model.w_b), 1);
  for (int i : {0, 1, 2}) EXPECT_EQ(problem.GetParameterLowerBound(model.shared, i), 0.0);
  EXPECT_EQ(problem.GetParameterLowerBound(model.shared, 3), kNoBound);
  EXPECT_EQ(problem.GetParameterLowerBound(model.w_a, 0), kNoBound);
  // Noise-free data at the truth: no cost, and so no gradient.
  EXPECT_LT(stage.DataCost(), 1e-25);
}

// The release test of the active set sees the caller's residual blocks: a
// prior pulling mu1 up makes d cost / d mu1 negative by its own gradient.
TEST(StageProblem, CostGradientIncludesTheCallersResidualBlocks) {
  const std::vector<Sweep> sweeps = SimulateDataset(kThesisTruth, 0.0, 0);
  ParameterVector p = kThesisTruth;
  FitDescription fit = SingleBlockFit(Pointers(sweeps), {}, &p);
  const double sigma = 0.01;  // 1/s
  fit.add_residuals = [&](ceres::Problem* problem) {
    ceres::Matrix inverse_sigma = ceres::Matrix::Zero(1, kNumParameters);
    inverse_sigma(0, kMu1) = 1.0 / sigma;
    ceres::Vector mean(kNumParameters);
    for (int i = 0; i < kNumParameters; ++i) mean[i] = kThesisTruth[i];
    mean[kMu1] = 0.3;
    problem->AddResidualBlock(new ceres::NormalPrior(inverse_sigma, mean), nullptr, p.data());
  };
  for (bool threaded : {true, false}) {
    StageSetup setup = SetupFor(fit, ResidualKind::kVertical);
    setup.threaded_evaluation = threaded;
    StageProblem stage(fit, setup);
    stage.AddCallerResiduals();
    ASSERT_EQ(stage.caller_blocks().size(), 1u);
    std::vector<double> gradient;
    ASSERT_TRUE(stage.CostGradient(&gradient));
    ASSERT_EQ(gradient.size(), static_cast<size_t>(kNumParameters));
    // The dwells are exact at the truth; the prior's r = (0.2 - 0.3) / sigma.
    EXPECT_NEAR(gradient[kMu1], (0.2 - 0.3) / (sigma * sigma), 1e-6) << threaded;
    EXPECT_NEAR(gradient[kEtaE], 0.0, 1e-9) << threaded;
  }
}

// One problem rates several points as problems assembled for each would:
// after EvaluateAfresh the dwells' cost and the missing folds at a point are
// those of a new problem there, to the bit, whatever points the problem was
// evaluated at before (the vertical error's root solves start anew).
TEST(StageProblem, RatingAPointAfreshGivesANewProblemsValues) {
  const std::vector<Sweep> sweeps = SimulateDataset(kThesisTruth, 0.01, 7);
  ParameterVector p = ThesisStart(kThesisTruth);
  const FitDescription fit = SingleBlockFit(Pointers(sweeps), {}, &p);
  BifurcationRangeOptions range;
  range.enabled = true;
  // So damped that no fold exists, and near the truth.
  ParameterVector damped = ThesisStart(kThesisTruth);
  damped[kMu1] *= 20.0;
  ParameterVector near = kThesisTruth;
  for (int i = 0; i < kNumParameters - 1; ++i) near[i] *= 1.0 + 0.003 * (i + 1);
  std::vector<std::vector<std::string>> fresh_missing;
  for (bool threaded : {true, false}) {
    StageSetup setup = SetupFor(fit, ResidualKind::kVertical);
    setup.threaded_evaluation = threaded;
    // A new problem at each point.
    std::vector<double> fresh_cost;
    fresh_missing.clear();
    for (const ParameterVector& point : {damped, near}) {
      p = point;
      StageProblem fresh(fit, setup);
      fresh_missing.push_back(fresh.MissingFolds(range));
      fresh_cost.push_back(fresh.DataCost());
    }
    // One problem at both, and at the first again.
    StageProblem reused(fit, setup);
    const std::vector<ParameterVector> points = {damped, near, damped, near};
    for (size_t i = 0; i < points.size(); ++i) {
      p = points[i];
      reused.EvaluateAfresh();
      EXPECT_EQ(reused.MissingFolds(range), fresh_missing[i % 2]) << threaded << i;
      EXPECT_EQ(reused.DataCost(), fresh_cost[i % 2]) << threaded << i;
    }
  }
  // The damped point lacks the frequency sweep's jump-down fold, the near
  // point lacks none.
  ASSERT_EQ(fresh_missing.size(), 2u);
  EXPECT_EQ(fresh_missing[0].size(), 1u);
  EXPECT_TRUE(fresh_missing[1].empty());
}

// Solving again on one problem with other entries held (Hold, then
// EvaluateAfresh) gives the solve of a problem assembled with them held, to
// the bit; a block held constant before moves again when released.
TEST(StageProblem, SolvingAgainWithOtherHeldEntriesMatchesANewProblem) {
  const std::vector<Sweep> sweeps = SimulateDataset(kThesisTruth, 0.01, 7);
  ParameterVector p = ThesisStart(kThesisTruth);
  const FitDescription fit = SingleBlockFit(Pointers(sweeps), {}, &p);
  const StageSetup setup = SetupFor(fit, ResidualKind::kVertical);
  ceres::Solver::Options options;
  options.linear_solver_type = ceres::DENSE_QR;
  options.max_num_iterations = 8;
  options.logging_type = ceres::SILENT;
  std::vector<bool> held(kNumParameters, false);
  held[kMu2] = true;
  held[kNaturalFrequency] = true;

  StageProblem reused(fit, setup);
  reused.Configure();
  ceres::Solver::Summary first;
  ceres::Solve(options, reused.problem(), &first);
  const ParameterVector after_first = p;
  reused.Hold(held);
  reused.EvaluateAfresh();
  reused.Configure();
  EXPECT_EQ(reused.problem()->ParameterBlockTangentSize(p.data()), 4);
  ceres::Solver::Summary second;
  ceres::Solve(options, reused.problem(), &second);
  const ParameterVector reused_end = p;

  p = after_first;
  StageProblem fresh(fit, setup);
  fresh.Hold(held);
  fresh.Configure();
  ceres::Solver::Summary fresh_summary;
  ceres::Solve(options, fresh.problem(), &fresh_summary);
  EXPECT_EQ(second.iterations.size(), fresh_summary.iterations.size());
  EXPECT_EQ(second.initial_cost, fresh_summary.initial_cost);
  EXPECT_EQ(second.final_cost, fresh_summary.final_cost);
  for (int i = 0; i < kNumParameters; ++i) EXPECT_EQ(reused_end[i], p[i]) << i;
  EXPECT_EQ(p[kMu2], after_first[kMu2]);

  // Every entry held: the block is constant; released, it moves again.
  reused.Hold(std::vector<bool>(kNumParameters, true));
  reused.Configure();
  EXPECT_TRUE(reused.problem()->IsParameterBlockConstant(p.data()));
  reused.Hold({});
  reused.Configure();
  EXPECT_FALSE(reused.problem()->IsParameterBlockConstant(p.data()));
  EXPECT_EQ(reused.problem()->ParameterBlockTangentSize(p.data()), kNumParameters);
}

// The dwells compressed into one block (threaded evaluation, the default)
// and as their own blocks: the same start cost, and a vertical-error solve on the noisy
// thesis case that ends at the same estimate, cost and data cost.
TEST(StageProblem, CompressedDwellsSolveAsTheDwellsThemselves) {
  const std::vector<Sweep> sweeps = SimulateDataset(kThesisTruth, 0.01, 7);
  ParameterVector start = ThesisStart(kThesisTruth);
  ParameterVector ends[2];
  double costs[2];
  double data_costs[2];
  for (bool compress : {true, false}) {
    ParameterVector p = start;
    const FitDescription fit = SingleBlockFit(Pointers(sweeps), {}, &p);
    StageSetup setup = SetupFor(fit, ResidualKind::kVertical);
    setup.threaded_evaluation = compress;
    setup.num_threads = 2;
    StageProblem stage(fit, setup);
    stage.Configure();
    EXPECT_EQ(stage.problem()->NumResidualBlocks(),
              compress ? 1 : static_cast<int>(stage.dwell_blocks().size()));
    ceres::Solver::Options options;
    options.linear_solver_type = ceres::DENSE_QR;
    options.max_num_iterations = 100;
    options.function_tolerance = 1e-12;
    options.logging_type = ceres::SILENT;
    ceres::Solver::Summary summary;
    ceres::Solve(options, stage.problem(), &summary);
    ASSERT_EQ(summary.termination_type, ceres::CONVERGENCE) << summary.BriefReport();
    ends[compress] = p;
    costs[compress] = summary.final_cost;
    data_costs[compress] = stage.DataCost();
  }
  // The solve went from the start (eta_e 30 % off) to near the truth.
  EXPECT_NEAR(ends[1][kEtaE], kThesisTruth[kEtaE], 0.02 * kThesisTruth[kEtaE]);
  EXPECT_NEAR(costs[1], costs[0], 1e-9 * costs[0]);
  EXPECT_NEAR(data_costs[1], costs[1], 1e-12 * costs[1]);
  EXPECT_NEAR(data_costs[0], costs[0], 1e-12 * costs[0]);
  for (int i = 0; i < kNumParameters; ++i) {
    EXPECT_NEAR(ends[1][i], ends[0][i], 1e-6 * std::abs(ends[0][i])) << i;
  }
}

// Counts its destructions; r = p[mu1] - target otherwise.
class CountedPrior : public ceres::SizedCostFunction<1, kNumParameters> {
 public:
  CountedPrior(double target, int* destroyed) : target_(target), destroyed_(destroyed) {}
  ~CountedPrior() override { ++*destroyed_; }
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    residuals[0] = parameters[0][kMu1] - target_;
    if (jacobians != nullptr && jacobians[0] != nullptr) {
      for (int i = 0; i < kNumParameters; ++i) jacobians[0][i] = i == kMu1 ? 1.0 : 0.0;
    }
    return true;
  }

 private:
  const double target_;
  int* const destroyed_;
};

// The stage problem owns every cost function, the caller's included, and
// deletes each once: a cost function the caller gives two residual blocks
// too, and those the caller added before it threw.
TEST(StageProblem, OwnsEveryCostFunctionOnce) {
  const std::vector<Sweep> sweeps = SimulateDataset(kThesisTruth, 0.0, 0);
  ParameterVector p = kThesisTruth;
  FitDescription fit = SingleBlockFit(Pointers(sweeps), {}, &p);
  int destroyed = 0;
  fit.add_residuals = [&](ceres::Problem* problem) {
    auto* shared = new CountedPrior(0.3, &destroyed);
    problem->AddResidualBlock(shared, nullptr, p.data());
    problem->AddResidualBlock(shared, nullptr, p.data());
    problem->AddResidualBlock(new CountedPrior(0.1, &destroyed), nullptr, p.data());
  };
  for (bool threaded : {true, false}) {
    destroyed = 0;
    {
      StageSetup setup = SetupFor(fit, ResidualKind::kVertical);
      setup.threaded_evaluation = threaded;
      StageProblem stage(fit, setup);
      stage.AddCallerResiduals();
      ASSERT_EQ(stage.caller_blocks().size(), 3u);
      // Threaded, the dwells are compressed into one block.
      EXPECT_EQ(stage.problem()->NumResidualBlocks(), (threaded ? 1 : Batches(fit)) + 3);
      // The dwells are exact at the truth; the priors' r = -0.1, -0.1, 0.1.
      double cost = 0.0;
      ASSERT_TRUE(stage.problem()->Evaluate(ceres::Problem::EvaluateOptions(), &cost, nullptr,
                                            nullptr, nullptr));
      EXPECT_NEAR(cost, 0.5 * 3 * 0.01, 1e-12) << threaded;
      EXPECT_EQ(destroyed, 0);
    }
    EXPECT_EQ(destroyed, 2) << threaded;
  }

  destroyed = 0;
  fit.add_residuals = [&](ceres::Problem* problem) {
    problem->AddResidualBlock(new CountedPrior(0.3, &destroyed), nullptr, p.data());
    throw std::runtime_error("the caller's own failure");
  };
  {
    StageProblem stage(fit, SetupFor(fit, ResidualKind::kVertical));
    EXPECT_THROW(stage.AddCallerResiduals(), std::runtime_error);
    EXPECT_EQ(destroyed, 0);
  }
  EXPECT_EQ(destroyed, 1);
}

}  // namespace
}  // namespace dwellfit
