// Harmonic balance's column of the method comparison on the virtual beam
// (datasets/virtual-beam): its estimates against the truth of the plan the
// rig ran, in the standard errors it states.
#include "dwellfit/estimator/studies/method_comparison.h"

#include <cmath>
#include <string>

#include "gtest/gtest.h"

namespace dwellfit {
namespace {

const std::string kDataset = std::string(DWELLFIT_SOURCE_DIR) + "/datasets/virtual-beam";

TraceCase VirtualBeam() {
  return LoadTraceCase(kDataset + "/beam.yaml", kDataset + "/plan.yaml", kDataset + "/rig.yaml",
                       kDataset + "/traces");
}

// The plan's truth (Table 3.1), typed here rather than read, so that a
// changed plan shows.
TEST(MethodComparison, TheVirtualBeamsTruthIsTheChaptersNumericalCase) {
  const TraceCase traces = VirtualBeam();
  const ParameterVector expected = {100.0, 0.2, 300.0, 1e4, 9e8, HzToRadPerSecond(40.0)};
  for (int i = 0; i < kNumParameters; ++i) {
    EXPECT_DOUBLE_EQ(traces.truth[i], expected[i]) << ParameterName(i);
  }
}

// eta_e, the damping, w and alpha_e (what the sweeps determine) lie within
// three of their standard errors of the truth. delta and alpha alone do not:
// noise in the regressors biases their split (docs/method-comparison.md;
// from noise-free traces they come back to 0.1 %, datasets/virtual-beam/
// README.md), so for them the test asserts what the doc states: both low, by
// more than 3 standard errors (and less than 10: 3.3 and 3.4 here, 5 to 7 over
// all dwells and with another noise seed).
TEST(MethodComparison, HarmonicBalanceOnTheFittedSweepsMatchesTheTruthWithinItsErrors) {
  const TraceCase traces = VirtualBeam();
  const HarmonicBalanceResult hb = FittedHarmonicBalance(traces);
  EXPECT_EQ(hb.dwells, 260);  // F0.01 and A41.5, up and down; the validation sweeps left out
  const ParameterVector& truth = traces.truth;
  for (ParameterIndex i : {kEtaE, kMu1, kMu2, kNaturalFrequency}) {
    ASSERT_GT(hb.standard_error[i], 0.0) << ParameterName(i);
    EXPECT_LE(std::abs(hb.estimate[i] - truth[i]), 3.0 * hb.standard_error[i]) << ParameterName(i);
  }
  const double omega_ref = HzToRadPerSecond(41.5);
  EXPECT_DOUBLE_EQ(hb.reference_rad_s, omega_ref);
  const double true_effective = truth[kAlpha] - 2.0 / 3.0 * truth[kDelta] * omega_ref * omega_ref;
  EXPECT_LE(std::abs(hb.effective_nonlinearity - true_effective),
            3.0 * hb.effective_nonlinearity_error);
  for (ParameterIndex i : {kDelta, kAlpha}) {
    const double z = (hb.estimate[i] - truth[i]) / hb.standard_error[i];
    EXPECT_LT(z, -3.0) << ParameterName(i);
    EXPECT_GT(z, -10.0) << ParameterName(i);
  }
}

}  // namespace
}  // namespace dwellfit
