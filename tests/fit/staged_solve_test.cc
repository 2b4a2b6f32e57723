// The public staged solve: bad input gives a failed status naming the field
// (never an abort), an embedder's prior joins every stage, blocks mapped as
// the identity give the one block's answer, and two datasets sharing eta_e
// are fitted jointly.
#include "dwellfit/estimator/fit/staged_solve.h"

#include <array>
#include <cmath>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "ceres/normal_prior.h"
#include "dwellfit/estimator/fit/identification.h"
#include "dwellfit/estimator/fit/multi_start.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "tests/fit_test_support.h"

namespace dwellfit {
namespace {

using ::testing::HasSubstr;

// The chapter's default options with the relative error (the thesis config).
StagedSolveOptions ThesisOptions() {
  StagedSolveOptions options;
  options.residual.error = ErrorMeasure::kRelative;
  return options;
}

class StagedSolve : public ::testing::Test {
 protected:
  void SetUp() override { sweeps_ = SimulateDataset(kThesisTruth, 0.0, 0); }
  std::vector<Sweep> sweeps_;
};

// One invalid field per options struct: the solve reports it and leaves the
// blocks as they were.
TEST_F(StagedSolve, InvalidOptionsGiveAFailedStatusNamingTheField) {
  const std::vector<std::pair<std::function<void(StagedSolveOptions*)>, std::string>> cases = {
      {[](StagedSolveOptions* o) { o->solver.max_iterations = 0; }, "solver.max_iterations"},
      {[](StagedSolveOptions* o) { o->solver.function_tolerance = -1.0; },
       "solver.function_tolerance must be a non-negative number (>= 0), got -1"},
      {[](StagedSolveOptions* o) { o->solver.start_function_tolerance = NAN; },
       "solver.start_function_tolerance must be a non-negative number (>= 0), got nan"},
      {[](StagedSolveOptions* o) { o->solver.num_threads = -2; }, "solver.num_threads"},
      {[](StagedSolveOptions* o) { o->residual.amplitude_floor = -1e-3; },
       "residual.amplitude_floor must be a non-negative number (>= 0)"},
      {[](StagedSolveOptions* o) { o->penalties.bifurcation_range.exponent = 3; },
       "penalties.bifurcation_range.exponent must be an even integer >= 2"},
      {[](StagedSolveOptions* o) { o->penalties.branch_stability.lambda = 0.0; },
       "penalties.branch_stability.lambda must be a positive number"},
      {[](StagedSolveOptions* o) { o->stages.clear(); }, "stages must list at least one"},
  };
  for (const auto& [spoil, field] : cases) {
    StagedSolveOptions options = ThesisOptions();
    spoil(&options);
    ParameterVector p = ThesisStart(kThesisTruth);
    const ParameterVector start = p;
    const FitSummary summary = SolveStaged(SingleBlockFit(Pointers(sweeps_), {}, &p), options);
    EXPECT_EQ(summary.status, FitStatus::kInvalidInput) << field;
    EXPECT_FALSE(summary.IsSolutionUsable());
    EXPECT_THAT(summary.message, HasSubstr(field));
    EXPECT_TRUE(summary.stages.empty());
    EXPECT_EQ(p, start);
  }
}

TEST_F(StagedSolve, InvalidIdentificationAndMultiStartOptionsNameTheField) {
  IdentificationOptions options;
  options.initial = ThesisStart(kThesisTruth);
  options.initial[kEtaE] = -5.0;
  IdentificationResult result = Identify(Pointers(sweeps_), options);
  EXPECT_EQ(result.status, FitStatus::kInvalidInput);
  EXPECT_THAT(result.message, HasSubstr("initial.eta_e must be positive (> 0), got -5"));
  EXPECT_EQ(result.parameters, options.initial);

  options.initial = ThesisStart(kThesisTruth);
  options.initial[kMu2] = std::nan("");
  result = Identify(Pointers(sweeps_), options);
  EXPECT_THAT(result.message, HasSubstr("initial.mu2 must be a finite number"));

  options.initial = ThesisStart(kThesisTruth);
  options.solve.solver.parameter_tolerance = -1.0;
  EXPECT_THAT(Identify(Pointers(sweeps_), options).message,
              HasSubstr("solver.parameter_tolerance"));

  options.solve.solver = SolverSettings{};
  MultiStartOptions multi_start;
  multi_start.spread = 1.0;
  const MultiStartResult multi = IdentifyMultiStart(Pointers(sweeps_), options, {}, multi_start);
  EXPECT_EQ(multi.best.status, FitStatus::kInvalidInput);
  EXPECT_THAT(multi.best.message, HasSubstr("multi_start.spread must be a factor greater than 1"));
}

// An algebraic stage whose end only starts the vertical stage ends on the
// looser start tolerance, in fewer iterations, and the vertical stage reaches
// the same minimum; an algebraic stage that is the last keeps the fit's own
// tolerance, whatever the start tolerance.
TEST_F(StagedSolve, AStartOnlyAlgebraicStageEndsOnTheStartTolerance) {
  const std::vector<Sweep> noisy = SimulateDataset(kThesisTruth, 0.01, 3);
  const auto solve = [&](std::vector<ResidualKind> stages, double start_tolerance,
                         ParameterVector* p) {
    StagedSolveOptions options = ThesisOptions();
    options.stages = std::move(stages);
    options.solver.start_function_tolerance = start_tolerance;
    *p = ThesisStart(kThesisTruth);
    std::array<bool, kNumParameters> fixed{};
    fixed[kNaturalFrequency] = true;
    return SolveStaged(SingleBlockFit(Pointers(noisy), fixed, p), options);
  };
  const std::vector<ResidualKind> two = {ResidualKind::kAlgebraic, ResidualKind::kVertical};
  ParameterVector tight_p, loose_p;
  const FitSummary tight = solve(two, 1e-8, &tight_p);
  const FitSummary loose = solve(two, 1e-2, &loose_p);
  ASSERT_EQ(tight.status, FitStatus::kConverged) << tight.message;
  ASSERT_EQ(loose.status, FitStatus::kConverged) << loose.message;
  ASSERT_EQ(tight.stages.front().residual, ResidualKind::kAlgebraic);
  EXPECT_LT(loose.stages.front().iterations, tight.stages.front().iterations);
  EXPECT_GT(loose.stages.front().final_cost, tight.stages.front().final_cost);
  EXPECT_NEAR(loose.final_cost, tight.final_cost, 1e-6 * tight.final_cost);
  for (int i = 0; i < kNumParameters; ++i) {
    EXPECT_NEAR(loose_p[i], tight_p[i], 1e-3 * std::abs(tight_p[i]) + 1e-12) << i;
  }

  ParameterVector alone_tight_p, alone_loose_p;
  const FitSummary alone_tight = solve({ResidualKind::kAlgebraic}, 1e-8, &alone_tight_p);
  const FitSummary alone_loose = solve({ResidualKind::kAlgebraic}, 1e-2, &alone_loose_p);
  EXPECT_EQ(alone_loose.iterations, alone_tight.iterations);
  EXPECT_EQ(alone_loose_p, alone_tight_p);
  EXPECT_EQ(alone_tight.stages.front().iterations, tight.stages.front().iterations);
}

// Each broken description names its dataset, block or entry.
TEST_F(StagedSolve, InvalidDescriptionsNameTheDatasetBlockOrEntry) {
  double other[6] = {1, 1, 1, 1, 1, 1};
  const std::vector<std::pair<std::function<void(FitDescription*, ThreeBlocks*)>, std::string>>
      cases = {
          {[&](FitDescription* f, ThreeBlocks*) { f->datasets[0].parameters[kMu2].block = other; },
           "dataset 'thesis': mu2 is mapped to a block that is not in FitDescription::blocks"},
          {[](FitDescription* f, ThreeBlocks*) { f->datasets[0].parameters[kAlpha].index = 3; },
           "alpha is mapped to entry 3 of block 'rest', which has entries 0 to 2"},
          {[](FitDescription* f, ThreeBlocks*) {
             f->blocks[1].scale = {1.0, -2.0};
           },
           "block 'damping': scale of mu2 must be positive and finite (> 0), got -2"},
          {[](FitDescription* f, ThreeBlocks*) { f->blocks[2].fixed = {true}; },
           "block 'rest': fixed has 1 entries, the block 3"},
          {[](FitDescription* f, ThreeBlocks* b) { f->blocks[1].values = b->eta_e; },
           "blocks 'eta_e' and 'damping' overlap in memory"},
          {[](FitDescription*, ThreeBlocks* b) { b->eta_e[0] = 0.0; },
           "dataset 'thesis': eta_e (eta_e) must be positive (> 0), got 0"},
          {[](FitDescription*, ThreeBlocks* b) { b->damping[0] = -0.1; },
           "mu1 (mu1) must be non-negative"},
          {[](FitDescription*, ThreeBlocks* b) { b->rest[1] = INFINITY; },
           "block 'rest': alpha is inf; every value must be a finite number"},
          {[](FitDescription* f, ThreeBlocks*) { f->datasets[0].sweeps.clear(); },
           "dataset 'thesis': no dwell points to fit"},
          {[](FitDescription* f, ThreeBlocks*) { f->datasets.clear(); },
           "FitDescription::datasets is empty"},
      };
  for (const auto& [spoil, expected] : cases) {
    ThreeBlocks blocks(ThesisStart(kThesisTruth));
    FitDescription fit = blocks.Describe(Pointers(sweeps_), true);
    spoil(&fit, &blocks);
    const FitSummary summary = SolveStaged(fit, ThesisOptions());
    EXPECT_EQ(summary.status, FitStatus::kInvalidInput) << expected;
    EXPECT_THAT(summary.message, HasSubstr(expected));
  }
}

// The same fit through three blocks mapped as the identity (the adapter)
// and through the one block read directly: the same estimate and cost.
TEST_F(StagedSolve, MappedBlocksGiveTheSingleBlocksAnswerWhenTheMappingIsTheIdentity) {
  IdentificationOptions options;
  options.initial = ThesisStart(kThesisTruth);
  options.fixed[kNaturalFrequency] = true;
  options.solve.residual.error = ErrorMeasure::kRelative;
  const IdentificationResult single = Identify(Pointers(sweeps_), options);
  ASSERT_EQ(single.status, FitStatus::kConverged) << single.message;

  ThreeBlocks blocks(options.initial);
  const FitSummary mapped = SolveStaged(blocks.Describe(Pointers(sweeps_), true), options.solve);
  ASSERT_EQ(mapped.status, FitStatus::kConverged) << mapped.message;
  const ParameterVector estimate = blocks.Values();
  for (int i = 0; i < kNumParameters; ++i) {
    EXPECT_NEAR(estimate[i], single.parameters[i], 1e-9 * std::abs(single.parameters[i]))
        << ParameterName(i);
    EXPECT_NEAR(estimate[i] / kThesisTruth[i], 1.0, 1e-8) << ParameterName(i);
  }
  EXPECT_NEAR(mapped.final_cost, single.final_cost, 1e-12);
  ASSERT_EQ(mapped.stages.size(), single.stages.size());
  for (size_t s = 0; s < single.stages.size(); ++s) {
    EXPECT_EQ(mapped.stages[s].solves, single.stages[s].solves);
    EXPECT_EQ(mapped.stages[s].residual_blocks, single.stages[s].residual_blocks);
  }
}

// A Gaussian prior on mu1, added by the caller: it joins every problem the
// stages assemble (each solve's, and the minimum check's at the end), and a
// strong one at a wrong value moves mu1 there while the data keep the rest
// near the truth.
TEST_F(StagedSolve, AnEmbeddersPriorJoinsEveryProblemTheStagesAssemble) {
  ThreeBlocks blocks(ThesisStart(kThesisTruth));
  FitDescription fit = blocks.Describe(Pointers(sweeps_), true);
  int calls = 0;
  const double prior_mean = 0.25;  // 1/s; the truth is 0.2
  fit.add_residuals = [&](ceres::Problem* problem) {
    ++calls;
    ceres::Matrix inverse_sigma(1, 2);
    inverse_sigma << 1.0 / 1e-5, 0.0;  // mu1 within 1e-5 1/s, mu2 free
    ceres::Vector mean(2);
    mean << prior_mean, 0.0;
    problem->AddResidualBlock(new ceres::NormalPrior(inverse_sigma, mean), nullptr, blocks.damping);
  };
  const FitSummary summary = SolveStaged(fit, ThesisOptions());
  ASSERT_TRUE(summary.IsSolutionUsable()) << summary.message;
  int solves = 0, checks = 1;
  for (const StageSummary& stage : summary.stages) {
    solves += stage.solves;
    checks += stage.note.find("the minimum check") != std::string::npos;
  }
  EXPECT_EQ(calls, solves + checks);
  EXPECT_NEAR(blocks.damping[0], prior_mean, 1e-4);
  EXPECT_NEAR(blocks.eta_e[0] / kThesisTruth[kEtaE], 1.0, 0.1);
  // The data alone put mu1 at the truth: the prior moved it.
  ThreeBlocks free_blocks(ThesisStart(kThesisTruth));
  ASSERT_TRUE(SolveStaged(free_blocks.Describe(Pointers(sweeps_), true), ThesisOptions())
                  .IsSolutionUsable());
  EXPECT_NEAR(free_blocks.damping[0], kThesisTruth[kMu1], 1e-8);
  // Its final cost includes the prior's.
  EXPECT_GT(summary.final_cost, summary.stages.back().final_data_cost);
}

class TwoDatasets : public ::testing::Test {
 protected:
  void SetUp() override {
    truth_b_ = kThesisTruth;
    truth_b_[kNaturalFrequency] = HzToRadPerSecond(43.0);
    a_ = SimulateDataset(kThesisTruth, 0.0, 0);
    b_ = SimulateDataset(truth_b_, 0.0, 0);
  }
  // Shared parameters from the thesis start, each w 0.5 % off.
  SharedModel Start() const {
    return SharedModel(
        [&] {
          ParameterVector p = ThesisStart(kThesisTruth);
          p[kNaturalFrequency] *= 1.005;
          return p;
        }(),
        truth_b_[kNaturalFrequency] * 0.995);
  }
  ParameterVector truth_b_;
  std::vector<Sweep> a_, b_;
};

// Both datasets' dwells on one shared eta_e, mu1, mu2, delta, alpha and a w
// each: the joint fit recovers every parameter.
TEST_F(TwoDatasets, SharedEtaEAndOneWPerDatasetRecoverTheTruth) {
  SharedModel model = Start();
  const FitSummary summary =
      SolveStaged(model.Describe(Pointers(a_), Pointers(b_)), ThesisOptions());
  ASSERT_EQ(summary.status, FitStatus::kConverged) << summary.message;
  EXPECT_EQ(summary.residual_blocks,
            static_cast<int>(2 * (a_[0].points.size() + a_[1].points.size() + a_[2].points.size() +
                                  a_[3].points.size())));
  for (int i = 0; i < 5; ++i) {
    EXPECT_NEAR(model.shared[i] / kThesisTruth[i], 1.0, 1e-6) << ParameterName(i);
  }
  EXPECT_NEAR(model.w_a[0] / kThesisTruth[kNaturalFrequency], 1.0, 1e-9);
  EXPECT_NEAR(model.w_b[0] / truth_b_[kNaturalFrequency], 1.0, 1e-9);
}

// The mapped blocks are evaluated on threads like the one block: bitwise the
// same fit on 1 and on 3 threads.
TEST_F(TwoDatasets, ResultDoesNotDependOnTheThreadCount) {
  std::vector<double> values[2];
  FitSummary summaries[2];
  for (int t = 0; t < 2; ++t) {
    SharedModel model = Start();
    StagedSolveOptions options = ThesisOptions();
    options.solver.num_threads = t == 0 ? 1 : 3;
    const FitDescription fit = model.Describe(Pointers(a_), Pointers(b_));
    summaries[t] = SolveStaged(fit, options);
    values[t] = fit.Values();
  }
  EXPECT_EQ(values[0], values[1]);
  EXPECT_EQ(summaries[0].final_cost, summaries[1].final_cost);
  EXPECT_EQ(summaries[0].iterations, summaries[1].iterations);
}

}  // namespace
}  // namespace dwellfit
