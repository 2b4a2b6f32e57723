// The automatic starting point (estimator/fit/initial_guess.h) on the chapter's
// numerical case, its 1 % noise replica and the real clamped-beam data, and
// the identification run from it.
#include "dwellfit/estimator/fit/initial_guess.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <set>
#include <string>
#include <vector>

#include "dwellfit/config/dwell_plan_reader.h"
#include "dwellfit/estimator/analysis/sweep_prediction.h"
#include "dwellfit/estimator/common/input_error.h"
#include "dwellfit/estimator/data/jump_detection.h"
#include "dwellfit/estimator/data/sweep_csv.h"
#include "dwellfit/estimator/fit/identification.h"
#include "dwellfit/estimator/simulation/dwell_simulator.h"
#include "gtest/gtest.h"

namespace dwellfit {
namespace {

const std::string kThesis = std::string(DWELLFIT_SOURCE_DIR) + "/datasets/thesis-numerical";
const ParameterVector kTruth = {100.0, 0.2, 300.0, 1e4, 9e8, HzToRadPerSecond(40.0)};
// alpha_e is reported at the amplitude sweep's frequency (beam.yaml).
const double kOmegaRef = HzToRadPerSecond(41.5);

// Loaded sweeps with jumps detected and branches labelled, as for measured data.
std::vector<Sweep> Labelled(std::vector<Sweep> sweeps) {
  DetectJumps(JumpDetectionOptions{}, &sweeps);
  return sweeps;
}

std::vector<const Sweep*> Select(const std::vector<Sweep>& sweeps,
                                 const std::set<std::string>& ids) {
  std::vector<const Sweep*> selected;
  for (const Sweep& sweep : sweeps) {
    if (ids.count(sweep.id) > 0) selected.push_back(&sweep);
  }
  return selected;
}

KnownParameters OmegaKnown() {
  KnownParameters known;
  known[kNaturalFrequency] = kTruth[kNaturalFrequency];
  return known;
}

void Print(const std::string& title, const InitialGuessReport& report) {
  std::printf("%s\n", title.c_str());
  for (const std::string& step : report.steps) std::printf("  %s\n", step.c_str());
}

void PrintParameters(const std::string& title, const ParameterVector& p, double omega_ref) {
  std::printf(
      "%s: eta_e %.6g mu1 %.6g mu2 %.6g delta %.6g alpha %.6g omega %.6g rad/s (%.4f Hz) "
      "alpha_e(%.2f Hz) %.6g\n",
      title.c_str(), p[kEtaE], p[kMu1], p[kMu2], p[kDelta], p[kAlpha], p[kNaturalFrequency],
      RadPerSecondToHz(p[kNaturalFrequency]), RadPerSecondToHz(omega_ref),
      EffectiveNonlinearity(p, omega_ref));
}

// eta_e, mu1, mu2 and alpha_e within a factor 2 of the truth, omega within 2 %.
void ExpectWithinFactorTwo(const ParameterVector& guess, const std::string& context) {
  for (int i : {kEtaE, kMu1, kMu2}) {
    const double ratio = guess[i] / kTruth[i];
    EXPECT_GT(ratio, 0.5) << ParameterName(i) << " " << context;
    EXPECT_LT(ratio, 2.0) << ParameterName(i) << " " << context;
  }
  const double alpha_e_ratio =
      EffectiveNonlinearity(guess, kOmegaRef) / EffectiveNonlinearity(kTruth, kOmegaRef);
  EXPECT_GT(alpha_e_ratio, 0.5) << "alpha_e " << context;
  EXPECT_LT(alpha_e_ratio, 2.0) << "alpha_e " << context;
  EXPECT_NEAR(guess[kNaturalFrequency] / kTruth[kNaturalFrequency], 1.0, 0.02)
      << "omega " << context;
}

class InitialGuessThesis : public ::testing::Test {
 protected:
  void SetUp() override {
    sweeps_ = Labelled(LoadSweepsCsv(kThesis + "/sweeps.csv").sweeps);
    fitted_ = Select(sweeps_, {"F0.01", "A41.5"});
    ASSERT_EQ(fitted_.size(), 4u);
  }
  std::vector<Sweep> sweeps_;
  std::vector<const Sweep*> fitted_;
};

TEST_F(InitialGuessThesis, NoiseFreeGuessIsWithinAFactorTwoWithOmegaKnownAndUnknown) {
  const InitialGuessReport with_omega = AutomaticInitialGuess(fitted_, OmegaKnown());
  Print("thesis noise-free, omega known", with_omega);
  PrintParameters("guess", with_omega.guess, kOmegaRef);
  EXPECT_EQ(with_omega.guess[kNaturalFrequency], kTruth[kNaturalFrequency]);
  ExpectWithinFactorTwo(with_omega.guess, "omega known");

  const InitialGuessReport without = AutomaticInitialGuess(fitted_, KnownParameters{});
  Print("thesis noise-free, omega unknown", without);
  PrintParameters("guess", without.guess, kOmegaRef);
  ExpectWithinFactorTwo(without.guess, "omega unknown");
}

TEST_F(InitialGuessThesis, GuessDoesNotDependOnTheAmplitudeUnit) {
  // The same sweeps with the amplitude a in a unit 1e9 times larger (a of
  // 1e-13..5e-12, as in metres for a small vibration) and 1e9 times smaller:
  // a parameter of unit length^k scales by s^k (eta_e: length per a_base).
  const InitialGuessReport reference = AutomaticInitialGuess(fitted_, KnownParameters{});
  for (double s : {1e-9, 1e9}) {
    std::vector<Sweep> scaled = sweeps_;
    for (Sweep& sweep : scaled) {
      for (DwellPoint& point : sweep.points) point.amplitude *= s;
    }
    const InitialGuessReport guess =
        AutomaticInitialGuess(Select(scaled, {"F0.01", "A41.5"}), KnownParameters{});
    const ParameterVector expected = {
        reference.guess[kEtaE] * s,        reference.guess[kMu1],
        reference.guess[kMu2] / s,         reference.guess[kDelta] / (s * s),
        reference.guess[kAlpha] / (s * s), reference.guess[kNaturalFrequency]};
    for (int i = 0; i < kNumParameters; ++i) {
      EXPECT_NEAR(guess.guess[i], expected[i], 1e-6 * std::abs(expected[i]))
          << ParameterName(i) << " at unit scale " << s;
    }
  }
}

TEST_F(InitialGuessThesis, IdentifyFromTheGuessReachesTheTruth) {
  for (bool omega_known : {true, false}) {
    const InitialGuessReport report =
        AutomaticInitialGuess(fitted_, omega_known ? OmegaKnown() : KnownParameters{});
    IdentificationOptions options;  // default stages: algebraic, then vertical
    options.initial = report.guess;
    options.fixed[kNaturalFrequency] = omega_known;
    const IdentificationResult result = Identify(fitted_, options);
    PrintParameters(omega_known ? "identified from the guess, omega fixed"
                                : "identified from the guess, omega free",
                    result.parameters, kOmegaRef);
    std::printf("  final cost %.3g, %d iterations\n", result.final_cost, result.iterations);
    EXPECT_TRUE(result.converged);
    for (int i = 0; i < kNumParameters; ++i) {
      EXPECT_NEAR(result.parameters[i] / kTruth[i], 1.0, 1e-6)
          << ParameterName(i) << (omega_known ? " (omega fixed)" : " (omega free)");
    }
  }
}

// The damping at amplitude a, mu1 + c mu2 a [1/s]: what peak heights fix.
double DampingAt(const ParameterVector& p, double a) {
  return p[kMu1] + 4.0 / (3.0 * kPi) * p[kMu2] * a;
}

TEST_F(InitialGuessThesis, OneFrequencySweepAloneGivesOmegaEtaAndThePeakDamping) {
  // One level: w and eta_e come together from the off-resonance dwells, and
  // only mu1 + c mu2 a_peak is fixed (split evenly, as `steps` says).
  const InitialGuessReport report = AutomaticInitialGuess(Select(sweeps_, {"F0.01"}), {});
  Print("F0.01 alone, omega unknown", report);
  PrintParameters("guess", report.guess, kOmegaRef);
  const ParameterVector& guess = report.guess;
  EXPECT_NEAR(guess[kNaturalFrequency] / kTruth[kNaturalFrequency], 1.0, 0.002);
  EXPECT_NEAR(guess[kEtaE] / kTruth[kEtaE], 1.0, 0.01);
  EXPECT_NEAR(EffectiveNonlinearity(guess, kOmegaRef) / EffectiveNonlinearity(kTruth, kOmegaRef),
              1.0, 0.1);
  const double a_peak = 4.707e-3;
  EXPECT_NEAR(DampingAt(guess, a_peak) / DampingAt(kTruth, a_peak), 1.0, 0.02);
  bool said_not_separable = false;
  for (const std::string& step : report.steps) {
    said_not_separable |=
        step.rfind("mu2 = ", 0) == 0 && step.find("not separable") != std::string::npos;
  }
  EXPECT_TRUE(said_not_separable);
}

TEST_F(InitialGuessThesis, KnownParametersAreKeptAndUsed) {
  KnownParameters known = OmegaKnown();
  known[kEtaE] = 100.0;
  known[kMu1] = 0.2;
  known[kDelta] = 1e4;
  const InitialGuessReport report = AutomaticInitialGuess(fitted_, known);
  Print("eta_e, mu1, delta, omega given", report);
  for (int i : {kEtaE, kMu1, kDelta, kNaturalFrequency}) {
    EXPECT_EQ(report.guess[i], *known[i]) << ParameterName(i);
  }
  // With delta given, the backbone's slope is alpha itself (not alpha_e), and
  // mu2 follows from the peak heights with mu1 / eta_e held.
  EXPECT_NEAR(report.guess[kAlpha] / kTruth[kAlpha], 1.0, 0.1);
  EXPECT_NEAR(report.guess[kMu2] / kTruth[kMu2], 1.0, 0.1);
  // One line per parameter, each saying how its value was obtained.
  for (int i = 0; i < kNumParameters; ++i) {
    const std::string prefix = std::string(ParameterName(i)) + " = ";
    int lines = 0;
    for (const std::string& step : report.steps) lines += step.rfind(prefix, 0) == 0 ? 1 : 0;
    EXPECT_EQ(lines, 1) << ParameterName(i);
  }
  EXPECT_NE(std::find(report.steps.begin(), report.steps.end(), "eta_e = 100: given"),
            report.steps.end());
}

TEST_F(InitialGuessThesis, SweepsWithoutResonanceAreAnInputError) {
  // The amplitude sweep's up direction below its jump: lower branch only.
  Sweep lower = *Select(sweeps_, {"A41.5"}).front();
  ASSERT_EQ(lower.direction, SweepDirection::kUp);
  lower.points.resize(30);  // a_base 0.002 .. 0.031, below the jump up at 0.0354
  DetectJumps(JumpDetectionOptions{}, &lower);
  EXPECT_THROW(AutomaticInitialGuess({&lower}, {}), InputError);
}

TEST(InitialGuess, OnePercentNoiseReplicaStaysWithinAFactorTwo) {
  DwellPlan plan = ReadDwellPlan(kThesis + "/plan.yaml");
  plan.noise.relative_sigma = 0.01;
  plan.noise.seed = 20261121;  // the replica of tests/fit/thesis_numerical_test.cc
  {
    const std::vector<Sweep> noisy = Labelled(SimulateDwells(plan));
    const std::vector<const Sweep*> fitted = Select(noisy, {"F0.01", "A41.5"});
    ASSERT_EQ(fitted.size(), 4u);
    const InitialGuessReport with_omega = AutomaticInitialGuess(fitted, OmegaKnown());
    PrintParameters("1% noise, omega known", with_omega.guess, kOmegaRef);
    ExpectWithinFactorTwo(with_omega.guess, "1% noise, omega known");
    const InitialGuessReport without = AutomaticInitialGuess(fitted, {});
    PrintParameters("1% noise, omega unknown", without.guess, kOmegaRef);
    ExpectWithinFactorTwo(without.guess, "1% noise, omega unknown");
  }
  // Over other noise draws, eta_e, alpha_e, omega and the damping at the peak
  // amplitude stay close. How that damping splits into mu1 and mu2 rests on
  // two peak heights 23 % apart in amplitude and is not robust at 1 % noise
  // (neither is the full fit's split), so it is not checked here.
  const double a_peak = 4.707e-3;
  for (int seed = 1; seed <= 20; ++seed) {
    plan.noise.seed = seed;
    const std::vector<Sweep> noisy = Labelled(SimulateDwells(plan));
    const std::vector<const Sweep*> fitted = Select(noisy, {"F0.01", "A41.5"});
    for (bool omega_known : {true, false}) {
      const ParameterVector guess =
          AutomaticInitialGuess(fitted, omega_known ? OmegaKnown() : KnownParameters{}).guess;
      const std::string context =
          "seed " + std::to_string(seed) + (omega_known ? ", omega known" : ", omega unknown");
      EXPECT_NEAR(guess[kEtaE] / kTruth[kEtaE], 1.0, 0.2) << context;
      EXPECT_NEAR(
          EffectiveNonlinearity(guess, kOmegaRef) / EffectiveNonlinearity(kTruth, kOmegaRef), 1.0,
          0.4)
          << context;
      EXPECT_NEAR(guess[kNaturalFrequency] / kTruth[kNaturalFrequency], 1.0, 0.02) << context;
      EXPECT_NEAR(DampingAt(guess, a_peak) / DampingAt(kTruth, a_peak), 1.0, 0.2) << context;
    }
  }
}

TEST(InitialGuess, SofteningModeFromOneFrequencySweep) {
  // The thesis plan with a softening cubic: the up sweep jumps up and the down
  // sweep jumps down; the signs of Q follow.
  DwellPlan plan = ReadDwellPlan(kThesis + "/plan.yaml");
  plan.truth = {100.0, 0.2, 300.0, 0.0, -4.5e8, HzToRadPerSecond(40.0)};
  plan.sweeps.resize(1);  // F0.01
  plan.sweeps[0].from = 34.0;
  plan.sweeps[0].to = 42.0;
  const std::vector<Sweep> sweeps = Labelled(SimulateDwells(plan));
  ASSERT_EQ(sweeps.size(), 2u);
  ASSERT_EQ(sweeps[0].jumps.size(), 1u);
  ASSERT_EQ(sweeps[0].jumps[0].kind, JumpKind::kJumpUp);
  const InitialGuessReport report = AutomaticInitialGuess({&sweeps[0], &sweeps[1]}, {});
  PrintParameters("softening, F alone", report.guess, plan.truth[kNaturalFrequency]);
  EXPECT_NEAR(report.guess[kNaturalFrequency] / plan.truth[kNaturalFrequency], 1.0, 0.002);
  EXPECT_NEAR(report.guess[kEtaE] / plan.truth[kEtaE], 1.0, 0.02);
  EXPECT_NEAR(report.guess[kAlpha] / plan.truth[kAlpha], 1.0, 0.1);
  const double a_peak = 5.043e-3;
  EXPECT_NEAR(DampingAt(report.guess, a_peak) / DampingAt(plan.truth, a_peak), 1.0, 0.02);
}

// The real clamped-clamped beam, bundled in datasets/clamped-beam-27C.
const std::string kClampedBeamCsv =
    std::string(DWELLFIT_SOURCE_DIR) + "/datasets/clamped-beam-27C/sweeps.csv";

TEST(InitialGuess, ClampedBeamGuessIsPlausibleAndTheFitConvergesFromIt) {
  const std::vector<Sweep> sweeps = Labelled(LoadSweepsCsv(kClampedBeamCsv).sweeps);
  const std::vector<const Sweep*> fitted = Select(sweeps, {"L0.060g", "L0.080g"});
  ASSERT_EQ(fitted.size(), 4u);
  KnownParameters known;
  known[kDelta] = 0.0;
  const InitialGuessReport report = AutomaticInitialGuess(fitted, known);
  Print("clamped beam, L0.060g and L0.080g up and down, delta = 0", report);
  const ParameterVector& guess = report.guess;
  PrintParameters("guess", guess, guess[kNaturalFrequency]);
  // The README: linear natural frequency near 156 Hz; hardening.
  EXPECT_NEAR(guess[kNaturalFrequency] / HzToRadPerSecond(156.0), 1.0, 0.03);
  for (int i : {kEtaE, kMu1, kMu2, kAlpha}) EXPECT_GT(guess[i], 0.0) << ParameterName(i);

  IdentificationOptions options;
  options.initial = guess;
  options.fixed[kDelta] = true;
  const IdentificationResult result = Identify(fitted, options);
  PrintParameters("identified from the guess (omega free, delta fixed at 0)", result.parameters,
                  guess[kNaturalFrequency]);
  for (const StageSummary& stage : result.stages) {
    std::printf("  %s stage: cost %.4g -> %.4g, %d iterations\n", ResidualKindName(stage.residual),
                stage.initial_cost, stage.final_cost, stage.iterations);
  }
  std::printf("  final cost %.4g over %d dwells\n", result.final_cost, result.residual_blocks);
  for (const Sweep* sweep : fitted) {
    for (const auto& [name, p] :
         {std::pair<const char*, ParameterVector>{"guess", guess}, {"fit", result.parameters}}) {
      const SweepPrediction prediction = PredictSweep(kFirstOrderForm, p, *sweep, true);
      double peak = 0.0;
      for (const StableRoot& root : prediction.model) peak = std::max(peak, root.a);
      std::printf(
          "  %s %s: rms error %.3g m (relative %.3g), %d points off branch, model peak %.3g\n",
          sweep->Name().c_str(), name, prediction.rms_error, prediction.relative_rms_error,
          prediction.points_off_branch, peak);
    }
  }
  EXPECT_TRUE(result.converged);
  EXPECT_LT(result.stages.back().final_cost, result.stages.back().initial_cost);
  for (int i : {kEtaE, kAlpha, kNaturalFrequency}) {
    EXPECT_GT(result.parameters[i], 0.0) << ParameterName(i);
  }
  // Without the bifurcation-range penalty the damping may move wholly into
  // the quadratic term (mu1 on its bound 0, the chapter's damping collapse);
  // the equivalent viscous damping at the measured peak amplitude stays
  // positive: mu1 + 4 mu2 a / (3 pi) > 0.
  double measured_peak = 0.0;
  for (const Sweep* sweep : fitted) {
    for (const DwellPoint& point : sweep->points) {
      measured_peak = std::max(measured_peak, point.amplitude);
    }
  }
  EXPECT_GT(result.parameters[kMu1] + 4.0 * result.parameters[kMu2] * measured_peak / (3.0 * kPi),
            0.1 * guess[kMu1]);
}

}  // namespace
}  // namespace dwellfit
