// ResolveRun and FitRun, the one path from a config to a fit: the data
// labelled, overridden and selected, the start found where the config
// leaves it to the data, and bad settings reported naming the field.
#include "dwellfit/estimator/run/resolved_run.h"

#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include "dwellfit/config/config_override.h"
#include "dwellfit/config/dwell_plan_reader.h"
#include "dwellfit/config/identify_config.h"
#include "dwellfit/estimator/common/input_error.h"
#include "dwellfit/estimator/data/jump_detection.h"
#include "dwellfit/estimator/fit/initial_guess.h"
#include "dwellfit/estimator/simulation/dwell_simulator.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "tests/config_test_support.h"

namespace dwellfit {
namespace {

using ::testing::AllOf;
using ::testing::Contains;
using ::testing::EndsWith;
using ::testing::HasSubstr;
using ::testing::StartsWith;

const std::string kDataset = std::string(DWELLFIT_SOURCE_DIR) + "/datasets/thesis-numerical";
const std::string kConfig = kDataset + "/beam.yaml";
const ParameterVector kTruth = {100.0, 0.2, 300.0, 1e4, 9e8, HzToRadPerSecond(40.0)};

std::vector<Sweep> SimulatedPlan() {
  return SimulateDwells(ReadDwellPlan(kDataset + "/plan.yaml"));
}

TEST(ResolveRun, GivenGuessesAreTheStartAndNoAutomaticStartIsSought) {
  const IdentifyConfig config = LoadIdentifyConfig(kConfig);
  const ResolvedRun run = ResolveRun(config);
  EXPECT_EQ(run.options.initial, config.identification.initial);
  EXPECT_FALSE(run.guessed_from_data);
  EXPECT_TRUE(run.initial_guess_steps.empty());
  EXPECT_FALSE(run.automatic_start.has_value());
  EXPECT_TRUE(run.automatic_start_steps.empty());
  ASSERT_EQ(run.fitted.size(), 4u);
  ASSERT_EQ(run.validation.size(), 4u);
  EXPECT_EQ(run.fitted[0]->Name(), "F0.01/up");
  EXPECT_THAT(DescribeJumps(*run.fitted[0]),
              StartsWith("F0.01/up: jump_down between 42.20 and 42.30 Hz"));
}

TEST(ResolveRun, GuessesLeftToTheDataAreFoundFromTheFittedSweepsAndTheGivenOnesKept) {
  const IdentifyConfig config = LoadIdentifyConfig(
      kConfig,
      {{"initial_guess.mu1", "auto", "--test"}, {"initial_guess.alpha", "auto", "--test"}});
  const ResolvedRun run = ResolveRun(config);
  ASSERT_TRUE(run.guessed_from_data);
  EXPECT_FALSE(run.automatic_start.has_value());  // one start
  const ParameterVector automatic = AutomaticInitialGuess(run.fitted, config.initial_guess).guess;
  for (int i = 0; i < kNumParameters; ++i) {
    const bool found = i == kMu1 || i == kAlpha;
    EXPECT_EQ(run.options.initial[i], found ? automatic[i] : config.identification.initial[i])
        << ParameterName(i);
  }
  // Found from the data, not the placeholders (mu1 = alpha = 0): within a
  // factor two of the truth.
  EXPECT_GT(run.options.initial[kMu1], 0.5 * kTruth[kMu1]);
  EXPECT_LT(run.options.initial[kMu1], 2.0 * kTruth[kMu1]);
  EXPECT_GT(run.options.initial[kAlpha], 0.5 * kTruth[kAlpha]);
  EXPECT_LT(run.options.initial[kAlpha], 2.0 * kTruth[kAlpha]);
  EXPECT_THAT(run.initial_guess_steps, Contains(StartsWith("mu1 = ")));
  EXPECT_THAT(run.initial_guess_steps, Contains("eta_e = 130: given"));
}

// Sweeps already in memory take the same path as the data file: the plan
// the file was simulated from resolves to the same labels and start.
TEST(ResolveRun, SimulatedSweepsAreLabelledSelectedAndStartedAsTheDataFile) {
  const IdentifyConfig config =
      LoadIdentifyConfig(kConfig, {{"initial_guess", "auto", "--test"}, {"fixed", "[]", "--test"}});
  const ResolvedRun from_file = ResolveRun(config);
  const ResolvedRun simulated = ResolveRun(config, SimulatedPlan());
  ASSERT_EQ(simulated.fitted.size(), from_file.fitted.size());
  for (size_t i = 0; i < from_file.fitted.size(); ++i) {
    EXPECT_EQ(DescribeJumps(*simulated.fitted[i]), DescribeJumps(*from_file.fitted[i]));
  }
  ASSERT_EQ(simulated.validation.size(), from_file.validation.size());
  for (int i = 0; i < kNumParameters; ++i) {
    EXPECT_NEAR(simulated.options.initial[i], from_file.options.initial[i],
                1e-6 * std::abs(from_file.options.initial[i]))
        << ParameterName(i);
  }
}

TEST(ResolveRun, TheConfigsJumpsReplaceDetectionOnSimulatedSweeps) {
  const IdentifyConfig config =
      LoadIdentifyConfig(kConfig, ParseSetFlag("jumps=[{sweep: F0.01/down, none: true}]", "--set"));
  const ResolvedRun run = ResolveRun(config, SimulatedPlan());
  for (const Sweep* sweep : run.fitted) {
    EXPECT_EQ(sweep->jumps_from_config, sweep->Name() == "F0.01/down") << sweep->Name();
  }
  EXPECT_THAT(DescribeJumps(*run.fitted[1]),
              AllOf(StartsWith("F0.01/down: no jump"), EndsWith("[config]")));
}

TEST(ResolveRun, NoResonanceToStartFromIsAnInputErrorNamingTheInitialGuess) {
  // The amplitude sweep's up direction below its jump: lower branch only.
  std::vector<Sweep> sweeps = SimulatedPlan();
  for (Sweep& sweep : sweeps) {
    if (sweep.Name() == "A41.5/up") sweep.points.resize(30);  // a_base up to 0.031
  }
  const IdentifyConfig config = LoadIdentifyConfig(kConfig, {{"initial_guess", "auto", "--test"},
                                                             {"fixed", "[]", "--test"},
                                                             {"fit", "[A41.5/up]", "--test"}});
  const InputError error = ErrorOf([&] { ResolveRun(config, std::move(sweeps)); });
  EXPECT_EQ(error.file(), config.config_path);
  EXPECT_EQ(error.field(), "initial_guess");
  EXPECT_THAT(error.what(), HasSubstr("cannot find a starting point from the data"));
  EXPECT_THAT(error.what(), HasSubstr("give the initial guesses in the config"));
}

// LoadIdentifyConfig checks every settings block at its line. A config built
// or changed in code is checked where each block enters the library, once:
// the jump detection by ResolveRun (an InputError naming the field), the
// fit's options by the fit (a run ending in kInvalidInput, its message
// naming the field).
TEST(ResolveRun, InvalidJumpDetectionBuiltInCodeIsAnInputErrorNamingTheField) {
  IdentifyConfig config = LoadIdentifyConfig(kConfig);
  config.jump_detection.min_ratio = 1.0;
  const InputError error = ErrorOf([&] { ResolveRun(config); });
  EXPECT_EQ(error.file(), config.config_path);
  EXPECT_EQ(error.field(), "jump_detection");
}

TEST(FitRun, InvalidFitOptionsBuiltInCodeEndInvalidInputNamingTheField) {
  const IdentifyConfig loaded = LoadIdentifyConfig(kConfig);
  IdentifyConfig solver = loaded;
  solver.identification.solve.solver.max_iterations = 0;
  IdentifyConfig multi_start = loaded;
  multi_start.multi_start.starts = 0;
  IdentifyConfig start = loaded;
  start.identification.initial[kEtaE] = 0.0;
  for (const auto& [config, field] : {std::pair{&solver, "solver.max_iterations"},
                                      {&multi_start, "multi_start.starts"},
                                      {&start, "initial.eta_e"}}) {
    const MultiStartResult fit = FitRun(ResolveRun(*config));
    EXPECT_EQ(fit.best.status, FitStatus::kInvalidInput) << field;
    EXPECT_THAT(fit.best.message, HasSubstr(field));
  }
}

// A parameter held fixed keeps its initial value, so that value must be
// given: held at a rough estimate from the data it would bias the others.
TEST(ResolveRun, AFixedParameterWithoutAGivenGuessIsAnInputError) {
  // LoadIdentifyConfig rejects such a file at its `fixed` line; a config
  // built in code reaches ResolveRun.
  IdentifyConfig config = LoadIdentifyConfig(kConfig);
  config.initial_guess[kNaturalFrequency].reset();
  ASSERT_TRUE(config.identification.fixed[kNaturalFrequency]);
  const InputError error = ErrorOf([&] { ResolveRun(config); });
  EXPECT_EQ(error.file(), config.config_path);
  EXPECT_EQ(error.field(), "fixed");
  EXPECT_THAT(error.what(), HasSubstr("omega is held fixed but its initial guess is left to the "
                                      "data (auto); give initial_guess.omega_hz, or remove it "
                                      "from 'fixed'"));
}

// With more than one start the automatic start, every free parameter found
// from the data, is sought even when every guess is given; FitRun fits from
// it as the second start.
TEST(FitRun, AMultiStartFitsFromTheGivenAndTheAutomaticStart) {
  const IdentifyConfig config =
      LoadIdentifyConfig(kConfig, {{"multi_start.starts", "3", "--test"}});
  const ResolvedRun run = ResolveRun(config);
  EXPECT_FALSE(run.guessed_from_data);
  EXPECT_EQ(run.options.initial, config.identification.initial);
  KnownParameters omega;  // the config fixes omega
  omega[kNaturalFrequency] = config.initial_guess[kNaturalFrequency];
  const InitialGuessReport automatic = AutomaticInitialGuess(run.fitted, omega);
  ASSERT_TRUE(run.automatic_start.has_value());
  EXPECT_EQ(*run.automatic_start, automatic.guess);
  EXPECT_EQ(run.automatic_start_steps, automatic.steps);
  EXPECT_NE(automatic.guess, config.identification.initial);

  const MultiStartResult fit = FitRun(run);
  ASSERT_EQ(fit.starts.size(), 3u);
  EXPECT_EQ(fit.starts[0], config.identification.initial);
  EXPECT_EQ(fit.starts[1], automatic.guess);
  EXPECT_EQ(fit.reached_best, 3);
  for (int i = 0; i < kNumParameters; ++i) {
    EXPECT_NEAR(fit.best.parameters[i] / kTruth[i], 1.0, 1e-6) << ParameterName(i);
  }
}

}  // namespace
}  // namespace dwellfit
