// Harmonic balance on exact Fourier coefficients, and its refusals.
#include "dwellfit/estimator/traces/harmonic_balance.h"

#include <complex>
#include <string>
#include <vector>

#include "dwellfit/estimator/common/input_error.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"

namespace dwellfit {
namespace {

using Complex = std::complex<double>;

// A linear mode (delta = alpha = mu2 = 0) answers a_b cos(Omega t) exactly
// with u = Re U exp(i Omega t), U = 2 eta_e a_b / (w^2 - Omega^2 + 2 i mu1 Omega).
std::vector<DwellHarmonics> LinearDwells(double eta_e, double mu1, double w, int harmonics) {
  std::vector<DwellHarmonics> dwells;
  for (double f_hz : {38.0, 39.5, 40.0, 40.5, 42.0}) {
    for (double a_base : {0.005, 0.02}) {
      const double omega = HzToRadPerSecond(f_hz);
      DwellHarmonics dwell;
      dwell.drive_frequency_rad_s = omega;
      dwell.u.assign(harmonics + 1, Complex(0.0));
      dwell.base.assign(harmonics + 1, Complex(0.0));
      dwell.base[1] = a_base;
      dwell.u[1] = 2.0 * eta_e * a_base / Complex(w * w - omega * omega, 2.0 * mu1 * omega);
      dwells.push_back(dwell);
    }
  }
  return dwells;
}

TEST(HarmonicBalance, ExactCoefficientsOfALinearModeGiveItsParameters) {
  const double w = HzToRadPerSecond(40.0);
  const HarmonicBalanceResult result =
      IdentifyHarmonicBalance(LinearDwells(100.0, 0.2, w, 3), 3, 0.0);
  EXPECT_NEAR(result.estimate[kEtaE] / 100.0, 1.0, 1e-9);
  EXPECT_NEAR(result.estimate[kMu1] / 0.2, 1.0, 1e-7);
  EXPECT_NEAR(result.estimate[kNaturalFrequency] / w, 1.0, 1e-12);
  // The nonlinear terms are absent: zero on the scale of Table 3.1's values.
  EXPECT_NEAR(result.estimate[kMu2], 0.0, 1e-6 * 300.0);
  EXPECT_NEAR(result.estimate[kDelta], 0.0, 1e-6 * 1e4);
  EXPECT_NEAR(result.estimate[kAlpha], 0.0, 1e-6 * 9e8);
  EXPECT_EQ(result.dwells, 10);
  EXPECT_EQ(result.rows, 70);
  EXPECT_EQ(result.reference_rad_s, result.estimate[kNaturalFrequency]);
}

TEST(HarmonicBalance, TooFewDwellsOrHarmonicsAreRefused) {
  const double w = HzToRadPerSecond(40.0);
  std::vector<DwellHarmonics> dwells = LinearDwells(100.0, 0.2, w, 3);
  dwells.resize(2);
  try {
    IdentifyHarmonicBalance(dwells, 3, 0.0);
    ADD_FAILURE() << "two dwells were accepted";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), ::testing::HasSubstr("2 dwell(s) give 14 equations for 6 parameters"));
  }
  EXPECT_THROW(IdentifyHarmonicBalance(LinearDwells(100.0, 0.2, w, 2), 3, 0.0), InputError);
}

}  // namespace
}  // namespace dwellfit
