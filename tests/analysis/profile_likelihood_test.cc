// Profile-likelihood intervals (profile_likelihood.h, EstimateUncertaintyAtMinimum):
// on a nearly linear problem they are the Gauss-Newton intervals; each end
// is where an independent constrained fit (the staged solve with the
// parameter fixed there) rises by Delta; bounds are kept; and on every
// bundled dataset no profile finds a cost below the reported minimum.
#include "dwellfit/estimator/analysis/profile_likelihood.h"

#include <cmath>
#include <cstdint>
#include <sstream>
#include <string>
#include <vector>

#include "dwellfit/config/dwell_plan_reader.h"
#include "dwellfit/config/identify_config.h"
#include "dwellfit/estimator/analysis/parameter_uncertainty.h"
#include "dwellfit/estimator/fit/identification.h"
#include "dwellfit/estimator/fit/parallel_residual_evaluator.h"
#include "dwellfit/estimator/run/identify_run.h"
#include "dwellfit/estimator/run/resolved_run.h"
#include "dwellfit/estimator/simulation/dwell_simulator.h"
#include "gtest/gtest.h"

namespace dwellfit {
namespace {

const std::string kDatasets = std::string(DWELLFIT_SOURCE_DIR) + "/datasets/";

// The thesis case with 1 % multiplicative noise, resolved as measured sweeps are.
ResolvedRun NoisyThesis(const IdentifyConfig& config, std::uint64_t seed) {
  DwellPlan plan = ReadDwellPlan(kDatasets + "thesis-numerical/plan.yaml");
  plan.noise.relative_sigma = 0.01;
  plan.noise.seed = seed;
  return ResolveRun(config, SimulateDwells(plan));
}

// The cost of the staged solve with parameter `j` fixed at `value`, from
// the estimate: a constrained minimum found by another path than the
// profile's own.
double FixedFitCost(const ResolvedRun& run, const ParameterVector& estimate, int j, double value) {
  IdentificationOptions options = run.options;
  options.initial = estimate;
  options.initial[j] = value;
  options.fixed[j] = true;
  const IdentificationResult result = Identify(run.fitted, options);
  EXPECT_TRUE(result.IsSolutionUsable()) << result.message;
  return result.final_cost;
}

TEST(ProfileLikelihood, NearlyLinearFitGivesTheGaussNewtonIntervalsAndEndsOneThresholdUp) {
  const IdentifyConfig config = LoadIdentifyConfig(kDatasets + "thesis-numerical/beam.yaml");
  const ResolvedRun run = NoisyThesis(config, 11);
  IdentificationResult result = Identify(run.fitted, run.options);
  ASSERT_TRUE(result.converged) << result.message;
  const double omega_ref = *config.omega_ref_rad_s;
  const ParameterUncertainty u =
      EstimateUncertaintyAtMinimum(run.fitted, run.options, omega_ref, &result, 2);
  ASSERT_TRUE(u.available) << u.message;
  ASSERT_EQ(u.interval_kind, "profile_likelihood") << u.message;
  // Delta = q^2 s^2 / 2.
  EXPECT_NEAR(u.profile.threshold, 0.5 * std::pow(u.interval_quantile * u.noise_sigma, 2),
              1e-12 * u.profile.threshold);
  // eta_e and alpha_e are well determined and nearly linear here: their
  // profile intervals are the Gauss-Newton ones. delta and alpha, 0.999
  // correlated along a curved valley, are narrower in the profile.
  const ProfileInterval& alpha_e = u.profile.effective_nonlinearity;
  ASSERT_TRUE(alpha_e.computed);
  EXPECT_NEAR((alpha_e.high - alpha_e.low) / (u.effective_nonlinearity_linearised_ci95_high -
                                              u.effective_nonlinearity_linearised_ci95_low),
              1.0, 0.15);
  for (int j : {kEtaE, kDelta, kAlpha}) {
    SCOPED_TRACE(ParameterName(j));
    const ProfileInterval& interval = u.profile.parameters[j];
    ASSERT_TRUE(interval.computed);
    EXPECT_EQ(interval.low_end, ProfileEnd::kCrossed);
    EXPECT_EQ(interval.high_end, ProfileEnd::kCrossed);
    const double linear = u.linearised_ci95_high[j] - u.linearised_ci95_low[j];
    EXPECT_NEAR((interval.high - interval.low) / linear, 1.0, j == kEtaE ? 0.15 : 0.3);
    EXPECT_EQ(u.ci95_low[j], interval.low);
    EXPECT_EQ(u.ci95_high[j], interval.high);
    // At each end an independent constrained fit sits one threshold up
    // (the search stops within 10 % of Delta, the end interpolated).
    for (double end : {interval.low, interval.high}) {
      const double rise = FixedFitCost(run, result.parameters, j, end) - result.final_cost;
      EXPECT_NEAR(rise / u.profile.threshold, 1.0, 0.15) << "end " << end;
    }
  }
}

TEST(ProfileLikelihood, IntervalsStayWithinTheBoundsAndSayHowEachEndWasFound) {
  // mu1 of the thesis case is 0.2 +/- 0.2 at 1 % noise: some replicas put
  // it on its bound, where the profile interval must stop at 0.
  const IdentifyConfig config = LoadIdentifyConfig(kDatasets + "thesis-numerical/beam.yaml");
  int at_bound = 0;
  for (std::uint64_t seed = 1; seed <= 12 && at_bound == 0; ++seed) {
    const ResolvedRun run = NoisyThesis(config, seed);
    IdentificationResult result = Identify(run.fitted, run.options);
    const ParameterUncertainty u =
        EstimateUncertaintyAtMinimum(run.fitted, run.options, *config.omega_ref_rad_s, &result, 2);
    ASSERT_EQ(u.interval_kind, "profile_likelihood") << u.message;
    for (int j : {kEtaE, kMu1, kMu2}) {
      EXPECT_GE(u.ci95_low[j], 0.0) << ParameterName(j) << " seed " << seed;
      // The linearised interval ignores the bound, the profile does not.
      if (u.profile.parameters[j].low_end == ProfileEnd::kBound) {
        EXPECT_EQ(u.ci95_low[j], 0.0);
        ++at_bound;
      }
    }
    EXPECT_LE(u.ci95_low[kMu1], result.parameters[kMu1]);
    EXPECT_GE(u.ci95_high[kMu1], result.parameters[kMu1]);
  }
  EXPECT_GT(at_bound, 0) << "no replica's mu1 profile reached its bound";
}

// The bar of the measured data: every bundled dataset's fit, as identify
// runs it, is a minimum that no profile undercuts (relative 1e-6 of the
// cost; on exact data, where the cost is round-off, 1e-20 absolute), and
// the reported intervals of the bounded parameters never go below zero.
class ProfileOfEveryBundledDataset : public ::testing::TestWithParam<std::string> {};

TEST_P(ProfileOfEveryBundledDataset, FindsNoCostBelowTheReportedMinimum) {
  IdentifyConfig config = LoadIdentifyConfig(kDatasets + GetParam());
  const ResolvedRun run = ResolveRun(config);
  IdentificationResult result = FitRun(run).best;
  const double omega_ref = config.omega_ref_rad_s.value_or(result.parameters[kNaturalFrequency]);
  const int threads = 2;
  const ParameterUncertainty u =
      EstimateUncertaintyAtMinimum(run.fitted, run.options, omega_ref, &result, threads);
  ASSERT_TRUE(u.available) << u.message;
  EXPECT_EQ(result.status, FitStatus::kConverged) << result.message;
  for (int j : {kEtaE, kMu1, kMu2, kNaturalFrequency}) {
    if (!run.options.fixed[j]) EXPECT_GE(u.ci95_low[j], 0.0) << ParameterName(j);
  }
  // The profile of every free parameter, run here whatever the reported
  // kind (exact data report the linearised one).
  ProfileProblem problem;
  problem.fitted = run.fitted;
  problem.fixed = run.options.fixed;
  problem.residual = run.options.solve.residual;
  problem.penalties = result.stages.back().penalties;
  problem.solver = run.options.solve.solver;
  problem.omega_ref_rad_s = omega_ref;
  problem.threshold = u.interval_kind == "profile_likelihood"
                          ? u.profile.threshold
                          : 0.5 * std::pow(u.interval_quantile * u.noise_sigma, 2);
  problem.threads = threads;
  const ProfileLikelihood profile =
      ProfileCost(problem, result.parameters, u.covariance, u.interval_quantile);
  const double floor = std::max(1e-6 * result.final_cost, 1e-20);
  EXPECT_GT(profile.fits, 0);
  EXPECT_NEAR(profile.minimum_cost, result.final_cost, floor);
  EXPECT_FALSE(profile.found_lower && profile.lower_cost < result.final_cost - floor)
      << profile.lower_while << ": " << profile.lower_cost << " < " << result.final_cost;
}

INSTANTIATE_TEST_SUITE_P(Datasets, ProfileOfEveryBundledDataset,
                         ::testing::Values("thesis-numerical/beam.yaml",
                                           "softening-numerical/beam.yaml",
                                           "virtual-beam/beam.yaml", "clamped-beam-27C/beam.yaml",
                                           "clamped-beam-27C/beam-selected.yaml"));

// The measured beam, both configs, as identify reports it: profile
// intervals (the reported interval is the profile's, so within any factor
// of it), none below zero for the bounded parameters, the linearised ones
// kept beside them.
TEST(ProfileLikelihood, IdentifyOnTheMeasuredBeamReportsProfileIntervals) {
  for (const std::string name : {"beam.yaml", "beam-selected.yaml"}) {
    SCOPED_TRACE(name);
    IdentifyConfig config = LoadIdentifyConfig(kDatasets + "clamped-beam-27C/" + name);
    config.output_dir = ::testing::TempDir() + "/profile_beam_" + name;
    std::ostringstream out;
    IdentifyRunOptions options;
    options.render_figures = false;
    const auto outcome = RunIdentify(config, out, options);
    const ParameterUncertainty& u = outcome->report.uncertainty;
    ASSERT_EQ(u.interval_kind, "profile_likelihood") << u.message;
    EXPECT_EQ(outcome->report.result.status, FitStatus::kConverged)
        << outcome->report.result.message;
    for (int j = 0; j < kNumParameters; ++j) {
      if (config.identification.fixed[j]) continue;
      const ProfileInterval& interval = u.profile.parameters[j];
      ASSERT_TRUE(interval.computed) << ParameterName(j);
      EXPECT_EQ(u.ci95_low[j], interval.low);
      EXPECT_EQ(u.ci95_high[j], interval.high);
      EXPECT_NE(interval.low_end, ProfileEnd::kOpen) << ParameterName(j);
      EXPECT_NE(interval.high_end, ProfileEnd::kOpen) << ParameterName(j);
      EXPECT_LE(interval.low, outcome->report.result.parameters[j]) << ParameterName(j);
      EXPECT_GE(interval.high, outcome->report.result.parameters[j]) << ParameterName(j);
      if (j == kEtaE || j == kMu1 || j == kMu2 || j == kNaturalFrequency) {
        EXPECT_GE(interval.low, 0.0) << ParameterName(j);
      }
    }
  }
}

}  // namespace
}  // namespace dwellfit
