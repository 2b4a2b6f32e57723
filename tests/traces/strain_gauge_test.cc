// The strain-gauge relations (3.4)-(3.7) on classical beam modes.
#include "dwellfit/estimator/traces/strain_gauge.h"

#include <cmath>
#include <string>

#include "gtest/gtest.h"

namespace dwellfit {
namespace {

// At the clamp of a cantilever the normalised first mode has phi' = 0 and
// phi'' = beta^2 (the cosh-cos form is 2 at the tip and 2 beta^2 at the clamp).
TEST(StrainGauge, CantileverFirstModeAtTheClampHasCurvatureBetaSquared) {
  StrainGaugeOptions options;
  options.gauge_position_m = 0.0;
  const ModeShapeAtGauge shape = ModeShapeAt(options);
  const double beta = 1.8751040687119611 / options.length_m;
  EXPECT_NEAR(shape.slope_per_m, 0.0, 1e-12);
  EXPECT_NEAR(shape.curvature_per_m2 / (beta * beta), 1.0, 1e-9);
}

// A clamped-clamped first mode peaks at mid-span: there phi' = 0, and the
// curvature is negative (the span bends the other way from the clamps).
TEST(StrainGauge, ClampedClampedFirstModeIsFlatAtMidSpan) {
  StrainGaugeOptions options;
  options.boundary = BeamBoundary::kClampedClamped;
  options.gauge_position_m = 0.5 * options.length_m;
  const ModeShapeAtGauge middle = ModeShapeAt(options);
  EXPECT_NEAR(middle.slope_per_m * options.length_m, 0.0, 1e-9);
  options.gauge_position_m = 0.0;
  const ModeShapeAtGauge clamp = ModeShapeAt(options);
  EXPECT_LT(middle.curvature_per_m2 * clamp.curvature_per_m2, 0.0);
}

TEST(StrainGauge, VoltageAndDisplacementAreInverses) {
  StrainGaugeOptions options;
  options.gauge_position_m = 0.3;  // phi' != 0: the nonlinear part of (3.7) acts
  const StrainGauge gauge(options);
  for (double u : {-0.2, -5e-3, -1e-6, 0.0, 2e-4, 4.7e-3, 0.15}) {
    double back = 1.0;
    ASSERT_TRUE(gauge.DisplacementFromVoltage(gauge.VoltageFromDisplacement(u), &back)) << u;
    EXPECT_NEAR(back, u, 1e-12 + 1e-12 * std::abs(u));
  }
  // (3.7) bends over: the small-signal slope overstates large displacements.
  const ModeShapeAtGauge shape = ModeShapeAt(options);
  const double u = 0.2;
  const double s = u * shape.slope_per_m;
  EXPECT_NEAR(gauge.VoltageFromDisplacement(u) / (gauge.SmallSignalVoltsPerMetre() * u),
              std::pow(1.0 + s * s, -1.5), 1e-12);
}

TEST(StrainGauge, AVoltageBeyondTheRelationsPeakIsRefused) {
  StrainGaugeOptions options;
  options.gauge_position_m = 0.3;
  const StrainGauge gauge(options);
  const double u_peak = 1.0 / (std::sqrt(2.0) * std::abs(ModeShapeAt(options).slope_per_m));
  double u = 0.0;
  EXPECT_FALSE(gauge.DisplacementFromVoltage(1.01 * gauge.VoltageFromDisplacement(u_peak), &u));
  EXPECT_FALSE(gauge.DisplacementFromVoltage(std::nan(""), &u));
}

TEST(StrainGauge, OptionsNameWhatIsWrong) {
  StrainGaugeOptions options;
  std::string error;
  EXPECT_TRUE(options.IsValid(&error)) << error;
  options.mode = 4;
  EXPECT_FALSE(options.IsValid(&error));
  EXPECT_NE(error.find("mode"), std::string::npos);
  options.mode = 1;
  options.gauge_position_m = 2.0;
  EXPECT_FALSE(options.IsValid(&error));
  EXPECT_NE(error.find("gauge_position_m"), std::string::npos);
}

}  // namespace
}  // namespace dwellfit
