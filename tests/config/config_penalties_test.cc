// The `penalties:` block of the identify config (config/README.md).
#include <string>

#include "dwellfit/config/config_override.h"
#include "dwellfit/config/identify_config.h"
#include "dwellfit/estimator/common/input_error.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "tests/config_test_support.h"

namespace dwellfit {
namespace {

using ::testing::ElementsAre;
using ::testing::HasSubstr;
using ::testing::StartsWith;

// kValidConfig (27 lines) with `extra` from line 28 on.
std::string ConfigWith(const std::string& extra) { return std::string(kValidConfig) + extra; }

constexpr char kPenalties[] = R"(penalties:
  bifurcation_range:
    enabled: true
    exponent: 6
    weight: 2.5
    enforce: [frequency_jump_up, amplitude_jump_down]
  branch_stability:
    enabled: true
    lambda: 30
    weight: 0.5
)";

TEST(ConfigPenalties, BlockLandsInPenaltyOptions) {
  const ConfigDirectory dir;
  const IdentifyConfig config = LoadIdentifyConfig(dir.WriteConfig(ConfigWith(kPenalties)));
  const PenaltyOptions& penalties = config.identification.solve.penalties;
  EXPECT_TRUE(penalties.bifurcation_range.enabled);
  EXPECT_EQ(penalties.bifurcation_range.exponent, 6);
  EXPECT_EQ(penalties.bifurcation_range.weight, 2.5);
  EXPECT_THAT(penalties.bifurcation_range.enforce,
              ElementsAre(JumpTarget::kFrequencyJumpUp, JumpTarget::kAmplitudeJumpDown));
  EXPECT_TRUE(penalties.branch_stability.enabled);
  EXPECT_EQ(penalties.branch_stability.lambda, 30.0);
  EXPECT_EQ(penalties.branch_stability.weight, 0.5);
}

// The defaults are the documented ones (config/README.md, `penalties`; the
// chapter's choice of enforced jumps), written here rather than read from
// PenaltyOptions, so a changed default in the code fails until the
// documentation is changed with it.
TEST(ConfigPenalties, MissingKeysTakeTheDocumentedDefaults) {
  const ConfigDirectory dir;
  IdentifyConfig config = LoadIdentifyConfig(dir.WriteConfig(kValidConfig));
  const PenaltyOptions* penalties = &config.identification.solve.penalties;
  EXPECT_FALSE(penalties->bifurcation_range.enabled);
  EXPECT_EQ(penalties->bifurcation_range.exponent, 10);
  EXPECT_EQ(penalties->bifurcation_range.weight, 1.0);
  EXPECT_THAT(penalties->bifurcation_range.enforce,
              ElementsAre(JumpTarget::kFrequencyJumpDown, JumpTarget::kAmplitudeJumpUp));
  EXPECT_FALSE(penalties->branch_stability.enabled);
  EXPECT_EQ(penalties->branch_stability.lambda, 50.0);
  EXPECT_EQ(penalties->branch_stability.weight, 1.0);

  // A block that sets one key keeps the documented values of the others.
  config = LoadIdentifyConfig(
      dir.WriteConfig(ConfigWith("penalties:\n  branch_stability:\n    enabled: true\n")));
  penalties = &config.identification.solve.penalties;
  EXPECT_TRUE(penalties->branch_stability.enabled);
  EXPECT_EQ(penalties->branch_stability.lambda, 50.0);
  EXPECT_EQ(penalties->branch_stability.weight, 1.0);
  EXPECT_FALSE(penalties->bifurcation_range.enabled);
  EXPECT_EQ(penalties->bifurcation_range.exponent, 10);
  // An empty enforce list enforces no jump.
  config = LoadIdentifyConfig(
      dir.WriteConfig(ConfigWith("penalties:\n  bifurcation_range:\n    enforce: []\n")));
  EXPECT_TRUE(config.identification.solve.penalties.bifurcation_range.enforce.empty());
}

TEST(ConfigPenalties, InvalidValuesAreReportedAtTheirBlock) {
  const ConfigDirectory dir;
  std::string path;
  InputError error =
      LoadError(dir, ConfigWith(Replace(kPenalties, "exponent: 6", "exponent: 7")), &path);
  EXPECT_EQ(error.file(), path);
  EXPECT_EQ(error.line(), 29);
  EXPECT_EQ(error.field(), "penalties.bifurcation_range");
  EXPECT_THAT(error.what(), HasSubstr("penalties.bifurcation_range.exponent must be an even "
                                      "integer >= 2"));

  error = LoadError(dir, ConfigWith(Replace(kPenalties, "lambda: 30", "lambda: 0")), &path);
  EXPECT_EQ(error.line(), 34);
  EXPECT_EQ(error.field(), "penalties.branch_stability");
  EXPECT_THAT(error.what(), HasSubstr("penalties.branch_stability.lambda must be a positive"));

  error = LoadError(dir, ConfigWith(Replace(kPenalties, "weight: 2.5", "weight: -1")), &path);
  EXPECT_EQ(error.line(), 29);
  EXPECT_THAT(error.what(), HasSubstr("bifurcation_range.weight must be a non-negative"));
}

TEST(ConfigPenalties, StrictKeysAndTypes) {
  const ConfigDirectory dir;
  std::string path;
  InputError error =
      LoadError(dir, ConfigWith(Replace(kPenalties, "exponent: 6", "exponant: 6")), &path);
  EXPECT_EQ(error.line(), 31);
  EXPECT_EQ(error.field(), "penalties.bifurcation_range.exponant");
  EXPECT_THAT(error.what(), HasSubstr("unknown key 'exponant' in 'penalties.bifurcation_range' "
                                      "(did you mean 'exponent'?); allowed: enabled, exponent, "
                                      "weight, enforce"));

  error = LoadError(dir, ConfigWith(Replace(kPenalties, "exponent: 6", "exponent: 6.5")), &path);
  EXPECT_EQ(error.line(), 31);
  EXPECT_THAT(error.what(), HasSubstr("expected a whole number (e.g. 200), got '6.5'"));

  error = LoadError(dir, ConfigWith(Replace(kPenalties, "enabled: true", "enabled: yes")), &path);
  EXPECT_EQ(error.line(), 30);
  EXPECT_THAT(error.what(), HasSubstr("expected true or false, got 'yes'"));

  error = LoadError(dir, ConfigWith("penalties:\n  stability: {}\n"), &path);
  EXPECT_EQ(error.line(), 29);
  EXPECT_THAT(error.what(), HasSubstr("allowed: bifurcation_range, branch_stability"));
}

TEST(ConfigPenalties, EnforceNamesJumpTargetsOnce) {
  const ConfigDirectory dir;
  std::string path;
  InputError error = LoadError(
      dir, ConfigWith(Replace(kPenalties, "frequency_jump_up,", "frequency_jumpdown,")), &path);
  EXPECT_EQ(error.line(), 33);
  EXPECT_EQ(error.field(), "penalties.bifurcation_range.enforce");
  EXPECT_THAT(error.what(),
              HasSubstr("unknown jump 'frequency_jumpdown' (did you mean 'frequency_jump_down'?); "
                        "allowed: frequency_jump_up, frequency_jump_down, amplitude_jump_up, "
                        "amplitude_jump_down"));

  error = LoadError(dir,
                    ConfigWith(Replace(kPenalties, "amplitude_jump_down]",
                                       "amplitude_jump_down, frequency_jump_up]")),
                    &path);
  EXPECT_THAT(error.what(), HasSubstr("jump 'frequency_jump_up' is listed twice"));
}

TEST(ConfigPenalties, OverridesSetAndCheckPenalties) {
  const ConfigDirectory dir;
  const std::string path = dir.WriteConfig(ConfigWith(kPenalties));
  IdentifyConfig config =
      LoadIdentifyConfig(path, ParseSetFlag("penalties.bifurcation_range.enabled=false,"
                                            "penalties.branch_stability.lambda=80",
                                            "--set"));
  EXPECT_FALSE(config.identification.solve.penalties.bifurcation_range.enabled);
  EXPECT_EQ(config.identification.solve.penalties.bifurcation_range.exponent, 6);  // from the file
  EXPECT_EQ(config.identification.solve.penalties.branch_stability.lambda, 80.0);

  // A block the file lacks is created.
  config = LoadIdentifyConfig(dir.WriteFile("lacks.yaml", kValidConfig),
                              ParseSetFlag("penalties.branch_stability.enabled=true", "--set"));
  EXPECT_TRUE(config.identification.solve.penalties.branch_stability.enabled);

  // An invalid value set on the command line names the flag.
  InputError error = ErrorOf([&] {
    LoadIdentifyConfig(path, ParseSetFlag("penalties.bifurcation_range.exponent=3", "--set"));
  });
  EXPECT_THAT(error.what(), HasSubstr(":29: field 'penalties.bifurcation_range': "
                                      "penalties.bifurcation_range.exponent must be an even "
                                      "integer >= 2 (values set on the command line: --set "
                                      "penalties.bifurcation_range.exponent=3)"));
  error = ErrorOf([&] {
    LoadIdentifyConfig(path,
                       ParseSetFlag("penalties.bifurcation_range.enforce=[sideways]", "--set"));
  });
  EXPECT_THAT(error.what(), StartsWith("--set: field 'penalties.bifurcation_range.enforce': "
                                       "unknown jump 'sideways'"));
}

TEST(ConfigPenalties, PrintedConfigRoundTrips) {
  const ConfigDirectory dir;
  const IdentifyConfig loaded = LoadIdentifyConfig(dir.WriteConfig(ConfigWith(kPenalties)));
  const std::string yaml = ConfigToYaml(loaded);
  EXPECT_THAT(yaml, HasSubstr("penalties:\n  bifurcation_range:\n    enabled: true\n    "
                              "exponent: 6\n    weight: 2.5\n    enforce: [frequency_jump_up, "
                              "amplitude_jump_down]\n  branch_stability:\n    enabled: true\n"
                              "    lambda: 30\n    weight: 0.5\n"));
  const IdentifyConfig reloaded = LoadIdentifyConfig(dir.WriteFile("in_effect.yaml", yaml));
  const PenaltyOptions& a = loaded.identification.solve.penalties;
  const PenaltyOptions& b = reloaded.identification.solve.penalties;
  EXPECT_EQ(b.bifurcation_range.enabled, a.bifurcation_range.enabled);
  EXPECT_EQ(b.bifurcation_range.exponent, a.bifurcation_range.exponent);
  EXPECT_EQ(b.bifurcation_range.weight, a.bifurcation_range.weight);
  EXPECT_EQ(b.bifurcation_range.enforce, a.bifurcation_range.enforce);
  EXPECT_EQ(b.branch_stability.enabled, a.branch_stability.enabled);
  EXPECT_EQ(b.branch_stability.lambda, a.branch_stability.lambda);
  EXPECT_EQ(b.branch_stability.weight, a.branch_stability.weight);

  // Defaults are spelled out too.
  EXPECT_THAT(ConfigToYaml(LoadIdentifyConfig(dir.WriteConfig(kValidConfig))),
              HasSubstr("enforce: [frequency_jump_down, amplitude_jump_up]"));
}

}  // namespace
}  // namespace dwellfit
