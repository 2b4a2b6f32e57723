// The `jumps:` list of the identify config (config/README.md) and its
// application to measured sweeps.
#include <sstream>
#include <string>
#include <vector>

#include "dwellfit/config/config_override.h"
#include "dwellfit/config/identify_config.h"
#include "dwellfit/estimator/common/input_error.h"
#include "dwellfit/estimator/data/jump_detection.h"
#include "dwellfit/estimator/run/identify_run.h"
#include "dwellfit/estimator/run/resolved_run.h"
#include "dwellfit/residuals/model/model_parameters.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "tests/config_test_support.h"

namespace dwellfit {
namespace {

using ::testing::HasSubstr;
using ::testing::IsEmpty;
using ::testing::StartsWith;

// kValidConfig (27 lines) with `extra` from line 28 on.
std::string ConfigWith(const std::string& extra) { return std::string(kValidConfig) + extra; }

constexpr char kJumps[] = R"(jumps:
  - sweep: L0.060g/down
    kind: jump_up
    between_hz: [161.041, 161.012]
  - sweep: A41.5/up
    kind: jump_up
    between_a_base: [0.035, 0.036]
  - sweep: L0.040g/down
    none: true
)";

TEST(ConfigJumps, EntriesLandInJumpOverridesWithHzAsRadPerSecond) {
  const ConfigDirectory dir;
  const IdentifyConfig config = LoadIdentifyConfig(dir.WriteConfig(ConfigWith(kJumps)));
  ASSERT_EQ(config.jump_overrides.size(), 3u);
  const JumpOverride& frequency = config.jump_overrides[0];
  EXPECT_EQ(frequency.sweep, "L0.060g/down");
  EXPECT_FALSE(frequency.none);
  EXPECT_EQ(frequency.kind, JumpKind::kJumpUp);
  EXPECT_EQ(frequency.control, SweepKind::kFrequency);
  EXPECT_EQ(frequency.control_before, HzToRadPerSecond(161.041));
  EXPECT_EQ(frequency.control_after, HzToRadPerSecond(161.012));
  EXPECT_EQ(frequency.line, 29);
  EXPECT_EQ(frequency.field, "jumps[0]");

  const JumpOverride& amplitude = config.jump_overrides[1];
  EXPECT_EQ(amplitude.control, SweepKind::kAmplitude);
  EXPECT_EQ(amplitude.control_before, 0.035);
  EXPECT_EQ(amplitude.control_after, 0.036);
  EXPECT_EQ(amplitude.line, 32);

  EXPECT_EQ(config.jump_overrides[2].sweep, "L0.040g/down");
  EXPECT_TRUE(config.jump_overrides[2].none);
  EXPECT_EQ(config.jump_overrides[2].field, "jumps[2]");

  // No key: no overrides.
  EXPECT_THAT(LoadIdentifyConfig(dir.WriteConfig(kValidConfig)).jump_overrides, IsEmpty());
}

TEST(ConfigJumps, EachEntryStatesExactlyOneOfBetweenHzBetweenABaseAndNone) {
  const ConfigDirectory dir;
  std::string path;
  InputError error = LoadError(
      dir, ConfigWith(Replace(kJumps, "    none: true", "    none: true\n    between_hz: [1, 2]")),
      &path);
  EXPECT_EQ(error.file(), path);
  EXPECT_EQ(error.line(), 36);
  EXPECT_EQ(error.field(), "jumps[2].none");
  EXPECT_THAT(error.what(), HasSubstr("give exactly one of between_hz, between_a_base and none "
                                      "(this entry also has 'between_hz')"));

  error = LoadError(dir, ConfigWith(Replace(kJumps, "    between_hz: [161.041, 161.012]\n", "")),
                    &path);
  EXPECT_EQ(error.line(), 29);
  EXPECT_EQ(error.field(), "jumps[0]");
  EXPECT_THAT(error.what(), HasSubstr("give exactly one of between_hz: [before, after] (frequency "
                                      "sweep), between_a_base: [before, after] (amplitude sweep) "
                                      "or none: true"));
}

TEST(ConfigJumps, ABracketOverflowingInRadPerSecondIsAnError) {
  const ConfigDirectory dir;
  std::string path;
  const InputError error = LoadError(
      dir, ConfigWith(Replace(kJumps, "[161.041, 161.012]", "[161.041, 1.7e308]")), &path);
  EXPECT_EQ(error.line(), 31);
  EXPECT_EQ(error.field(), "jumps[0].between_hz");
  EXPECT_THAT(error.what(), HasSubstr("the frequency 1.7e+308 Hz is too large"));
}

TEST(ConfigJumps, KindGoesWithABracketAndNoneMustBeTrue) {
  const ConfigDirectory dir;
  std::string path;
  InputError error = LoadError(
      dir, ConfigWith(Replace(kJumps, "    kind: jump_up\n    between_hz", "    between_hz")),
      &path);
  EXPECT_EQ(error.line(), 29);
  EXPECT_EQ(error.field(), "jumps[0].kind");
  EXPECT_THAT(error.what(), HasSubstr("missing required key 'kind' in 'jumps[0]'; give jump_up "
                                      "or jump_down"));

  error = LoadError(
      dir,
      ConfigWith(Replace(kJumps, "kind: jump_up\n    between_hz", "kind: jumpup\n    between_hz")),
      &path);
  EXPECT_EQ(error.line(), 30);
  EXPECT_THAT(error.what(), HasSubstr("unknown jump kind 'jumpup' (did you mean 'jump_up'?); "
                                      "allowed: jump_up, jump_down"));

  error = LoadError(dir, ConfigWith(Replace(kJumps, "none: true", "none: false")), &path);
  EXPECT_EQ(error.line(), 36);
  EXPECT_THAT(error.what(), HasSubstr("none: false states nothing"));

  error = LoadError(
      dir, ConfigWith(Replace(kJumps, "    none: true", "    none: true\n    kind: jump_up")),
      &path);
  EXPECT_EQ(error.line(), 37);
  EXPECT_THAT(error.what(), HasSubstr("a sweep with none: true has no jump, so no kind"));
}

TEST(ConfigJumps, SweepNamesOneDirectionOnce) {
  const ConfigDirectory dir;
  std::string path;
  InputError error =
      LoadError(dir, ConfigWith(Replace(kJumps, "sweep: L0.060g/down", "sweep: L0.060g")), &path);
  EXPECT_EQ(error.line(), 29);
  EXPECT_EQ(error.field(), "jumps[0].sweep");
  EXPECT_THAT(error.what(), HasSubstr("'L0.060g' names both directions; a jump belongs to one: "
                                      "write 'L0.060g/up' or 'L0.060g/down'"));

  error = LoadError(dir, ConfigWith(Replace(kJumps, "sweep: L0.040g/down", "sweep: L0.060g/down")),
                    &path);
  EXPECT_EQ(error.line(), 35);
  EXPECT_EQ(error.field(), "jumps[2]");
  EXPECT_THAT(error.what(),
              HasSubstr("sweep 'L0.060g/down' has a jump entry already (at line 29); keep one"));

  error = LoadError(dir, ConfigWith(Replace(kJumps, "sweep: L0.060g/down", "swep: L0.060g/down")),
                    &path);
  EXPECT_EQ(error.line(), 29);
  EXPECT_THAT(error.what(), HasSubstr("unknown key 'swep' in 'jumps[0]' (did you mean 'sweep'?); "
                                      "allowed: sweep, kind, between_hz, between_a_base, none"));
}

TEST(ConfigJumps, BracketIsTwoDifferentPositiveNumbers) {
  const ConfigDirectory dir;
  std::string path;
  InputError error = LoadError(
      dir, ConfigWith(Replace(kJumps, "[161.041, 161.012]", "[161.07, 161.041, 161.012]")), &path);
  EXPECT_EQ(error.line(), 31);
  EXPECT_EQ(error.field(), "jumps[0].between_hz");
  EXPECT_THAT(error.what(), HasSubstr("expected two values, [before, after] in measurement "
                                      "order, got 3"));
  error = LoadError(dir, ConfigWith(Replace(kJumps, "[161.041, 161.012]", "161.041")), &path);
  EXPECT_THAT(error.what(), HasSubstr("got 1"));
  error = LoadError(dir, ConfigWith(Replace(kJumps, "[161.041, 161.012]", "[161.041, 161.041]")),
                    &path);
  EXPECT_THAT(error.what(), HasSubstr("the bracket's two values are equal"));
  error = LoadError(dir, ConfigWith(Replace(kJumps, "[0.035, 0.036]", "[-0.035, 0.036]")), &path);
  EXPECT_EQ(error.line(), 34);
  EXPECT_THAT(error.what(), HasSubstr("the bracket's values must be positive"));
  error =
      LoadError(dir, ConfigWith(Replace(kJumps, "[161.041, 161.012]", "[161.041, high]")), &path);
  EXPECT_THAT(error.what(), HasSubstr("expected a number"));
  error = LoadError(dir, ConfigWith("jumps:\n  sweep: L0.060g/down\n"), &path);
  EXPECT_EQ(error.line(), 28);
  EXPECT_THAT(error.what(), HasSubstr("expected a list such as [a, b]"));
}

TEST(ConfigJumps, PrintedConfigRoundTripsTheBracketsExactly) {
  const ConfigDirectory dir;
  const IdentifyConfig loaded = LoadIdentifyConfig(dir.WriteConfig(ConfigWith(kJumps)));
  const std::string yaml = ConfigToYaml(loaded);
  EXPECT_THAT(yaml, HasSubstr("  - sweep: L0.060g/down\n    kind: jump_up\n    between_hz: "
                              "[161.041, 161.012]"));
  EXPECT_THAT(yaml, HasSubstr("between_a_base: [0.035, 0.036]"));
  EXPECT_THAT(yaml, HasSubstr("  - sweep: L0.040g/down\n    none: true"));
  const IdentifyConfig reloaded = LoadIdentifyConfig(dir.WriteFile("in_effect.yaml", yaml));
  ASSERT_EQ(reloaded.jump_overrides.size(), 3u);
  for (size_t i = 0; i < 3; ++i) {
    EXPECT_EQ(reloaded.jump_overrides[i].sweep, loaded.jump_overrides[i].sweep);
    EXPECT_EQ(reloaded.jump_overrides[i].none, loaded.jump_overrides[i].none);
    EXPECT_EQ(reloaded.jump_overrides[i].kind, loaded.jump_overrides[i].kind);
    EXPECT_EQ(reloaded.jump_overrides[i].control, loaded.jump_overrides[i].control);
    EXPECT_EQ(reloaded.jump_overrides[i].control_before, loaded.jump_overrides[i].control_before);
    EXPECT_EQ(reloaded.jump_overrides[i].control_after, loaded.jump_overrides[i].control_after);
  }
  // No overrides print as an empty list, which loads again.
  const std::string none = ConfigToYaml(LoadIdentifyConfig(dir.WriteConfig(kValidConfig)));
  EXPECT_THAT(none, HasSubstr("\njumps: []\n"));
  EXPECT_THAT(LoadIdentifyConfig(dir.WriteFile("none.yaml", none)).jump_overrides, IsEmpty());
}

TEST(ConfigJumps, OverridesReplaceTheListAndTheirErrorsNameTheFlag) {
  const ConfigDirectory dir;
  const std::string path = dir.WriteConfig(ConfigWith(kJumps));
  const IdentifyConfig config = LoadIdentifyConfig(
      path, ParseSetFlag("jumps=[{sweep: F0.01/up, kind: jump_down, between_hz: [42.2, 42.3]}]",
                         "--set"));
  ASSERT_EQ(config.jump_overrides.size(), 1u);
  EXPECT_EQ(config.jump_overrides[0].sweep, "F0.01/up");
  EXPECT_EQ(config.jump_overrides[0].line, 0);  // no line: set on the command line
  const InputError error = ErrorOf([&] {
    LoadIdentifyConfig(path, ParseSetFlag("jumps=[{sweep: F0.01/up, none: maybe}]", "--set"));
  });
  EXPECT_THAT(error.what(),
              StartsWith("--set: field 'jumps[0].none': expected true or false, got 'maybe'"));
}

// A config reading the measured beam, with `extra` appended.
std::string BeamConfig(const std::string& extra) {
  return "data: " + std::string(DWELLFIT_SOURCE_DIR) +
         "/datasets/clamped-beam-27C/sweeps.csv\n"
         "fit: [L0.060g]\n"
         "initial_guess: {eta_e: 1, mu1: 1, mu2: 0, delta: 0, alpha: 1e12, omega_hz: 156}\n"
         "output_dir: out\n" +
         extra;
}

TEST(ConfigJumps, ApplyToTheMeasuredBeamAfterDetection) {
  const ConfigDirectory dir;
  const IdentifyConfig config = LoadIdentifyConfig(dir.WriteConfig(BeamConfig(R"(jumps:
  - sweep: L0.060g/down
    kind: jump_up
    between_hz: [161.07, 161.041]
  - sweep: L0.040g/down
    none: true
)")));
  const ResolvedRun run = ResolveRun(config);
  for (const Sweep& sweep : run.sweeps) {
    if (sweep.Name() == "L0.060g/down") {
      ASSERT_EQ(sweep.jumps.size(), 1u);
      EXPECT_EQ(sweep.jumps[0].control_before, HzToRadPerSecond(161.07));
      EXPECT_EQ(sweep.jumps[0].control_after, HzToRadPerSecond(161.041));
      EXPECT_EQ(DescribeJumps(sweep),
                "L0.060g/down: jump_up between 161.070 and 161.041 Hz (a 1.8e-4 -> 1.9e-4) "
                "[config]");
    } else if (sweep.Name() == "L0.040g/down") {
      EXPECT_THAT(sweep.jumps, IsEmpty());
      EXPECT_TRUE(sweep.jumps_from_config);
    } else {
      EXPECT_FALSE(sweep.jumps_from_config) << sweep.Name();
      EXPECT_EQ(sweep.jumps.size(), 1u) << sweep.Name();
    }
  }
}

TEST(ConfigJumps, RunIdentifyRejectsAnOverrideOfASweepNotInTheData) {
  const ConfigDirectory dir;
  const std::string path = dir.WriteConfig(BeamConfig(R"(jumps:
  - sweep: L0.060g/down
    kind: jump_up
    between_hz: [161.041, 161.012]
  - sweep: L0.061g/down
    none: true
)"));
  std::ostringstream out;
  const InputError error = ErrorOf([&] { RunIdentify(LoadIdentifyConfig(path), out); });
  EXPECT_EQ(error.file(), path);
  EXPECT_EQ(error.line(), 9);
  EXPECT_EQ(error.field(), "jumps[1]");
  EXPECT_THAT(error.what(), HasSubstr("sweep 'L0.061g/down' is not in the data; available: "
                                      "L0.040g/up, L0.040g/down, L0.045g/up"));
  // A bracket across a dwell is rejected the same way, naming the sweep.
  const std::string across = dir.WriteFile("across.yaml", BeamConfig(R"(jumps:
  - sweep: L0.060g/down
    kind: jump_up
    between_hz: [161.070, 161.012]
)"));
  const InputError bracket = ErrorOf([&] { RunIdentify(LoadIdentifyConfig(across), out); });
  EXPECT_EQ(bracket.line(), 6);
  EXPECT_THAT(bracket.what(), HasSubstr("sweep 'L0.060g/down': the bracket [161.07 Hz, 161.012 "
                                        "Hz] does not lie between two consecutive dwells (dwells "
                                        "inside it: 161.041 Hz)"));
}

}  // namespace
}  // namespace dwellfit
