// The measured clamped beam (datasets/clamped-beam-27C) identified with the
// bifurcation-range penalty: the bars, the active set that holds mu2
// on its bound, and the same minimum from every way of running the stages.
#include <algorithm>
#include <cmath>
#include <iostream>
#include <string>
#include <vector>

#include "ceres/problem.h"
#include "dwellfit/config/identify_config.h"
#include "dwellfit/estimator/analysis/sweep_prediction.h"
#include "dwellfit/estimator/fit/identification.h"
#include "dwellfit/estimator/fit/problem_builder.h"
#include "dwellfit/estimator/run/resolved_run.h"
#include "gtest/gtest.h"

namespace dwellfit {
namespace {

const std::string kBeamConfig =
    std::string(DWELLFIT_SOURCE_DIR) + "/datasets/clamped-beam-27C/beam.yaml";

class ClampedBeamIdentification : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    config_ = new IdentifyConfig(LoadIdentifyConfig(kBeamConfig));
    data_ = new ResolvedRun(ResolveRun(*config_));
    committed_ = new IdentificationResult(FitRun(*data_).best);
  }
  static void TearDownTestSuite() {
    delete committed_;
    delete data_;
    delete config_;
  }

  static IdentifyConfig* config_;
  static ResolvedRun* data_;
  static IdentificationResult* committed_;  // the committed config's fit
};

IdentifyConfig* ClampedBeamIdentification::config_ = nullptr;
ResolvedRun* ClampedBeamIdentification::data_ = nullptr;
IdentificationResult* ClampedBeamIdentification::committed_ = nullptr;

// The bars with the penalty on: the damping stays physical (the
// free fit's collapse to mu1 of 6 1/s does not happen), both fitted
// jump-downs lie inside their brackets, and the held-out levels' jump-down
// frequencies are predicted with a median error of at most 3 %.
TEST_F(ClampedBeamIdentification, PenalisedFitMeetsTheJumpBars) {
  const IdentificationResult& fit = *committed_;
  ASSERT_TRUE(fit.converged);
  EXPECT_GT(fit.parameters[kMu1], 0.5);
  EXPECT_LT(fit.parameters[kMu1], 3.0);

  int fitted_jump_downs = 0;
  for (const Sweep* sweep : data_->fitted) {
    for (const PredictedJump& jump : PredictJumps(kFirstOrderForm, fit.parameters, *sweep)) {
      if (jump.kind != JumpKind::kJumpDown || !jump.measured) continue;
      ++fitted_jump_downs;
      EXPECT_TRUE(jump.inside) << sweep->Name();
    }
  }
  EXPECT_EQ(fitted_jump_downs, 2);

  std::vector<double> errors;  // percent; a missing fold counts 100 %
  for (const Sweep* sweep : data_->validation) {
    for (const PredictedJump& jump : PredictJumps(kFirstOrderForm, fit.parameters, *sweep)) {
      if (jump.kind != JumpKind::kJumpDown || !jump.measured) continue;
      const double measured = jump.bracket.centre();
      errors.push_back(jump.exists ? 100.0 * std::abs(jump.control - measured) / measured : 100.0);
    }
  }
  ASSERT_EQ(errors.size(), 10u);
  std::sort(errors.begin(), errors.end());
  const double median = 0.5 * (errors[4] + errors[5]);
  std::cout << "held-out jump-down median error " << median << " %\n";
  EXPECT_LE(median, 3.0);
}

// The penalised stages end holding mu2 on its bound 0, and there the bound is
// active: the stage's cost rises as mu2 leaves it (the KKT condition the
// stage checks before it ends).
TEST_F(ClampedBeamIdentification, Mu2IsHeldOnItsBoundWhereTheCostPushesItOutward) {
  const StageSummary* held_stage = nullptr;
  for (const StageSummary& stage : committed_->stages) {
    if (std::find(stage.held_at_bound.begin(), stage.held_at_bound.end(), kMu2) !=
        stage.held_at_bound.end()) {
      held_stage = &stage;
    }
  }
  ASSERT_NE(held_stage, nullptr) << "no stage held mu2";
  ASSERT_EQ(held_stage->values.size(), static_cast<size_t>(kNumParameters));
  EXPECT_EQ(held_stage->values[kMu2], 0.0);
  EXPECT_GE(held_stage->solves, 2);
  ASSERT_GT(held_stage->penalty_unit, 0.0);

  // The stage's cost, rebuilt: the data and the bifurcation-range penalty
  // with the stage's exponent and weight, no bounds and no manifold.
  ParameterVector p;
  std::copy(held_stage->values.begin(), held_stage->values.end(), p.begin());
  ProblemBuilderOptions options;
  options.residual_options = config_->identification.solve.residual;
  options.penalties = config_->identification.solve.penalties;
  options.penalties.bifurcation_range.exponent = held_stage->penalty_exponent;
  options.penalties.bifurcation_range.weight *= held_stage->penalty_unit;
  const ProblemBuilder builder(options);
  ceres::Problem problem;
  const ParameterLayout layout = LayoutOf(SingleBlockFit({}, {}, &p), IdentityMap(p.data()));
  for (const Sweep* sweep : data_->fitted) {
    builder.AddSweep(*sweep, layout, &problem);
    builder.AddPenalties(*sweep, layout, &problem);
  }
  double cost = 0.0;
  std::vector<double> gradient;
  ASSERT_TRUE(
      problem.Evaluate(ceres::Problem::EvaluateOptions(), &cost, nullptr, &gradient, nullptr));
  std::cout << "stage cost " << cost << ", d cost / d mu2 " << gradient[kMu2] << "\n";
  EXPECT_NEAR(cost, held_stage->final_cost, 1e-6 * cost);
  EXPECT_GT(gradient[kMu2], 0.0);
}

