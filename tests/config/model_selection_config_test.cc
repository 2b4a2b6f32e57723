// The `model_selection:` block: defaults, values, errors at their line, and
// the config in effect printed back.
#include <string>

#include "dwellfit/config/identify_config.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "tests/config_test_support.h"

namespace dwellfit {
namespace {

using ::testing::HasSubstr;

std::string WithBlock(const std::string& block) {
  return Replace(kValidConfig, "output_dir:", block + "output_dir:");
}

TEST(ModelSelectionConfig, AbsentBlockLeavesItUnsetAndAnEmptyOneGivesTheDefaults) {
  ConfigDirectory dir;
  EXPECT_FALSE(LoadIdentifyConfig(dir.WriteConfig(kValidConfig)).model_selection.has_value());
  const IdentifyConfig config =
      LoadIdentifyConfig(dir.WriteConfig(WithBlock("model_selection:\n")));
  ASSERT_TRUE(config.model_selection.has_value());
  const ModelSelectionConfig& selection = *config.model_selection;
  ASSERT_EQ(selection.delta.size(), 2u);
  EXPECT_FALSE(selection.delta[0].value.has_value());
  EXPECT_EQ(selection.delta[1].value, 0.0);
  ASSERT_EQ(selection.mu2.size(), 2u);
  ASSERT_EQ(selection.omega.size(), 1u);
  EXPECT_FALSE(selection.omega[0].value.has_value());
  EXPECT_EQ(selection.scheme, CrossValidationScheme::kLeaveOneLevelOut);
  EXPECT_EQ(selection.training, CrossValidationTraining::kConfig);
  EXPECT_TRUE(selection.pool.empty());
  EXPECT_EQ(selection.threads, 2);
}

TEST(ModelSelectionConfig, ReadsChoicesWithOmegaInHzAndInitial) {
  ConfigDirectory dir;
  const IdentifyConfig config = LoadIdentifyConfig(dir.WriteConfig(
      WithBlock("model_selection:\n  delta: [0]\n  mu2: [free, 0]\n  omega_hz: [free, initial, "
                "40.5]\n  cross_validation: none\n  training: all\n  pool: [A41.2, F0.01/up]\n"
                "  threads: 3\n")));
  const ModelSelectionConfig& selection = *config.model_selection;
  ASSERT_EQ(selection.omega.size(), 3u);
  EXPECT_DOUBLE_EQ(*selection.omega[1].value, HzToRadPerSecond(40.0));  // initial_guess.omega_hz
  EXPECT_EQ(selection.omega[1].text, "40");
  EXPECT_DOUBLE_EQ(*selection.omega[2].value, HzToRadPerSecond(40.5));
  EXPECT_EQ(selection.scheme, CrossValidationScheme::kNone);
  EXPECT_EQ(selection.training, CrossValidationTraining::kAll);
  ASSERT_EQ(selection.pool.size(), 2u);
  EXPECT_EQ(selection.pool[1].Name(), "F0.01/up");
  EXPECT_EQ(selection.threads, 3);
  // The config in effect reads back to the same block.
  const std::string again = dir.WriteFile("again.yaml", ConfigToYaml(config));
  const IdentifyConfig reread = LoadIdentifyConfig(again);
  ASSERT_TRUE(reread.model_selection.has_value());
  EXPECT_EQ(ConfigToYaml(reread).substr(ConfigToYaml(reread).find("model_selection")),
            ConfigToYaml(config).substr(ConfigToYaml(config).find("model_selection")));
}

TEST(ModelSelectionConfig, ErrorsNameTheLineAndTheKey) {
  ConfigDirectory dir;
  std::string path;
  // kValidConfig has 27 lines before output_dir; the block starts at line 27.
  EXPECT_THAT(LoadError(dir, WithBlock("model_selection:\n  delta: [free, free]\n"), &path).what(),
              HasSubstr("lists 'free' twice"));
  EXPECT_THAT(LoadError(dir, WithBlock("model_selection:\n  training: some\n"), &path).what(),
              HasSubstr("unknown training set 'some'"));
  EXPECT_THAT(LoadError(dir, WithBlock("model_selection:\n  mu2: [-1]\n"), &path).what(),
              HasSubstr("mu2: a fixed value must be >= 0"));
  EXPECT_THAT(LoadError(dir, WithBlock("model_selection:\n  variants: 3\n"), &path).what(),
              HasSubstr("variants"));
  const InputError auto_initial = LoadError(
      dir,
      Replace(WithBlock("model_selection:\n  delta: [initial]\n"), "delta: 1.3e4", "delta: auto"),
      &path);
  EXPECT_THAT(auto_initial.what(), HasSubstr("initial_guess.delta is auto"));
  EXPECT_THAT(auto_initial.what(), HasSubstr(":28:"));
}

}  // namespace
}  // namespace dwellfit
