// Per-sweep forcing calibration (estimator/fit/forcing_calibration.h) on
// noise-free simulated sweeps whose recorded level is off by a known factor:
// the calibrated fit finds that factor and the true parameters, a held-out
// sweep's scale comes from its dwells before the jump, and the prior's
// derivatives match finite differences.
#include "dwellfit/estimator/fit/forcing_calibration.h"

#include <cmath>
#include <string>
#include <vector>

#include "ceres/gradient_checker.h"
#include "gtest/gtest.h"
#include "tests/fit_test_support.h"

namespace dwellfit {
namespace {

// The shaker drove the "F" sweeps `factor` times harder than recorded: the
// recorded a_base is the true one divided by `factor`.
std::vector<Sweep> MisleveledDataset(double factor) {
  std::vector<Sweep> sweeps = SimulateDataset(kThesisTruth, 0.0, 1);
  for (Sweep& sweep : sweeps) {
    if (sweep.id != "F") continue;
    for (DwellPoint& point : sweep.points) point.a_base /= factor;
  }
  return sweeps;
}

// The prior's residual at the shared truth and `own`, after checking its
// Jacobian against finite differences there.
double CheckedPriorResidual(const ForcingScalePrior& prior, std::vector<double> own) {
  ParameterVector shared = kThesisTruth;
  ceres::NumericDiffOptions numeric;
  const std::vector<const ceres::Manifold*>* euclidean = nullptr;
  ceres::GradientChecker checker(&prior, euclidean, numeric);
  ceres::GradientChecker::ProbeResults results;
  std::vector<double*> blocks = {shared.data(), own.data()};
  EXPECT_TRUE(checker.Probe(blocks.data(), 1e-9, &results)) << results.error_log;
  double residual = 0.0;
  const double* values[] = {shared.data(), own.data()};
  EXPECT_TRUE(prior.Evaluate(values, &residual, nullptr));
  return residual;
}

TEST(ForcingCalibration, ThePriorsJacobianMatchesFiniteDifferences) {
  EXPECT_DOUBLE_EQ(CheckedPriorResidual(ForcingScalePrior(3, 1, 7.0), {95.0, 104.0, 99.0}),
                   7.0 * (104.0 / 100.0 - 1.0));
  // On the natural frequency: w_k / w - 1.
  EXPECT_NEAR(CheckedPriorResidual(ForcingScalePrior(2, 0, 3.0, kNaturalFrequency),
                                   {1.01 * kThesisTruth[kNaturalFrequency], 250.0}),
              3.0 * 0.01, 1e-15);
}

TEST(ForcingCalibration, TheCalibratedFitFindsTheLevelErrorAndTheTrueParameters) {
  const double factor = 1.05;
  const std::vector<Sweep> sweeps = MisleveledDataset(factor);
  IdentificationOptions options;
  options.initial = kThesisTruth;
  options.initial[kEtaE] *= 1.02;
  options.initial[kDelta] *= 0.9;
  options.fixed[kNaturalFrequency] = true;
  ForcingCalibrationOptions calibration;
  const CalibratedIdentification result = IdentifyWithForcingCalibration(
      Pointers(sweeps), options, calibration, 1e-9);  // the data decide
  ASSERT_TRUE(result.fit.IsSolutionUsable()) << result.fit.message;
  ASSERT_EQ(result.scales.size(), sweeps.size());
  for (size_t k = 0; k < sweeps.size(); ++k) {
    const double expected = sweeps[k].id == "F" ? factor : 1.0;
    // Each sweep's eta_k = s_k eta_e is fixed by its dwells: the ratios are exact.
    EXPECT_NEAR(result.scales[k] / result.scales.back(), expected, 1e-6) << sweeps[k].Name();
    EXPECT_NEAR(result.scales[k] * result.fit.parameters[kEtaE], expected * kThesisTruth[kEtaE],
                1e-4)
        << sweeps[k].Name();
  }
  for (ParameterIndex i : {kMu1, kMu2, kDelta, kAlpha}) {
    EXPECT_NEAR(result.fit.parameters[i] / kThesisTruth[i], 1.0, 1e-6) << ParameterName(i);
  }
}

TEST(ForcingCalibration, AHeldOutSweepsScaleComesFromItsDwellsBeforeTheJump) {
  const std::vector<Sweep> sweeps = MisleveledDataset(1.04);
  const Sweep& up = sweeps[0];
  ASSERT_EQ(up.Name(), "F/up");
  ASSERT_FALSE(up.jumps.empty());
  const Sweep before = CalibrationDwells(up, HeldOutDwells::kBeforeJump);
  EXPECT_EQ(before.points.size(), static_cast<size_t>(up.jumps.front().index_before) + 1);
  EXPECT_TRUE(before.jumps.empty());
  const Sweep low = CalibrationDwells(up, HeldOutDwells::kBelowHalfPeak);
  ASSERT_GE(low.points.size(), 2u);
  EXPECT_LT(low.points.size(), before.points.size());
  IdentificationOptions options;
  options.initial = kThesisTruth;
  std::string why;
  ForcingCalibrationOptions calibration;
  // A data sigma far below the prior's: the dwells decide.
  const double scale = CalibrateHeldOutScale(up, kThesisTruth, options, calibration, 1e-8, &why);
  EXPECT_NEAR(scale, 1.04, 1e-5) << why;
  // A data sigma far above it: the prior holds the scale near 1.
  const double held = CalibrateHeldOutScale(up, kThesisTruth, options, calibration, 1e3, &why);
  EXPECT_NEAR(held, 1.0, 1e-3) << why;
  calibration.held_out_dwells = HeldOutDwells::kBelowHalfPeak;
  EXPECT_NEAR(CalibrateHeldOutScale(up, kThesisTruth, options, calibration, 1e-8, &why), 1.04, 1e-5)
      << why;
  calibration.prior_sigma = 0.0;
  EXPECT_TRUE(std::isnan(CalibrateHeldOutScale(up, kThesisTruth, options, calibration, 1.0, &why)));
  EXPECT_NE(why.find("prior_sigma"), std::string::npos) << why;
}

// The "F" sweeps of a structure whose natural frequency drifted by `factor`
// between sweeps: they are simulated at w * factor, the others at w.
std::vector<Sweep> DriftedDataset(double factor) {
  ParameterVector drifted = kThesisTruth;
  drifted[kNaturalFrequency] *= factor;
  const std::vector<Sweep> shifted = SimulateDataset(drifted, 0.0, 1);
  std::vector<Sweep> sweeps = SimulateDataset(kThesisTruth, 0.0, 1);
  for (size_t k = 0; k < sweeps.size(); ++k) {
    if (sweeps[k].id == "F") sweeps[k] = shifted[k];
  }
  return sweeps;
}

// With omega calibrated, each sweep gets its own w: the drifted sweeps' w_k
// come out `factor` times the others', the other parameters true, and a
// held-out drifted sweep's scale from its dwells before the jump is `factor`.
TEST(ForcingCalibration, ADriftedNaturalFrequencyIsFoundPerSweep) {
  const double factor = 1.003;
  const std::vector<Sweep> sweeps = DriftedDataset(factor);
  IdentificationOptions options;
  options.initial = kThesisTruth;
  options.initial[kEtaE] *= 1.02;
  options.initial[kDelta] *= 0.9;
  ForcingCalibrationOptions calibration;
  calibration.parameter = CalibratedParameter::kNaturalFrequency;
  const CalibratedIdentification result =
      IdentifyWithForcingCalibration(Pointers(sweeps), options, calibration, 1e-9);
  ASSERT_TRUE(result.fit.IsSolutionUsable()) << result.fit.message;
  ASSERT_EQ(result.scales.size(), sweeps.size());
  for (size_t k = 0; k < sweeps.size(); ++k) {
    const double expected = sweeps[k].id == "F" ? factor : 1.0;
    EXPECT_NEAR(result.scales[k] / result.scales.back(), expected, 1e-6) << sweeps[k].Name();
  }
  for (ParameterIndex i : {kEtaE, kMu1, kMu2, kDelta, kAlpha}) {
    EXPECT_NEAR(result.fit.parameters[i] / kThesisTruth[i], 1.0, 1e-6) << ParameterName(i);
  }
  const Sweep& up = sweeps[0];
  ASSERT_EQ(up.Name(), "F/up");
  std::string why;
  calibration.held_out_dwells = HeldOutDwells::kBelowHalfPeak;
  EXPECT_NEAR(CalibrateHeldOutScale(up, kThesisTruth, options, calibration, 1e-8, &why), factor,
              1e-6)
      << why;
  EXPECT_STREQ(CalibratedParameterName(calibration.parameter), "omega");
}

}  // namespace
}  // namespace dwellfit
