// EstimateUncertainty on the chapter's numerical case (datasets/thesis-numerical):
// tiny intervals on exact data, Student-t intervals from the residual noise,
// standardised residuals with point sigmas, rank deficiency reported in plain
// words, fixed parameters kept out, the penalty's curvature in the
// linearisation, and the coverage of the reported (profile) 95 % intervals
// over 200 noisy replicas.
#include "dwellfit/estimator/analysis/parameter_uncertainty.h"

#include <cmath>
#include <cstdint>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include "Eigen/LU"
#include "dwellfit/config/dwell_plan_reader.h"
#include "dwellfit/config/identify_config.h"
#include "dwellfit/estimator/fit/identification.h"
#include "dwellfit/estimator/fit/problem_builder.h"
#include "dwellfit/estimator/run/resolved_run.h"
#include "dwellfit/estimator/simulation/dwell_simulator.h"
#include "dwellfit/estimator/studies/coverage_study.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"

namespace dwellfit {
namespace {

using ::testing::AllOf;
using ::testing::HasSubstr;
using ::testing::Not;

const std::string kDataset = std::string(DWELLFIT_SOURCE_DIR) + "/datasets/thesis-numerical";
const ParameterVector kTruth = {100.0, 0.2, 300.0, 1e4, 9e8, HzToRadPerSecond(40.0)};

// Every number of `u` is finite (collinearity may be +inf: exactly collinear).
void ExpectAllFinite(const ParameterUncertainty& u) {
  for (double x :
       {u.noise_sigma, u.reduced_chi_square, u.interval_quantile, u.effective_nonlinearity,
        u.effective_nonlinearity_standard_error, u.effective_nonlinearity_ci95_low,
        u.effective_nonlinearity_ci95_high, u.omega_ref_rad_s}) {
    EXPECT_TRUE(std::isfinite(x)) << x;
  }
  EXPECT_FALSE(std::isnan(u.collinearity));
  for (int i = 0; i < kNumParameters; ++i) {
    EXPECT_TRUE(std::isfinite(u.standard_error[i])) << ParameterName(i);
    EXPECT_TRUE(std::isfinite(u.ci95_low[i])) << ParameterName(i);
    EXPECT_TRUE(std::isfinite(u.ci95_high[i])) << ParameterName(i);
  }
  EXPECT_TRUE(u.covariance.allFinite());
  EXPECT_TRUE(u.correlation.allFinite());
}

class UncertaintyThesisNumerical : public ::testing::Test {
 protected:
  virtual std::string Dataset() const { return kDataset; }
  void SetUp() override {
    config_ = LoadIdentifyConfig(Dataset() + "/beam.yaml");
    ASSERT_TRUE(config_.omega_ref_rad_s.has_value());
    omega_ref_ = *config_.omega_ref_rad_s;
    exact_ = ResolveRun(config_);
  }

  // The plan simulated with 1 % multiplicative noise, resolved as measured
  // sweeps are (branches labelled from the noisy data).
  ResolvedRun NoisyRun(std::uint64_t seed) const {
    DwellPlan plan = ReadDwellPlan(Dataset() + "/plan.yaml");
    plan.noise.relative_sigma = 0.01;
    plan.noise.seed = seed;
    return ResolveRun(config_, SimulateDwells(plan));
  }

  static std::vector<const Sweep*> Fitted(const ResolvedRun& run) { return run.fitted; }

  void CheckPenalisedLinearisation(std::uint64_t seed) const;

  // Both directions of the sweeps with these ids.
  static std::vector<const Sweep*> Named(const ResolvedRun& run,
                                         const std::vector<std::string>& ids) {
    std::vector<const Sweep*> selected;
    for (const Sweep& sweep : run.sweeps) {
      for (const std::string& id : ids) {
        if (sweep.id == id) selected.push_back(&sweep);
      }
    }
    return selected;
  }

