// How a staged solve ends: the Duffing form of the measured beam reaches
// its minimum from starts where the algebraic stage or the start itself has
// no enforced fold (a fold stage, and the better of a stage's start and
// end), and a fit that ends without an enforced fold is a failure that names
// it, never "converged".
#include <cmath>
#include <string>
#include <vector>

#include "dwellfit/config/identify_config.h"
#include "dwellfit/estimator/fit/identification.h"
#include "dwellfit/estimator/run/resolved_run.h"
#include "dwellfit/residuals/functors/fold_condition_residual.h"
#include "dwellfit/residuals/model/fold_point.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"

namespace dwellfit {
namespace {

using ::testing::HasSubstr;

const std::string kBeamConfig =
    std::string(DWELLFIT_SOURCE_DIR) + "/datasets/clamped-beam-27C/beam.yaml";

// The beam's config with delta and mu2 fixed at 0 (the classic Duffing
// form): `fixed` and `initial_guess` (left out: from the data) as given.
ResolvedRun DuffingRun(const std::string& fixed, const std::string& initial_guess,
                       const std::string& stages = "[algebraic, vertical]") {
  return ResolveRun(LoadIdentifyConfig(kBeamConfig, {{"fixed", fixed, "test"},
                                                     {"initial_guess", initial_guess, "test"},
                                                     {"stages", stages, "test"}}));
}

// The minimum the vertical stage alone reaches from the automatic start.
constexpr double kDuffingMinimum = 620.66;

TEST(FitStatus, DuffingBeamFromTheAutomaticStartReachesItsMinimum) {
  const IdentificationResult fit = FitRun(DuffingRun("[delta, mu2]", "{delta: 0, mu2: 0}")).best;
  EXPECT_EQ(fit.status, FitStatus::kConverged) << fit.message;
  EXPECT_NEAR(fit.final_cost, kDuffingMinimum, 0.01 * kDuffingMinimum);
}

// From a start with so much damping that no fold exists, the vertical stage
// alone used to end at a cost of 3e33, "converged". Neither the start nor
// the algebraic start stage's end has the enforced folds, so a fold stage
// follows the start stage.
TEST(FitStatus, DuffingBeamFromAStartWithoutFoldsRunsAFoldStage) {
  const IdentificationResult fit =
      FitRun(DuffingRun("[delta, mu2]",
                        "{eta_e: 15, mu1: 30, mu2: 0, delta: 0, alpha: 7.85e11, omega_hz: 156}",
                        "[vertical]"))
          .best;
  ASSERT_GE(fit.stages.size(), 3u);
  EXPECT_TRUE(fit.stages[0].start_stage);
  EXPECT_TRUE(fit.stages[1].fold_stage);
  EXPECT_THAT(fit.stages[1].note, HasSubstr("L0.060g/up: no jump_down fold"));
  EXPECT_THAT(fit.stages[2].note, HasSubstr("where the fold stage ended"));
  EXPECT_EQ(fit.status, FitStatus::kConverged) << fit.message;
  EXPECT_NEAR(fit.final_cost, kDuffingMinimum, 0.01 * kDuffingMinimum);
}

// The numerical case with mu1 held at 25 times its value: the damping leaves
// the frequency sweep no jump, so the fit fails and says which fold.
TEST(FitStatus, AFitWithoutItsEnforcedFoldIsAFailureNamingIt) {
  const IdentifyConfig config =
      LoadIdentifyConfig(std::string(DWELLFIT_SOURCE_DIR) + "/datasets/thesis-numerical/beam.yaml",
                         {{"fixed", "[omega, mu1]", "test"},
                          {"initial_guess.mu1", "5", "test"},
                          {"penalties.bifurcation_range.enabled", "true", "test"}});
  const IdentificationResult fit = FitRun(ResolveRun(config)).best;
  EXPECT_EQ(fit.status, FitStatus::kFailure);
  EXPECT_FALSE(fit.converged);
  EXPECT_FALSE(fit.IsSolutionUsable());
  EXPECT_THAT(fit.message, HasSubstr("without the enforced fold(s) F0.01/up: no jump_down fold"));
  EXPECT_FALSE(fit.stages.back().missing_folds.empty());
}

// The fold conditions vanish at the model's own fold: the (a, Omega) where
// the upper branch of the thesis truth ends at a_base 0.01.
TEST(FoldConditionResidual, VanishesAtTheModelsFold) {
  const ParameterVector truth = {100.0, 0.2, 300.0, 1e4, 9e8, 2.0 * kPi * 40.0};
  const double a_base = 0.01;
  const FoldPoint fold = SolveFrequencyFold(kFirstOrderForm, truth.data(), a_base,
                                            JumpKind::kJumpDown, 2.0 * kPi * 42.25, 0.1);
  ASSERT_TRUE(fold.exists);
  const FoldConditionResidual at_fold(kFirstOrderForm, fold.control, a_base, fold.a, 1.0);
  double residual[2];
  ASSERT_TRUE(at_fold(truth.data(), residual));
  EXPECT_NEAR(residual[0], 0.0, 1e-9);
  EXPECT_NEAR(residual[1], 0.0, 1e-9);
  // A tenth lower in amplitude the turning point is missed.
  const FoldConditionResidual below(kFirstOrderForm, fold.control, a_base, 0.9 * fold.a, 1.0);
  ASSERT_TRUE(below(truth.data(), residual));
  EXPECT_GT(std::abs(residual[1]), 1e-3);
}

}  // namespace
}  // namespace dwellfit
