#include "dwellfit/estimator/analysis/modal_properties.h"

#include <cmath>

#include "dwellfit/estimator/curves/response_curve.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"

namespace dwellfit {
namespace {

// Table 3.1's truth (omega in rad/s).
const ParameterVector kTruth = {100.0, 0.2, 300.0, 1e4, 9e8, 2.0 * 3.14159265358979323846 * 40.0};

// omega(a) is the backbone the response curve traces (its own formula, B / C
// of response_curve.h), and omega itself at a -> 0.
TEST(ModalProperties, TheNaturalFrequencyIsTheTracedBackbone) {
  CurveSpec spec;
  spec.name = "F0.01";
  spec.a_base = 0.01;
  spec.control_low = 2.0 * 3.14159265358979323846 * 38.0;
  spec.control_high = 2.0 * 3.14159265358979323846 * 46.0;
  const ResponseCurve curve = TraceResponseCurve(kFirstOrderForm, kTruth, spec);
  ASSERT_GT(curve.backbone.size(), 10u);
  for (const BackbonePoint& point : curve.backbone) {
    EXPECT_NEAR(ModalFrequency(kFirstOrderForm, kTruth, point.a), point.omega_rad_s,
                1e-9 * point.omega_rad_s);
  }
  EXPECT_DOUBLE_EQ(ModalFrequency(kFirstOrderForm, kTruth, 0.0), kTruth[kNaturalFrequency]);
}

// zeta(a) -> mu1 / omega as a -> 0 (2 mu1 u' = 2 zeta omega u'); with only
// mu1 uncertain (variance s^2) zeta's band is +/- 1.96 s / ((1 + delta a^2 / 2)
// omega(a)), and omega's has no width.
TEST(ModalProperties, TheDampingRatioAndItsBand) {
  EXPECT_NEAR(ModalDampingRatio(kFirstOrderForm, kTruth, 0.0), 0.2 / kTruth[kNaturalFrequency],
              1e-15);
  ParameterMatrix covariance = ParameterMatrix::Zero();
  const double s = 0.01;
  covariance(kMu1, kMu1) = s * s;
  const ModalProperties modal =
      ComputeModalProperties(kFirstOrderForm, kTruth, &covariance, 1e-4, 4e-3, 5);
  ASSERT_EQ(modal.points.size(), 5u);
  EXPECT_TRUE(modal.bands);
  EXPECT_DOUBLE_EQ(modal.points.back().a, 4e-3);
  for (const ModalPoint& p : modal.points) {
    const double half =
        1.959963984540054 * s /
        ((1.0 + 0.5 * kTruth[kDelta] * p.a * p.a) * ModalFrequency(kFirstOrderForm, kTruth, p.a));
    EXPECT_NEAR(p.zeta_high - p.zeta, half, 1e-6 * half);
    EXPECT_NEAR(p.zeta - p.zeta_low, half, 1e-6 * half);
    EXPECT_EQ(p.omega_hz_low, p.omega_hz);
    const double expected =
        (0.2 + 4.0 * 300.0 * p.a / (3.0 * 3.14159265358979323846)) /
        ((1.0 + 0.5e4 * p.a * p.a) * ModalFrequency(kFirstOrderForm, kTruth, p.a));
    EXPECT_NEAR(p.zeta, expected, 1e-15);
  }
  EXPECT_TRUE(ComputeModalProperties(kFirstOrderForm, kTruth, nullptr, 0.0, 1e-3).points.empty());
}

}  // namespace
}  // namespace dwellfit
