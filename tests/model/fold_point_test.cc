#include "dwellfit/residuals/model/fold_point.h"

#include <memory>
#include <vector>

#include "ceres/autodiff_cost_function.h"
#include "ceres/gradient_checker.h"
#include "gtest/gtest.h"

namespace dwellfit {
namespace {

const ParameterVector kTruth = {100.0, 0.2, 300.0, 1e4, 9e8, HzToRadPerSecond(40.0)};

TEST(SolveAmplitudeFold, JumpLevelsAt41_5HzSolveTheFoldConditions) {
  const double omega = HzToRadPerSecond(41.5);
  const FoldPoint up = SolveAmplitudeFold(kFirstOrderForm, kTruth.data(), omega, JumpKind::kJumpUp);
  const FoldPoint down =
      SolveAmplitudeFold(kFirstOrderForm, kTruth.data(), omega, JumpKind::kJumpDown);
  ASSERT_TRUE(up.exists);
  ASSERT_TRUE(down.exists);
  // The dataset's A41.5 sweep jumps up between a_base 0.035 and 0.036 and
  // down between 0.007 and 0.006.
  EXPECT_GT(up.control, 0.035);
  EXPECT_LT(up.control, 0.036);
  EXPECT_GT(down.control, 0.006);
  EXPECT_LT(down.control, 0.007);
  const auto k =
      ResponseCoefficients<double>::FromParameters(kFirstOrderForm, kTruth.data(), omega);
  EXPECT_NEAR(k.dG(up.a), 0.0, 1e-14);
  EXPECT_NEAR(k.G(down.a), down.control * down.control, 1e-18);
}

TEST(SolveFrequencyFold, JumpFrequenciesAtABase0_01SolveTheFoldConditions) {
  const double a_base = 0.01;
  const FoldPoint down =
      SolveFrequencyFold(kFirstOrderForm, kTruth.data(), a_base, JumpKind::kJumpDown,
                         HzToRadPerSecond(42.25), HzToRadPerSecond(0.05));
  const FoldPoint up = SolveFrequencyFold(kFirstOrderForm, kTruth.data(), a_base, JumpKind::kJumpUp,
                                          HzToRadPerSecond(40.65), HzToRadPerSecond(0.05));
  ASSERT_TRUE(down.exists);
  ASSERT_TRUE(up.exists);
  // Brackets of the dataset's F0.01 sweep: 42.2-42.3 Hz (up), 40.7-40.6 Hz (down).
  EXPECT_GT(RadPerSecondToHz(down.control), 42.2);
  EXPECT_LT(RadPerSecondToHz(down.control), 42.3);
  EXPECT_GT(RadPerSecondToHz(up.control), 40.6);
  EXPECT_LT(RadPerSecondToHz(up.control), 40.7);
  for (const FoldPoint& fold : {down, up}) {
    const auto k =
        ResponseCoefficients<double>::FromParameters(kFirstOrderForm, kTruth.data(), fold.control);
    EXPECT_NEAR(k.G(fold.a) / (a_base * a_base), 1.0, 1e-12);
    EXPECT_NEAR(k.dG(fold.a) / k.d2G(fold.a), 0.0, 1e-12 * fold.a);
  }
}

TEST(SolveFrequencyFold, FindsTheFoldFromAGuessFarFromItAndFromBeyondTheCusp) {
  const FoldPoint reference = SolveFrequencyFold(kFirstOrderForm, kTruth.data(), 0.01,
                                                 JumpKind::kJumpDown, HzToRadPerSecond(42.25), 0.1);
  for (double guess_hz : {41.0, 44.0, 39.0}) {  // 39 Hz: no turning points there
    const FoldPoint fold = SolveFrequencyFold(kFirstOrderForm, kTruth.data(), 0.01,
                                              JumpKind::kJumpDown, HzToRadPerSecond(guess_hz), 0.1);
    ASSERT_TRUE(fold.exists) << guess_hz;
    EXPECT_NEAR(fold.control, reference.control, 1e-9 * reference.control) << guess_hz;
  }
}

TEST(SolveFrequencyFold, ReportsNoFoldWhenTheDampingIsTooHighForAJump) {
  ParameterVector damped = kTruth;
  damped[kMu1] = 20.0;  // 100 x: no bistability at a_base = 0.01
  EXPECT_FALSE(SolveFrequencyFold(kFirstOrderForm, damped.data(), 0.01, JumpKind::kJumpDown,
                                  HzToRadPerSecond(42.25), 0.1)
                   .exists);
  EXPECT_FALSE(
      SolveAmplitudeFold(kFirstOrderForm, damped.data(), HzToRadPerSecond(41.5), JumpKind::kJumpUp)
          .exists);
}

// Functors exposing the lifted folds as residuals, to check their derivatives.
struct FrequencyFoldOf {
  JumpKind kind;
  template <typename T>
  bool operator()(const T* p, T* out) const {
    ParameterVector value;
    for (int i = 0; i < kNumParameters; ++i) value[i] = ScalarPart(p[i]);
    const FoldPoint fold = SolveFrequencyFold(kFirstOrderForm, value.data(), 0.01, kind,
                                              HzToRadPerSecond(41.5), HzToRadPerSecond(0.05));
    if (!fold.exists) return false;
    out[0] = LiftFrequencyFold(kFirstOrderForm, p, 0.01, fold);
    return true;
  }
};

struct AmplitudeFoldOf {
  JumpKind kind;
  template <typename T>
  bool operator()(const T* p, T* out) const {
    ParameterVector value;
    for (int i = 0; i < kNumParameters; ++i) value[i] = ScalarPart(p[i]);
    const FoldPoint fold =
        SolveAmplitudeFold(kFirstOrderForm, value.data(), HzToRadPerSecond(41.5), kind);
    if (!fold.exists) return false;
    out[0] = LiftAmplitudeFold(kFirstOrderForm, p, HzToRadPerSecond(41.5), fold);
    return true;
  }
};

void ExpectDerivativesMatch(const ceres::CostFunction& cost) {
  ParameterVector p = kTruth;
  ceres::NumericDiffOptions numeric;
  numeric.ridders_relative_initial_step_size = 1e-4;
  const std::vector<const ceres::Manifold*>* euclidean = nullptr;
  ceres::GradientChecker checker(&cost, euclidean, numeric);
  ceres::GradientChecker::ProbeResults results;
  double* blocks[] = {p.data()};
  EXPECT_TRUE(checker.Probe(blocks, 1e-6, &results)) << results.error_log;
  EXPECT_GT(results.jacobians[0].norm(), 0.0);
}

TEST(FoldPoint, LiftedFoldDerivativesPassTheGradientChecker) {
  for (JumpKind kind : {JumpKind::kJumpUp, JumpKind::kJumpDown}) {
    ceres::AutoDiffCostFunction<FrequencyFoldOf, 1, kNumParameters> frequency(
        new FrequencyFoldOf{kind});
    ExpectDerivativesMatch(frequency);
    ceres::AutoDiffCostFunction<AmplitudeFoldOf, 1, kNumParameters> amplitude(
        new AmplitudeFoldOf{kind});
    ExpectDerivativesMatch(amplitude);
  }
}

}  // namespace
}  // namespace dwellfit