// The same minimum however the stages run (cost at most 0.01 % above the
// committed fit's, w within 0.02 %): before the active set and without
// Ceres' projected line search, turning non-monotonic steps off or skipping
// the algebraic stage ended in a basin of ten to seventeen times the cost.
// The valley's floor is uneven at the 1e-4 level: without non-monotonic
// steps the fit now ends 0.013 % below the committed cost, 0.02 Hz away in w.
TEST_F(ClampedBeamIdentification, SameMinimumWithoutNonmonotonicStepsOrTheAlgebraicStage) {
  IdentificationOptions monotonic = config_->identification;
  monotonic.solve.solver.nonmonotonic_steps = false;
  IdentificationOptions vertical_only = config_->identification;
  vertical_only.solve.stages = {ResidualKind::kVertical};
  vertical_only.solve.algebraic_start_candidate = false;  // no algebraic stage at all
  for (const IdentificationOptions& options : {monotonic, vertical_only}) {
    const IdentificationResult fit = Identify(data_->fitted, options);
    std::cout << "final cost " << fit.final_cost << " against " << committed_->final_cost << "\n";
    EXPECT_TRUE(fit.converged);
    EXPECT_LT(fit.final_cost, (1.0 + 1e-4) * committed_->final_cost);
    EXPECT_GT(fit.final_cost, (1.0 - 1e-3) * committed_->final_cost);
    EXPECT_NEAR(fit.parameters[kNaturalFrequency], committed_->parameters[kNaturalFrequency],
                2e-4 * committed_->parameters[kNaturalFrequency]);
  }
}

// The start stage can lose: a vertical stage run alone from the committed
// fit's minimum keeps that start (the algebraic residual's minimum lies
// elsewhere, at a higher vertical cost), says so in its note, and ends no
// higher (its penalty is weighed anew where it starts, so the cost is not
// quite the same function; the valley's floor is uneven at the 1e-4 level).
TEST_F(ClampedBeamIdentification, AVerticalStageAloneKeepsAGivenStartBetterThanTheStartStages) {
  IdentificationOptions options = config_->identification;
  options.initial = committed_->parameters;
  options.solve.stages = {ResidualKind::kVertical};
  const IdentificationResult fit = Identify(data_->fitted, options);
  ASSERT_GE(fit.stages.size(), 2u);
  EXPECT_TRUE(fit.stages[0].start_stage);
  EXPECT_FALSE(fit.stages[1].fold_stage);
  EXPECT_EQ(fit.stages[1].note.rfind("started at the given start, not where the start stage "
                                     "ended, since where it ended ",
                                     0),
            0u)
      << fit.stages[1].note;
  EXPECT_TRUE(fit.converged) << fit.message;
  EXPECT_LT(fit.final_cost, (1.0 + 1e-4) * committed_->final_cost);
  EXPECT_GT(fit.final_cost, (1.0 - 1e-3) * committed_->final_cost);
}

// The residual blocks are evaluated on threads in fixed chunks and summed by
// Ceres in block order: the fit is bitwise the same on 1 and on 3 threads.
TEST_F(ClampedBeamIdentification, ResultDoesNotDependOnTheThreadCount) {
  IdentificationOptions one = config_->identification;
  one.solve.solver.num_threads = 1;
  IdentificationOptions three = config_->identification;
  three.solve.solver.num_threads = 3;
  const IdentificationResult a = Identify(data_->fitted, one);
  const IdentificationResult b = Identify(data_->fitted, three);
  EXPECT_EQ(a.parameters, b.parameters);
  EXPECT_EQ(a.final_cost, b.final_cost);
  EXPECT_EQ(a.iterations, b.iterations);
}

}  // namespace
}  // namespace dwellfit