  IdentifyConfig config_;
  double omega_ref_ = 0.0;
  ResolvedRun exact_;
};

TEST_F(UncertaintyThesisNumerical, ExactDataAtTheTruthGivesTinyIntervalsAroundIt) {
  const ParameterUncertainty u =
      EstimateUncertainty(Fitted(exact_), config_.identification, kTruth, omega_ref_);
  ASSERT_TRUE(u.available) << u.message;
  ExpectAllFinite(u);
  EXPECT_EQ(u.num_points, 260);
  EXPECT_EQ(u.num_free, 5);
  EXPECT_LT(u.noise_sigma, 1e-12);
  for (int i = 0; i < kNumParameters; ++i) {
    if (config_.identification.fixed[i]) continue;
    EXPECT_GT(u.standard_error[i], 0.0) << ParameterName(i);
    EXPECT_LT(u.standard_error[i], 1e-9 * kTruth[i]) << ParameterName(i);
    EXPECT_LE(u.ci95_low[i], kTruth[i]) << ParameterName(i);
    EXPECT_GE(u.ci95_high[i], kTruth[i]) << ParameterName(i);
  }
  EXPECT_NEAR(u.effective_nonlinearity, EffectiveNonlinearity(kTruth, omega_ref_), 1e-6);
  EXPECT_LT(u.effective_nonlinearity_standard_error, 1e-12 * u.effective_nonlinearity);
}

TEST_F(UncertaintyThesisNumerical, NoisyFitGivesStudentTIntervalsFromTheResidualNoise) {
  const ResolvedRun noisy = NoisyRun(20261121);
  const std::vector<const Sweep*> fitted = Fitted(noisy);
  const IdentificationResult result = Identify(fitted, config_.identification);
  const ParameterUncertainty u =
      EstimateUncertainty(fitted, config_.identification, result.parameters, omega_ref_, nullptr,
                          IntervalMethod::kLinearised);
  ASSERT_TRUE(u.available) << u.message;
  ExpectAllFinite(u);
  EXPECT_EQ(u.degrees_of_freedom, 260 - 5);
  // s^2 = 2 F / (n - k): the relative error measures ln(1 + 0.01 N) ~ 0.01 N.
  EXPECT_NEAR(u.reduced_chi_square, 2.0 * result.stages.back().final_data_cost / 255.0, 1e-12);
  EXPECT_NEAR(u.noise_sigma, 0.01, 0.0015);
  EXPECT_NEAR(u.interval_quantile, 1.96931, 1e-4);  // t_{0.975, 255}
  for (int i = 0; i < kNumParameters; ++i) {
    if (config_.identification.fixed[i]) continue;
    EXPECT_NEAR(u.standard_error[i], std::sqrt(u.covariance(i, i)), 1e-12 * u.standard_error[i]);
    EXPECT_NEAR(u.ci95_high[i] - result.parameters[i], u.interval_quantile * u.standard_error[i],
                1e-9 * u.standard_error[i]);
    EXPECT_NEAR(result.parameters[i] - u.ci95_low[i], u.interval_quantile * u.standard_error[i],
                1e-9 * u.standard_error[i]);
    EXPECT_DOUBLE_EQ(u.correlation(i, i), 1.0);
  }
  EXPECT_TRUE(u.covariance.isApprox(u.covariance.transpose(), 1e-12));
  // alpha_e's variance g^T C g, with g = [0, 0, 0, -(2/3) Omega_ref^2, 1, 0].
  const double g_delta = -(2.0 / 3.0) * omega_ref_ * omega_ref_;
  const double variance = u.covariance(kAlpha, kAlpha) +
                          2.0 * g_delta * u.covariance(kDelta, kAlpha) +
                          g_delta * g_delta * u.covariance(kDelta, kDelta);
  EXPECT_NEAR(u.effective_nonlinearity_standard_error, std::sqrt(variance),
              1e-6 * u.effective_nonlinearity_standard_error);
  // delta and alpha nearly collinear over this band, alpha_e well determined.
  EXPECT_THAT(u.warnings, ::testing::Contains(AllOf(HasSubstr("delta and alpha correlate at +"),
                                                    HasSubstr("fixed: [delta]"))));
  EXPECT_LT(u.effective_nonlinearity_standard_error / u.effective_nonlinearity,
            0.05 * u.standard_error[kAlpha] / result.parameters[kAlpha]);
}

TEST_F(UncertaintyThesisNumerical, PointSigmasStandardiseTheResidualsAndUseTheNormalQuantile) {
  ResolvedRun noisy = NoisyRun(20261121);
  const std::vector<const Sweep*> fitted = Fitted(noisy);
  const IdentificationResult result = Identify(fitted, config_.identification);
  const ParameterUncertainty estimated =
      EstimateUncertainty(fitted, config_.identification, result.parameters, omega_ref_, nullptr,
                          IntervalMethod::kLinearised);
  // The true standard deviation of every amplitude: 1 % of it (ln a: 0.01).
  for (Sweep& sweep : noisy.sweeps) {
    for (DwellPoint& point : sweep.points) point.sigma = 0.01 * point.amplitude;
  }
  IdentificationOptions options = config_.identification;
  options.solve.residual.use_point_sigma = true;
  const ParameterUncertainty given = EstimateUncertainty(
      fitted, options, result.parameters, omega_ref_, nullptr, IntervalMethod::kLinearised);
  ASSERT_TRUE(given.available) << given.message;
  ExpectAllFinite(given);
  EXPECT_DOUBLE_EQ(given.noise_sigma, 1.0);
  EXPECT_NEAR(given.interval_quantile, 1.959964, 1e-6);
  // Goodness of fit: (s_estimated / 0.01)^2, about 1.
  EXPECT_NEAR(given.reduced_chi_square, std::pow(estimated.noise_sigma / 0.01, 2), 1e-9);
  EXPECT_NEAR(given.reduced_chi_square, 1.0, 0.3);
  // Same J, noise 0.01 instead of s: every standard error scales by 0.01 / s.
  for (int i = 0; i < kNumParameters; ++i) {
    EXPECT_NEAR(given.standard_error[i], estimated.standard_error[i] * 0.01 / estimated.noise_sigma,
                1e-6 * estimated.standard_error[i])
        << ParameterName(i);
  }
  EXPECT_THAT(given.warnings, ::testing::Each(Not(HasSubstr("sigma"))));

  // Only some points with a sigma: mixed units, said so.
  for (DwellPoint& point : noisy.sweeps[0].points) point.sigma.reset();
  const ParameterUncertainty mixed = EstimateUncertainty(
      fitted, options, result.parameters, omega_ref_, nullptr, IntervalMethod::kLinearised);
  EXPECT_THAT(mixed.warnings, ::testing::Contains(HasSubstr("only some points have a sigma")));
  // s estimated from the mixed residuals, not assumed to be 1.
  EXPECT_NE(mixed.noise_sigma, 1.0);
  EXPECT_NEAR(mixed.noise_sigma * mixed.noise_sigma, mixed.reduced_chi_square, 1e-12);
  EXPECT_NEAR(mixed.interval_quantile, 1.96931, 1e-4);
}

TEST_F(UncertaintyThesisNumerical, AmplitudeSweepAloneCannotSeparateDeltaAndAlpha) {
  // At one drive frequency delta and alpha act only through
  // k4 = (3 alpha - 2 delta Omega^2) / (8 eta_e): their Jacobian columns are
  // exactly proportional, so J^T J is singular.
  const ParameterUncertainty u =
      EstimateUncertainty(Named(exact_, {"A41.5"}), config_.identification, kTruth, omega_ref_);
  EXPECT_FALSE(u.available);
  EXPECT_THAT(u.message, AllOf(HasSubstr("delta and alpha cannot be told apart"),
                               HasSubstr("correlation is +1.000"),
                               HasSubstr("alpha - (2/3) delta Omega^2 at Omega = 2 pi 41.5 Hz"),
                               HasSubstr("fixed: [delta]")));
  EXPECT_GT(u.collinearity, 1e12);
  ExpectAllFinite(u);
  for (int i = 0; i < kNumParameters; ++i) EXPECT_EQ(u.standard_error[i], 0.0);
  EXPECT_EQ(u.effective_nonlinearity_standard_error, 0.0);

  // With omega free as well, eta_e rescales with omega^2 - Omega^2: a second
  // lost direction.
  IdentificationOptions omega_free = config_.identification;
  omega_free.fixed[kNaturalFrequency] = false;
  const ParameterUncertainty two =
      EstimateUncertainty(Named(exact_, {"A41.5"}), omega_free, kTruth, omega_ref_);
  EXPECT_FALSE(two.available);
  EXPECT_THAT(two.message, AllOf(HasSubstr("eta_e"), HasSubstr("delta"), HasSubstr("alpha"),
                                 HasSubstr("omega"), HasSubstr("2 combination(s)")));
  ExpectAllFinite(two);

  // Fixing delta restores a covariance.
  IdentificationOptions delta_fixed = config_.identification;
  delta_fixed.fixed[kDelta] = true;
  EXPECT_TRUE(
      EstimateUncertainty(Named(exact_, {"A41.5"}), delta_fixed, kTruth, omega_ref_).available);
}

TEST_F(UncertaintyThesisNumerical, FrequencySweepAloneWarnsButKeepsTheEffectiveNonlinearity) {
  // Omega^2 varies by 47 % over 38-46 Hz, so delta and alpha are separable in
  // principle but correlate beyond 0.99: a warning, not a failure.
  const ResolvedRun noisy = NoisyRun(7);
  const std::vector<const Sweep*> fitted = Named(noisy, {"F0.01"});
  const IdentificationResult result = Identify(fitted, config_.identification);
  const ParameterUncertainty u =
      EstimateUncertainty(fitted, config_.identification, result.parameters, omega_ref_, nullptr,
                          IntervalMethod::kLinearised);
  ASSERT_TRUE(u.available) << u.message;
  ExpectAllFinite(u);
  EXPECT_GT(u.correlation(kDelta, kAlpha), 0.99);
  EXPECT_THAT(u.warnings, ::testing::Contains(HasSubstr("delta and alpha correlate")));
  // alpha_e is known to a few per cent, alpha alone far worse.
  EXPECT_LT(u.effective_nonlinearity_standard_error / u.effective_nonlinearity, 0.05);
  EXPECT_GT(u.standard_error[kAlpha] / result.parameters[kAlpha],
            5.0 * u.effective_nonlinearity_standard_error / u.effective_nonlinearity);
  EXPECT_LT(u.effective_nonlinearity_ci95_low, u.effective_nonlinearity);
  EXPECT_GT(u.effective_nonlinearity_ci95_high, u.effective_nonlinearity);
}

TEST_F(UncertaintyThesisNumerical, FixedParametersHaveZeroErrorAndStayOutOfWarnings) {
  const ResolvedRun noisy = NoisyRun(3);
  const std::vector<const Sweep*> fitted = Fitted(noisy);
  IdentificationOptions options = config_.identification;
  options.initial[kDelta] = kTruth[kDelta];
  options.fixed[kDelta] = true;
  const IdentificationResult result = Identify(fitted, options);
  const ParameterUncertainty u = EstimateUncertainty(fitted, options, result.parameters, omega_ref_,
                                                     nullptr, IntervalMethod::kLinearised);
  ASSERT_TRUE(u.available) << u.message;
  ExpectAllFinite(u);
  EXPECT_EQ(u.num_free, 4);
  for (int i : {kDelta, kNaturalFrequency}) {
    EXPECT_EQ(u.standard_error[i], 0.0) << ParameterName(i);
    EXPECT_EQ(u.ci95_low[i], result.parameters[i]) << ParameterName(i);
    EXPECT_EQ(u.ci95_high[i], result.parameters[i]) << ParameterName(i);
    EXPECT_TRUE(u.covariance.row(i).isZero(0.0)) << ParameterName(i);
    EXPECT_TRUE(u.covariance.col(i).isZero(0.0)) << ParameterName(i);
    EXPECT_TRUE(u.correlation.row(i).isZero(0.0)) << ParameterName(i);
  }
  for (const std::string& warning : u.warnings) {
    EXPECT_THAT(warning, AllOf(Not(HasSubstr("delta")), Not(HasSubstr("omega")))) << warning;
  }
  // delta fixed: alpha_e moves with alpha alone.
  EXPECT_NEAR(u.effective_nonlinearity_standard_error, u.standard_error[kAlpha],
              1e-9 * u.standard_error[kAlpha]);
}

TEST_F(UncertaintyThesisNumerical, WarnsWhenTheModelsFoldFallsShortOfMeasuredDwells) {
  // F0.01/up is on the upper branch at 42.2 Hz, 0.015 Hz below the true
  // jump-down fold; 1 % less alpha moves the model's fold below that dwell.
  const ParameterUncertainty at_truth =
      EstimateUncertainty(Fitted(exact_), config_.identification, kTruth, omega_ref_, nullptr,
                          IntervalMethod::kLinearised);
  EXPECT_EQ(at_truth.dwells_past_branch_end, 0);
  EXPECT_THAT(at_truth.warnings, ::testing::Each(Not(HasSubstr("past the end of their branch"))));

  ParameterVector softer = kTruth;
  softer[kAlpha] *= 0.99;
  const ParameterUncertainty u =
      EstimateUncertainty(Fitted(exact_), config_.identification, softer, omega_ref_, nullptr,
                          IntervalMethod::kLinearised);
  ASSERT_TRUE(u.available) << u.message;
  EXPECT_EQ(u.dwells_past_branch_end, 1);
  EXPECT_THAT(u.warnings, ::testing::Contains(AllOf(HasSubstr("1 fitted dwell(s) lie past"),
                                                    HasSubstr("F0.01/up at 42.2 Hz"))));
}

TEST_F(UncertaintyThesisNumerical, NoDampingAtAllHasNoFirstOrderEffectAndNoInterval) {
  // G depends on mu1, mu2 through k1^2, k2^2 and k1 k2: at mu1 = mu2 = 0 the
  // Jacobian columns of both vanish.
  ParameterVector undamped = kTruth;
  undamped[kMu1] = undamped[kMu2] = 0.0;
  const ParameterUncertainty u =
      EstimateUncertainty(Fitted(exact_), config_.identification, undamped, omega_ref_);
  EXPECT_FALSE(u.available);
  EXPECT_THAT(u.message, HasSubstr("mu1 = 0 has no first-order effect"));
  ExpectAllFinite(u);
}

TEST_F(UncertaintyThesisNumerical, NothingToEstimateIsReportedInWords) {
  IdentificationOptions all_fixed = config_.identification;
  all_fixed.fixed.fill(true);
  const ParameterUncertainty none =
      EstimateUncertainty(Fitted(exact_), all_fixed, kTruth, omega_ref_);
  EXPECT_FALSE(none.available);
  EXPECT_THAT(none.message, HasSubstr("every parameter is fixed"));
  ExpectAllFinite(none);

  // Three dwells for five free parameters: no degrees of freedom for s.
  Sweep short_sweep = *Named(exact_, {"F0.01"}).front();
  short_sweep.points.resize(3);
  const ParameterUncertainty few =
      EstimateUncertainty({&short_sweep}, config_.identification, kTruth, omega_ref_);
  EXPECT_FALSE(few.available);
  EXPECT_THAT(few.message, HasSubstr("no degrees of freedom"));
  EXPECT_EQ(few.degrees_of_freedom, -2);
  ExpectAllFinite(few);
}

// The finite-difference gradient of the distance u of `jump`'s fold from its
// bracket's centre (in half-widths), independent of the functor's Jets.
Eigen::VectorXd DistanceGradient(const Sweep& sweep, const JumpBracket& jump,
                                 const ParameterVector& p, double* distance) {
  BifurcationRangeOptions reading;
  reading.exponent = 2;
  reading.weight = 1.0;
  const std::unique_ptr<ceres::CostFunction> row(
      MakeBifurcationRangePenalty(kFirstOrderForm, sweep, jump, reading));
  auto evaluate = [&row](const ParameterVector& at) {
    const double* blocks[] = {at.data()};
    double u = 0.0;
    EXPECT_TRUE(row->Evaluate(blocks, &u, nullptr));
    return u;
  };
  *distance = evaluate(p);
  Eigen::VectorXd gradient(kNumParameters);
  for (int i = 0; i < kNumParameters; ++i) {
    const double h = 1e-6 * std::abs(p[i]);
    ParameterVector up = p, down = p;
    up[i] += h;
    down[i] -= h;
    gradient[i] = (evaluate(up) - evaluate(down)) / (2.0 * h);
  }
  return gradient;
}

// With the bifurcation-range penalty (W u^n, eq. 3.17) on, the linearised
// covariance is that of the penalised cost, recomputed here in another
// algebraic form with finite-difference gradients:
//   C = (C_d^-1 + I_p)^-1,  I_p = sum_k (kappa_k / s^2) g_k g_k^T,
//   kappa_k = (1/2) W n (n - 1) u_k^(n - 2),
// with C_d the dwells' own covariance.
void UncertaintyThesisNumerical::CheckPenalisedLinearisation(std::uint64_t seed) const {
  SCOPED_TRACE("seed " + std::to_string(seed));
  const ResolvedRun noisy = NoisyRun(seed);  // fits that keep every branch label
  IdentificationOptions options = config_.identification;
  options.solve.penalties.bifurcation_range.enabled = true;
  const IdentificationResult result = Identify(noisy.fitted, options);
  EXPECT_TRUE(result.converged) << result.message;
  const ParameterVector& p = result.parameters;
  const ParameterUncertainty data =
      EstimateUncertainty(noisy.fitted, options, p, omega_ref_, &result, IntervalMethod::kDataOnly);
  const ParameterUncertainty u = EstimateUncertainty(noisy.fitted, options, p, omega_ref_, &result,
                                                     IntervalMethod::kLinearised);
  ASSERT_TRUE(data.available) << data.message;
  ASSERT_TRUE(u.available) << u.message;
  EXPECT_EQ(data.interval_kind, "gauss_newton");
  EXPECT_EQ(u.interval_kind, "linearised_with_penalty");
  EXPECT_EQ(u.penalty_terms, 2);  // F0.01/up jump_down and A41.5/up jump_up
  EXPECT_THAT(u.message, HasSubstr("penalty's curvature at 2 enforced jump(s)"));

  const StageSummary& stage = result.stages.back();
  EXPECT_EQ(stage.penalty_exponent, 10);
  // The fit hands on the weight it used, in the cost's units.
  const double weight = options.solve.penalties.bifurcation_range.weight * stage.penalty_unit;
  EXPECT_DOUBLE_EQ(stage.penalties.bifurcation_range.weight, weight);
  const double s2 = data.noise_sigma * data.noise_sigma;
  // Free parameters only (omega is fixed), scaled by their values.
  const std::vector<int> free = {kEtaE, kMu1, kMu2, kDelta, kAlpha};
  Eigen::VectorXd scale(5);
  Eigen::MatrixXd data_cov(5, 5);
  for (int a = 0; a < 5; ++a) {
    scale[a] = std::abs(p[free[a]]);
    for (int b = 0; b < 5; ++b) {
      data_cov(a, b) = data.covariance(free[a], free[b]) / (scale[a] * std::abs(p[free[b]]));
    }
  }
  Eigen::MatrixXd penalty_information = Eigen::MatrixXd::Zero(5, 5);
  int enforced = 0;
  for (const Sweep* sweep : noisy.fitted) {
    for (const JumpBracket& jump : sweep->jumps) {
      const JumpTarget target = TargetOf(*sweep, jump);
      if (target != JumpTarget::kFrequencyJumpDown && target != JumpTarget::kAmplitudeJumpUp) {
        continue;
      }
      ++enforced;
      double distance = 0.0;
      const Eigen::VectorXd full = DistanceGradient(*sweep, jump, p, &distance);
      Eigen::VectorXd g(5);
      for (int a = 0; a < 5; ++a) g[a] = full[free[a]] * scale[a];
      EXPECT_LT(std::abs(distance), 1.0);  // the fold inside its bracket
      const double kappa = 0.5 * weight * 90.0 * std::pow(distance, 8);
      penalty_information += (kappa / s2) * g * g.transpose();
    }
  }
  EXPECT_EQ(enforced, 2);
  const Eigen::MatrixXd expected = (data_cov.inverse() + penalty_information).inverse();
  for (int k = 0; k < 5; ++k) {
    const int i = free[k];
    EXPECT_NEAR(u.standard_error[i] / scale[k], std::sqrt(expected(k, k)),
                1e-4 * std::sqrt(expected(k, k)))
        << ParameterName(i);
    EXPECT_LE(u.standard_error[i], data.standard_error[i] * (1.0 + 1e-9)) << ParameterName(i);
  }

  // Without the fit's summary the weight is unknown: the dwells alone, said.
  const ParameterUncertainty unknown = EstimateUncertainty(noisy.fitted, options, p, omega_ref_,
                                                           nullptr, IntervalMethod::kLinearised);
  EXPECT_EQ(unknown.interval_kind, "gauss_newton");
  EXPECT_THAT(unknown.warnings,
              ::testing::Contains(HasSubstr("the fit's penalty weight is not known here")));
  EXPECT_DOUBLE_EQ(unknown.standard_error[kMu2], data.standard_error[kMu2]);
}

TEST_F(UncertaintyThesisNumerical, PenaltyCurvatureEntersTheLinearisedCovariance) {
  for (std::uint64_t seed : {1, 2, 4}) CheckPenalisedLinearisation(seed);
}

// The softening case, where the penalty binds harder.
class UncertaintySofteningNumerical : public UncertaintyThesisNumerical {
 protected:
  std::string Dataset() const override {
    return std::string(DWELLFIT_SOURCE_DIR) + "/datasets/softening-numerical";
  }
};

TEST_F(UncertaintySofteningNumerical, PenaltyCurvatureEntersTheLinearisedCovariance) {
  for (std::uint64_t seed = 1; seed <= 4; ++seed) CheckPenalisedLinearisation(seed);
}

// The bar: over 200 noisy replicas each free parameter's 95 % interval
// covers the truth in 90-98 % of them (binomial sd of the rate: 1.5 %), and
// the mean standard error is near the spread of the estimates.
TEST(UncertaintyCoverage, NinetyFivePercentIntervalsCoverTheTruthOnTheThesisCase) {
  const IdentifyConfig config = LoadIdentifyConfig(kDataset + "/beam.yaml");
  const DwellPlan plan = ReadDwellPlan(kDataset + "/plan.yaml");
  CoverageStudyOptions options;
  options.replicas = 200;
  options.relative_noise = 0.01;
  options.first_seed = 1;
  const CoverageStudy study = RunCoverageStudy(config, plan, options);
  PrintCoverageStudy(study, std::cout);

  EXPECT_EQ(study.available, study.replicas);
  EXPECT_EQ(study.converged, study.replicas);
  EXPECT_NEAR(study.mean_noise_sigma, 0.01, 0.0005);
  ASSERT_EQ(study.rows.size(), 6u);  // five free parameters and alpha_e
  for (const CoverageRow& row : study.rows) {
    EXPECT_GE(row.Coverage(), 0.90) << row.name;
    EXPECT_LE(row.Coverage(), 0.98) << row.name;
    EXPECT_GT(row.mean_standard_error, 0.75 * row.empirical_std) << row.name;
    // The linearised standard errors beside the profile intervals.
    EXPECT_LT(row.mean_standard_error, 1.5 * row.empirical_std) << row.name;
  }
}

}  // namespace
}  // namespace dwellfit
