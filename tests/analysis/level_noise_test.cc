// The measured level's noise in the intervals (level_noise.h), against
// independent truths on the chapter's numerical case: the sandwich term
// against refits with each level draw moved (the estimate's own response to
// its levels), and the amplitude's own noise recovered from residuals that
// hold level errors too.
#include "dwellfit/estimator/analysis/level_noise.h"

#include <algorithm>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "dwellfit/config/dwell_plan_reader.h"
#include "dwellfit/config/identify_config.h"
#include "dwellfit/estimator/analysis/parameter_uncertainty.h"
#include "dwellfit/estimator/fit/identification.h"
#include "dwellfit/estimator/run/resolved_run.h"
#include "dwellfit/estimator/simulation/dwell_simulator.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"

namespace dwellfit {
namespace {

using Matrix6 = Eigen::Matrix<double, kNumParameters, kNumParameters>;
using Vector6 = Eigen::Matrix<double, kNumParameters, 1>;

const std::string kDataset = std::string(DWELLFIT_SOURCE_DIR) + "/datasets/thesis-numerical";

class LevelNoiseThesisNumerical : public ::testing::Test {
 protected:
  void SetUp() override {
    config_ = LoadIdentifyConfig(kDataset + "/beam.yaml");
    Simulate(0.01);
    options_ = config_.identification;
    options_.solve.stages = {ResidualKind::kVertical};
    options_.solve.penalties = PenaltyOptions();  // the dwells alone, as C_0
    options_.solve.solver.function_tolerance = 1e-16;
    options_.solve.solver.num_threads = 1;
  }

  // The plan's dwells with `noise` (relative), resolved as measured ones.
  void Simulate(double noise) {
    DwellPlan plan = ReadDwellPlan(kDataset + "/plan.yaml");
    plan.noise.relative_sigma = noise;
    plan.noise.seed = 20261127;
    run_ = ResolveRun(config_, SimulateDwells(plan));
  }

  ParameterVector Fit(const ParameterVector& start) const {
    IdentificationOptions options = options_;
    options.initial = start;
    const IdentificationResult result = Identify(run_.fitted, options);
    EXPECT_TRUE(result.IsSolutionUsable()) << result.message;
    return result.parameters;
  }

  // d p^ / d e: the refitted estimate's change per unit relative change of
  // the levels of the dwells `members` (central differences, step `h`).
  Vector6 RefitSlope(const ParameterVector& estimate, const std::vector<DwellPoint*>& members,
                     double h) {
    Vector6 slope;
    ParameterVector sides[2];
    for (int side = 0; side < 2; ++side) {
      const double scale = side == 0 ? 1.0 + h : 1.0 - h;
      for (DwellPoint* point : members) point->a_base *= scale;
      sides[side] = Fit(estimate);
      for (DwellPoint* point : members) point->a_base /= scale;
    }
    for (int j = 0; j < kNumParameters; ++j) slope[j] = (sides[0][j] - sides[1][j]) / (2.0 * h);
    return slope;
  }

  bool IsFitted(const Sweep& sweep) const {
    return std::find(run_.fitted.begin(), run_.fitted.end(), &sweep) != run_.fitted.end();
  }

