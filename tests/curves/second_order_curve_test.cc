// The second-order model's response curves (response_curve.h): every traced
// point is a fixed point of the full model, the folds are its turning points,
// and the curve's amplitudes are the model's stable roots.
#include <cmath>

#include "dwellfit/estimator/curves/response_curve.h"
#include "dwellfit/residuals/model/fold_point.h"
#include "dwellfit/residuals/model/response_model.h"
#include "gtest/gtest.h"

namespace dwellfit {
namespace {

// Table 3.1 (docs/model.md).
const ParameterVector kTruth = {100.0, 0.2, 300.0, 1e4, 9e8, HzToRadPerSecond(40.0)};

CurveSpec FrequencySpec(double a_base) {
  CurveSpec spec;
  spec.name = "F";
  spec.kind = SweepKind::kFrequency;
  spec.a_base = a_base;
  spec.control_low = HzToRadPerSecond(38.0);
  spec.control_high = HzToRadPerSecond(46.0);
  return spec;
}

CurveSpec AmplitudeSpec(double hz) {
  CurveSpec spec;
  spec.name = "A";
  spec.kind = SweepKind::kAmplitude;
  spec.omega_rad_s = HzToRadPerSecond(hz);
  spec.control_low = 0.002;
  spec.control_high = 0.05;
  return spec;
}

ResponseCoefficients<double> SecondOrderAt(double omega) {
  return ResponseCoefficients<double>::FromParameters(kSecondOrderForm, kTruth.data(), omega);
}

void ExpectPointsAndFoldsOfTheFullModel(const ResponseCurve& curve) {
  ASSERT_GT(curve.points.size(), 100u);
  int folds = 0;
  for (const CurvePoint& point : curve.points) {
    const auto k = SecondOrderAt(point.omega_rad_s);
    const double target = point.a_base * point.a_base;
    EXPECT_NEAR(k.G(point.a), target, 1e-8 * target)
        << RadPerSecondToHz(point.omega_rad_s) << " Hz, a " << point.a;
    // A fold is listed twice, once with each side's stability.
    if (!point.fold) {
      EXPECT_EQ(point.stable, k.dG(point.a) > 0.0);
      continue;
    }
    ++folds;
    // dG/da = 0, relative to the scale G / a of the slope.
    EXPECT_NEAR(k.dG(point.a) * point.a / target, 0.0, 1e-8);
  }
  EXPECT_GT(folds, 0);
}

TEST(SecondOrderCurve, FrequencyCurveSolvesTheFullModelAndFoldsWhereItsSlopeVanishes) {
  const ResponseCurve curve = TraceResponseCurve(kSecondOrderForm, kTruth, FrequencySpec(0.01));
  ExpectPointsAndFoldsOfTheFullModel(curve);
  // Two folds, each where SolveFrequencyFold puts the second order's.
  ASSERT_EQ(curve.folds.size(), 2u);
  for (const CurveFold& fold : curve.folds) {
    const FoldPoint solved = SolveFrequencyFold(kSecondOrderForm, kTruth.data(), 0.01, fold.kind,
                                                fold.control, 1e-3 * fold.control);
    ASSERT_TRUE(solved.exists);
    EXPECT_NEAR(fold.control, solved.control, 1e-9 * solved.control) << JumpKindName(fold.kind);
    EXPECT_NEAR(fold.a, solved.a, 1e-6 * solved.a);
  }
  // The peak is lower than the first order's: the second order lies below
  // it (docs/model.md: the first order lies above the integrated response).
  double peak_first = 0.0, peak_second = 0.0;
  for (const CurvePoint& p : curve.points) peak_second = std::max(peak_second, p.a);
  const ResponseCurve first = TraceResponseCurve(kFirstOrderForm, kTruth, FrequencySpec(0.01));
  for (const CurvePoint& p : first.points) peak_first = std::max(peak_first, p.a);
  EXPECT_LT(peak_second, peak_first);
  EXPECT_GT(peak_second, 0.99 * peak_first);
}

TEST(SecondOrderCurve, AmplitudeCurveSolvesTheFullModel) {
  const ResponseCurve curve = TraceResponseCurve(kSecondOrderForm, kTruth, AmplitudeSpec(41.5));
  ExpectPointsAndFoldsOfTheFullModel(curve);
  EXPECT_EQ(curve.folds.size(), 2u);
}

TEST(SecondOrderCurve, AmplitudesAtAFrequencyAreTheModelsStableRoots) {
  const ResponseCurve curve = TraceResponseCurve(kSecondOrderForm, kTruth, FrequencySpec(0.01));
  const double omega = HzToRadPerSecond(41.5);
  const std::vector<CurveRoot> roots = CurveAmplitudesAt(kSecondOrderForm, kTruth, curve, omega);
  ASSERT_EQ(roots.size(), 3u);  // lower, middle (unstable), upper
  for (Branch branch : {Branch::kLower, Branch::kUpper}) {
    const StableRoot root = ModelAmplitude(kSecondOrderForm, kTruth, omega, 0.01, branch, 0.0);
    ASSERT_EQ(root.status, RootStatus::kOnBranch);
    EXPECT_NEAR(CurveAmplitudeOnBranch(roots, branch, 0.0), root.a, 1e-9 * root.a)
        << BranchName(branch);
  }
  EXPECT_FALSE(roots[1].stable);
}

}  // namespace
}  // namespace dwellfit
