// End to end on the chapter's numerical case (datasets/thesis-numerical):
// the committed config and data through the same path `identify` takes.
#include <cmath>
#include <string>
#include <vector>

#include "dwellfit/config/dwell_plan_reader.h"
#include "dwellfit/config/identify_config.h"
#include "dwellfit/estimator/analysis/sweep_prediction.h"
#include "dwellfit/estimator/fit/identification.h"
#include "dwellfit/estimator/run/resolved_run.h"
#include "dwellfit/estimator/simulation/dwell_simulator.h"
#include "gtest/gtest.h"

namespace dwellfit {
namespace {

const std::string kDataset = std::string(DWELLFIT_SOURCE_DIR) + "/datasets/thesis-numerical";
const ParameterVector kTruth = {100.0, 0.2, 300.0, 1e4, 9e8, HzToRadPerSecond(40.0)};

class ThesisNumerical : public ::testing::Test {
 protected:
  void SetUp() override {
    config_ = LoadIdentifyConfig(kDataset + "/beam.yaml");
    run_ = ResolveRun(config_);
    fitted_ = run_.fitted;
    validation_ = run_.validation;
  }

  IdentificationOptions StartAt(const std::vector<double>& factors) const {
    IdentificationOptions options = config_.identification;
    for (int i = 0; i < 5; ++i) options.initial[i] = factors[i] * kTruth[i];
    return options;
  }

  IdentifyConfig config_;
  ResolvedRun run_;
  std::vector<const Sweep*> fitted_;
  std::vector<const Sweep*> validation_;
};

TEST_F(ThesisNumerical, CommittedConfigStartsAtTheFirstStartOfTheIssue) {
  const IdentificationOptions expected = StartAt({1.3, 0.7, 1.3, 0.7, 1.3});
  for (int i = 0; i < 5; ++i) {
    EXPECT_DOUBLE_EQ(config_.identification.initial[i], expected.initial[i]) << ParameterName(i);
  }
  EXPECT_TRUE(config_.identification.fixed[kNaturalFrequency]);
  EXPECT_EQ(fitted_.size(), 4u);
  EXPECT_EQ(validation_.size(), 4u);
}

// The active set's release: from eta_e at half its value the vertical error
// first pushes mu1 onto its bound 0, where the stage holds it; the reduced
// solve converges (mu2 takes all the damping), the cost gradient then points
// back into mu1 > 0, the stage releases mu1 and a third solve reaches the
// truth with nothing held.
TEST_F(ThesisNumerical, AParameterHeldOnItsBoundIsReleasedWhenTheCostPullsItBack) {
  IdentificationOptions options = StartAt({0.5, 1.0, 1.0, 1.0, 1.0});
  options.solve.stages = {ResidualKind::kVertical};
  options.solve.algebraic_start_candidate = false;  // the vertical stage from this start
  const IdentificationResult result = Identify(fitted_, options);
  ASSERT_EQ(result.stages.size(), 1u);
  const StageSummary& stage = result.stages.front();
  EXPECT_EQ(stage.solves, 3);  // held, reduced, released
  EXPECT_TRUE(stage.held_at_bound.empty());
  EXPECT_TRUE(result.converged);
  for (int i = 0; i < 5; ++i) {
    EXPECT_NEAR(result.parameters[i] / kTruth[i], 1.0, 1e-6) << ParameterName(i);
  }
}

TEST_F(ThesisNumerical, BothStartsRecoverTheTruthAndPredictTheValidationSweeps) {
  for (const std::vector<double>& factors : {std::vector<double>{1.3, 0.7, 1.3, 0.7, 1.3},
                                             std::vector<double>{0.7, 1.3, 0.7, 1.3, 0.7}}) {
    const IdentificationResult result = Identify(fitted_, StartAt(factors));
    EXPECT_TRUE(result.converged);
    for (int i = 0; i < 5; ++i) {
      EXPECT_NEAR(result.parameters[i] / kTruth[i], 1.0, 1e-6)
          << ParameterName(i) << " from start x" << factors[i];
    }
    for (const Sweep* sweep : validation_) {
      const SweepPrediction prediction =
          PredictSweep(kFirstOrderForm, result.parameters, *sweep, false);
      EXPECT_LT(prediction.relative_rms_error, 1e-6) << sweep->Name();
      EXPECT_EQ(prediction.points_off_branch, 0) << sweep->Name();
    }
  }
}

TEST_F(ThesisNumerical,
       WithPenaltiesEveryFittedJumpIsInsideItsBracketAndEstimatesWithinOnePercent) {
  for (const std::vector<double>& factors : {std::vector<double>{1.3, 0.7, 1.3, 0.7, 1.3},
                                             std::vector<double>{0.7, 1.3, 0.7, 1.3, 0.7}}) {
    IdentificationOptions options = StartAt(factors);
    options.solve.penalties.bifurcation_range.enabled = true;
    options.solve.penalties.branch_stability.enabled = true;
    const IdentificationResult result = Identify(fitted_, options);
    EXPECT_TRUE(result.converged);
    for (int i = 0; i < 5; ++i) {
      EXPECT_NEAR(result.parameters[i] / kTruth[i], 1.0, 0.01) << ParameterName(i);
    }
    int jumps = 0;
    for (const Sweep* sweep : fitted_) {
      for (const PredictedJump& jump : PredictJumps(kFirstOrderForm, result.parameters, *sweep)) {
        ASSERT_TRUE(jump.measured);
        EXPECT_TRUE(jump.inside) << sweep->Name() << " " << JumpKindName(jump.kind);
        ++jumps;
      }
    }
    EXPECT_EQ(jumps, 4);
  }
}

TEST_F(ThesisNumerical, VerticalErrorAloneFromTheFirstStartEndsAtAWrongMinimum) {
  // Why the default runs the algebraic stage first, and why a first vertical
  // stage gets the algebraic start stage: without either, the damping
  // collapses (the issue's observation, kept as a regression guard).
  IdentificationOptions options = StartAt({1.3, 0.7, 1.3, 0.7, 1.3});
  options.solve.stages = {ResidualKind::kVertical};
  options.solve.algebraic_start_candidate = false;
  options.solve.penalties = PenaltyOptions{};  // none
  const IdentificationResult result = Identify(fitted_, options);
  EXPECT_GT(std::abs(result.parameters[kMu2] / kTruth[kMu2] - 1.0), 0.1);
}

TEST_F(ThesisNumerical, OnePercentNoiseKeepsEtaAndTheEffectiveNonlinearityWithinOnePercent) {
  DwellPlan plan = ReadDwellPlan(kDataset + "/plan.yaml");
  plan.noise.relative_sigma = 0.01;
  plan.noise.seed = 20261121;
  // Labelled from the noisy data and fitted as measured sweeps are.
  const ResolvedRun noisy = ResolveRun(config_, SimulateDwells(plan));
  const IdentificationResult result = FitRun(noisy).best;
  EXPECT_TRUE(result.converged);
  EXPECT_NEAR(result.parameters[kEtaE] / kTruth[kEtaE], 1.0, 0.01);
  ASSERT_TRUE(config_.omega_ref_rad_s.has_value());
  const double omega_ref = *config_.omega_ref_rad_s;
  EXPECT_NEAR(EffectiveNonlinearity(result.parameters, omega_ref) /
                  EffectiveNonlinearity(kTruth, omega_ref),
              1.0, 0.01);
}

}  // namespace
}  // namespace dwellfit
