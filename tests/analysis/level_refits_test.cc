#include "dwellfit/estimator/analysis/level_refits.h"

#include <cmath>
#include <string>
#include <vector>

#include "dwellfit/estimator/fit/identification.h"
#include "gtest/gtest.h"
#include "tests/fit_test_support.h"

namespace dwellfit {
namespace {

LevelRefit RefitWith(double eta_e, double alpha, double delta, bool usable) {
  LevelRefit refit;
  refit.parameters = kThesisTruth;
  refit.parameters[kEtaE] = eta_e;
  refit.parameters[kAlpha] = alpha;
  refit.parameters[kDelta] = delta;
  refit.effective_nonlinearity = EffectiveNonlinearity(refit.parameters, 100.0);
  refit.usable = usable;
  return refit;
}

// Three usable refits with eta_e 1, 2, 4 and one unusable (left out):
// mean 7/3, sum of squares 42/9, jackknife se sqrt(2/3 x 42/9) = 1.7638.
TEST(LevelRefits, SpreadIsTheRangeAndTheJackknifeStandardError) {
  const std::vector<LevelRefit> refits = {
      RefitWith(1.0, 10.0, 0.0, true), RefitWith(2.0, 10.0, 0.0, true),
      RefitWith(100.0, 99.0, 0.0, false), RefitWith(4.0, 13.0, 0.03, true)};
  std::array<bool, kNumParameters> fixed;
  fixed.fill(true);
  fixed[kEtaE] = false;
  fixed[kAlpha] = false;
  ParameterVector estimate = kThesisTruth;
  estimate[kEtaE] = 2.5;
  const std::vector<RefitSpread> spread = SpreadOverRefits(refits, fixed, estimate, 100.0);
  ASSERT_EQ(spread.size(), 3u);  // eta_e, alpha, alpha_e
  EXPECT_EQ(spread[0].name, "eta_e");
  EXPECT_EQ(spread[0].estimate, 2.5);
  EXPECT_EQ(spread[0].min, 1.0);
  EXPECT_EQ(spread[0].max, 4.0);
  EXPECT_NEAR(spread[0].jackknife_standard_error, std::sqrt(2.0 / 3.0 * 42.0 / 9.0), 1e-12);
  EXPECT_EQ(spread[1].name, "alpha");
  EXPECT_EQ(spread[1].max, 13.0);
  // alpha_e = alpha - (2/3) delta 100^2: 10, 10, 13 - 200 = -187.
  EXPECT_EQ(spread[2].name, "alpha_e");
  EXPECT_EQ(spread[2].index, kNumParameters);
  EXPECT_NEAR(spread[2].min, -187.0, 1e-9);
  EXPECT_NEAR(spread[2].max, 10.0, 1e-9);
  // Fewer than two usable refits: no spread.
  EXPECT_TRUE(SpreadOverRefits({refits[0], refits[2]}, fixed, estimate, 100.0).empty());
}

// Three simulated levels of the thesis case (its frequency and amplitude
// sweeps and a second frequency sweep at the same a_base, other noise; 1 %): every
// refit converges near the truth, the spread is that of the refits, and the
// result is the same on one and on two threads.
TEST(LevelRefits, ThreeSimulatedLevelsRefitNearTheTruthOnAnyThreadCount) {
  std::vector<Sweep> sweeps = SimulateDataset(kThesisTruth, 0.01, 11);
  std::vector<Sweep> second = SimulateDataset(kThesisTruth, 0.01, 12);
  for (Sweep& sweep : second) {
    if (sweep.kind != SweepKind::kFrequency) continue;
    sweep.id = "F2";
    sweeps.push_back(sweep);
  }
  const std::vector<const Sweep*> fitted = Pointers(sweeps);
  IdentificationOptions options;
  options.initial = ThesisStart(kThesisTruth);
  options.solve.solver.num_threads = 1;
  const IdentificationResult all = Identify(fitted, options);
  ASSERT_TRUE(all.converged) << all.message;
  const double omega_ref = kThesisTruth[kNaturalFrequency];
  const LevelRefits one = RefitLeavingOneLevelOut(fitted, options, all.parameters, omega_ref, 1);
  const LevelRefits two = RefitLeavingOneLevelOut(fitted, options, all.parameters, omega_ref, 2);
  ASSERT_TRUE(one.computed) << one.message;
  ASSERT_EQ(one.levels, (std::vector<std::string>{"F", "A", "F2"}));
  ASSERT_EQ(one.refits.size(), 3u);
  EXPECT_EQ(one.usable, 3);
  for (std::size_t i = 0; i < one.refits.size(); ++i) {
    const LevelRefit& refit = one.refits[i];
    EXPECT_EQ(refit.left_out, one.levels[i]);
    EXPECT_EQ(refit.status, FitStatus::kConverged) << refit.message;
    EXPECT_NEAR(refit.parameters[kNaturalFrequency], kThesisTruth[kNaturalFrequency],
                1e-3 * kThesisTruth[kNaturalFrequency]);
    EXPECT_NEAR(refit.parameters[kEtaE], kThesisTruth[kEtaE], 0.1 * kThesisTruth[kEtaE]);
    for (int j = 0; j < kNumParameters; ++j) {
      EXPECT_EQ(refit.parameters[j], two.refits[i].parameters[j]) << ParameterName(j);
    }
  }
  ASSERT_EQ(one.spread.size(), 7u);  // six free parameters and alpha_e
  for (const RefitSpread& s : one.spread) {
    EXPECT_TRUE(std::isfinite(s.jackknife_standard_error)) << s.name;
    EXPECT_GT(s.jackknife_standard_error, 0.0) << s.name;
    EXPECT_LE(s.min, s.max) << s.name;
    // With m = 3 the jackknife se is at most 2/3 of the range (two values at
    // one end, one at the other).
    EXPECT_LE(s.jackknife_standard_error, (2.0 / 3.0 + 1e-12) * (s.max - s.min)) << s.name;
  }
  EXPECT_EQ(one.spread[0].estimate, all.parameters[kEtaE]);
  // Two levels: no refits, and the message says why.
  const std::vector<const Sweep*> two_levels(fitted.begin(), fitted.begin() + 4);
  const LevelRefits none =
      RefitLeavingOneLevelOut(two_levels, options, all.parameters, omega_ref, 2);
  EXPECT_FALSE(none.computed);
  EXPECT_NE(none.message.find("2 levels fitted"), std::string::npos) << none.message;
}

}  // namespace
}  // namespace dwellfit