  IdentifyConfig config_;
  ResolvedRun run_;
  IdentificationOptions options_;
};

// Exact dwells standardised by a stated 1 % (s = 1 known; zero residuals, so
// that J^T J is the cost's whole Hessian): the level's term equals
// sum_g kappa_g^2 (dp/de_g)(dp/de_g)^T with dp/de_g from refits, each level
// draw in turn moved by +/- 1e-4: both frequency sweeps (one draw each) and
// every fifth dwell of the amplitude sweeps (one draw per dwell).
TEST_F(LevelNoiseThesisNumerical, TheSandwichTermMatchesRefitsWithEachLevelMoved) {
  constexpr double kKappa = 0.005;
  Simulate(0.0);
  std::vector<std::vector<DwellPoint*>> groups;
  for (Sweep& sweep : run_.sweeps) {
    if (!IsFitted(sweep)) continue;
    const bool frequency = sweep.kind == SweepKind::kFrequency;
    if (frequency) groups.emplace_back();
    for (std::size_t i = 0; i < sweep.points.size(); ++i) {
      DwellPoint& point = sweep.points[i];
      point.sigma = 0.01 * point.amplitude;
      if (!frequency && i % 5 != 0) continue;
      point.a_base_sigma = kKappa * point.a_base;
      if (!frequency) groups.emplace_back();
      groups.back().push_back(&point);
    }
  }
  ASSERT_GT(groups.size(), 10u);
  const ParameterVector estimate = Fit(options_.initial);
  const ParameterUncertainty u =
      EstimateUncertainty(run_.fitted, options_, estimate, 0.0, nullptr, IntervalMethod::kDataOnly);
  ASSERT_TRUE(u.available) << u.message;
  EXPECT_THAT(u.message, ::testing::HasSubstr("with the measured level's noise (" +
                                              std::to_string(groups.size()) + " level draws)"));
  // C_0: the same fit's covariance without the levels' sigmas.
  for (const auto& group : groups) {
    for (DwellPoint* point : group) point->a_base_sigma.reset();
  }
  const ParameterUncertainty u0 =
      EstimateUncertainty(run_.fitted, options_, estimate, 0.0, nullptr, IntervalMethod::kDataOnly);
  ASSERT_TRUE(u0.available);
  for (const auto& group : groups) {
    for (DwellPoint* point : group) point->a_base_sigma = kKappa * point->a_base;
  }
  const double data_cost = 0.5 * u0.reduced_chi_square * u0.degrees_of_freedom;
  const LevelNoise level =
      EstimateLevelNoise(run_.fitted, options_, estimate, u0.covariance, u0.noise_sigma, data_cost,
                         u0.degrees_of_freedom, /*standardised=*/true);
  ASSERT_EQ(level.groups, static_cast<int>(groups.size()));
  EXPECT_EQ(level.noise_sigma, 1.0);
  Matrix6 refitted = Matrix6::Zero();
  for (const auto& group : groups) {
    const Vector6 slope = RefitSlope(estimate, group, 1e-4);
    refitted += kKappa * kKappa * slope * slope.transpose();
  }
  for (int j = 0; j < kNumParameters; ++j) {
    if (options_.fixed[j]) {
      EXPECT_EQ(level.added(j, j), 0.0);
      continue;
    }
    EXPECT_NEAR(level.added(j, j), refitted(j, j), 0.01 * refitted(j, j)) << ParameterName(j);
    // The level adds a visible share to the dwells' own variance.
    EXPECT_GT(level.added(j, j), 0.05 * u0.covariance(j, j)) << ParameterName(j);
    EXPECT_NEAR(u.covariance(j, j), u0.covariance(j, j) + level.added(j, j),
                1e-9 * u.covariance(j, j));
  }
}

// Unstandardised dwells with 1 % amplitude noise and measured levels off by
// draws of 2 % (stated as a_base_sigma): the residuals' scatter s holds both,
// and s' (the amplitude's own noise) comes back near 1 %.
TEST_F(LevelNoiseThesisNumerical, TheAmplitudesOwnNoiseIsSeparatedFromTheLevels) {
  constexpr double kKappa = 0.02;
  std::mt19937_64 random(7);
  std::normal_distribution<double> normal;
  for (Sweep& sweep : run_.sweeps) {
    if (!IsFitted(sweep)) continue;
    const double shared = normal(random);
    for (DwellPoint& point : sweep.points) {
      const double e = sweep.kind == SweepKind::kFrequency ? shared : normal(random);
      point.a_base *= 1.0 + kKappa * e;
      point.a_base_sigma = kKappa * point.a_base;
    }
  }
  const ParameterVector estimate = Fit(options_.initial);
  const ParameterUncertainty u =
      EstimateUncertainty(run_.fitted, options_, estimate, 0.0, nullptr, IntervalMethod::kDataOnly);
  ASSERT_TRUE(u.available) << u.message;
  const double s = std::sqrt(u.reduced_chi_square);
  EXPECT_GT(s, 0.013);  // the levels' share is visible in the scatter
  EXPECT_NEAR(u.noise_sigma, 0.01, 0.0015);
  EXPECT_THAT(u.warnings, ::testing::Each(::testing::Not(::testing::HasSubstr("a_base_sigma"))));
}

// The reported profile intervals: each side's half-width h (the profile's,
// without the level) becomes sqrt(h^2 + q^2 dC_jj), dC the level's term of
// the linearised covariance; alpha_e's likewise with g^T dC g.
TEST_F(LevelNoiseThesisNumerical, ProfileIntervalsAreWidenedByTheLevelsTerm) {
  const ParameterVector estimate = Fit(options_.initial);
  const ParameterUncertainty profile0 =
      EstimateUncertainty(run_.fitted, options_, estimate, 0.0, nullptr, IntervalMethod::kProfile);
  const ParameterUncertainty linear0 = EstimateUncertainty(run_.fitted, options_, estimate, 0.0,
                                                           nullptr, IntervalMethod::kLinearised);
  for (Sweep& sweep : run_.sweeps) {
    for (DwellPoint& point : sweep.points) point.a_base_sigma = 0.005 * point.a_base;
  }
  const ParameterUncertainty profile1 =
      EstimateUncertainty(run_.fitted, options_, estimate, 0.0, nullptr, IntervalMethod::kProfile);
  const ParameterUncertainty linear1 = EstimateUncertainty(run_.fitted, options_, estimate, 0.0,
                                                           nullptr, IntervalMethod::kLinearised);
  ASSERT_EQ(profile0.interval_kind, "profile_likelihood") << profile0.message;
  ASSERT_EQ(profile1.interval_kind, "profile_likelihood") << profile1.message;
  EXPECT_THAT(profile1.message, ::testing::HasSubstr("widened by the level's noise"));
  const double q = profile1.interval_quantile;
  const auto widened = [q](double half, double added) {
    return std::sqrt(half * half + q * q * added);
  };
  for (int j = 0; j < kNumParameters; ++j) {
    if (options_.fixed[j]) continue;
    const double added = linear1.covariance(j, j) - linear0.covariance(j, j);
    EXPECT_GT(added, 0.0) << ParameterName(j);
    const double low = widened(estimate[j] - profile0.ci95_low[j], added);
    const double high = widened(profile0.ci95_high[j] - estimate[j], added);
    EXPECT_NEAR(estimate[j] - profile1.ci95_low[j], low, 1e-6 * low) << ParameterName(j);
    EXPECT_NEAR(profile1.ci95_high[j] - estimate[j], high, 1e-6 * high) << ParameterName(j);
  }
  EXPECT_GT(profile1.effective_nonlinearity_ci95_high - profile1.effective_nonlinearity_ci95_low,
            profile0.effective_nonlinearity_ci95_high - profile0.effective_nonlinearity_ci95_low);
}

}  // namespace
}  // namespace dwellfit
