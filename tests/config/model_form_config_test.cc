// The `model: {averaging: ..., damping: ..., backbone: ...}` key of identify's
// config and of a dwell plan.
#include <string>

#include "dwellfit/config/dwell_plan_reader.h"
#include "dwellfit/config/identify_config.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "tests/config_test_support.h"

namespace dwellfit {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;

TEST(ModelFormConfig, FirstOrderByDefaultNotShownAndTheSecondOrderRoundTrips) {
  const ConfigDirectory dir;
  const IdentifyConfig by_default = LoadIdentifyConfig(dir.WriteConfig(kValidConfig));
  EXPECT_EQ(by_default.identification.solve.residual.form.averaging, Averaging::kFirstOrder);
  EXPECT_THAT(ConfigToYaml(by_default), Not(HasSubstr("averaging")));

  const IdentifyConfig first = LoadIdentifyConfig(
      dir.WriteConfig(std::string(kValidConfig) + "model:\n  averaging: first_order\n"));
  EXPECT_EQ(first.identification.solve.residual.form.averaging, Averaging::kFirstOrder);

  // After `residual:` in the file or before it: the residual block keeps it.
  const IdentifyConfig second = LoadIdentifyConfig(
      dir.WriteConfig("model: {averaging: second_order}\n" + std::string(kValidConfig).substr(9)));
  EXPECT_EQ(second.identification.solve.residual.form.averaging, Averaging::kSecondOrder);
  EXPECT_EQ(second.identification.solve.residual.error, ErrorMeasure::kRelative);
  const std::string yaml = ConfigToYaml(second, ConfigKeys::kAffectingTheResult);
  EXPECT_THAT(yaml, HasSubstr("model:\n  averaging: second_order"));
  const IdentifyConfig reloaded = LoadIdentifyConfig(dir.WriteConfig(ConfigToYaml(second)));
  EXPECT_EQ(reloaded.identification.solve.residual.form.averaging, Averaging::kSecondOrder);
}

TEST(ModelFormConfig, AnUnknownAveragingNamesFileLineKeyAndTheAllowedNames) {
  const ConfigDirectory dir;
  std::string path;
  // kValidConfig has 27 lines: `model:` is line 28, `averaging:` line 29.
  const InputError error =
      LoadError(dir, std::string(kValidConfig) + "model:\n  averaging: third_order\n", &path);
  EXPECT_EQ(error.file(), path);
  EXPECT_EQ(error.line(), 29);
  EXPECT_THAT(error.what(), HasSubstr(path + ":29: "));
  EXPECT_THAT(error.what(), HasSubstr("averaging"));
  EXPECT_THAT(error.what(), HasSubstr("third_order"));
  EXPECT_THAT(error.what(), HasSubstr("allowed: first_order, second_order"));

  const InputError missing = LoadError(dir, std::string(kValidConfig) + "model: {}\n", &path);
  EXPECT_EQ(missing.line(), 28);
  EXPECT_THAT(missing.what(), HasSubstr("averaging"));
  const InputError unknown_key =
      LoadError(dir, std::string(kValidConfig) + "model: {order: 2}\n", &path);
  EXPECT_THAT(unknown_key.what(), HasSubstr("order"));
}

// A member of the family: its keys, its parameters' names in initial_guess
// and fixed, the echo, and the second order refused beside it.
TEST(ModelFormConfig, AMembersTermsAreNamedInTheKeysAndTheEcho) {
  const ConfigDirectory dir;
  std::string member(kValidConfig);
  member.replace(member.find("  mu2: 390"), 10, "  mu3: 1.0e5");
  member.replace(member.find("  delta: 1.3e4"), 14, "  alpha5: 2.0e13");
  member.replace(member.find("fixed: [omega]"), 14, "fixed: [omega, alpha5]");
  const IdentifyConfig config =
      LoadIdentifyConfig(dir.WriteConfig(member + "model: {damping: cubic, backbone: quintic}\n"));
  const ModelForm form = config.identification.solve.residual.form;
  EXPECT_TRUE(form.cubic_damping());
  EXPECT_TRUE(form.quintic_stiffness());
  EXPECT_FALSE(form.second_order());
  EXPECT_EQ(config.identification.initial[kMu3], 1.0e5);
  EXPECT_EQ(config.identification.initial[kAlpha5], 2.0e13);
  EXPECT_TRUE(config.identification.fixed[kAlpha5]);
  const std::string yaml = ConfigToYaml(config, ConfigKeys::kAffectingTheResult);
  EXPECT_THAT(yaml, HasSubstr("model:\n  damping: cubic\n  backbone: quintic"));
  EXPECT_THAT(yaml, HasSubstr("  mu3: 1e+05\n  alpha5: 2e+13\n"));
  EXPECT_THAT(yaml, HasSubstr("fixed: [alpha5, omega]"));
  const IdentifyConfig reloaded = LoadIdentifyConfig(dir.WriteConfig(ConfigToYaml(config)));
  EXPECT_TRUE(reloaded.identification.solve.residual.form == form);

  // The chapter's names are not the member's: mu2 under damping: cubic is
  // an unknown key, named with the allowed ones.
  std::string path;
  const InputError chapter_name =
      LoadError(dir, std::string(kValidConfig) + "model: {damping: cubic}\n", &path);
  EXPECT_EQ(chapter_name.line(), 8);
  EXPECT_THAT(chapter_name.what(), HasSubstr("mu2"));
  EXPECT_THAT(chapter_name.what(), HasSubstr("mu3"));

  const InputError second =
      LoadError(dir, member + "model: {averaging: second_order, damping: cubic}\n", &path);
  EXPECT_EQ(second.line(), 28);
  EXPECT_THAT(second.what(), HasSubstr("second_order"));
  const InputError unknown = LoadError(dir, member + "model: {backbone: septic}\n", &path);
  EXPECT_THAT(unknown.what(), HasSubstr("allowed: inertia, quintic"));
}

TEST(ModelFormConfig, ADwellPlanReadsItsModel) {
  const std::string plan_text =
      R"(truth: {eta_e: 100, mu1: 0.2, mu2: 300, delta: 1.0e4, alpha: 9.0e8, omega_hz: 40}
sweeps:
  - {id: F0.01, kind: frequency, a_base: 0.01, from_hz: 38, to_hz: 46, step_hz: 0.1}
)";
  EXPECT_EQ(ParseDwellPlan(plan_text, "plan.yaml").form.averaging, Averaging::kFirstOrder);
  EXPECT_EQ(
      ParseDwellPlan(plan_text + "model: {averaging: second_order}\n", "plan.yaml").form.averaging,
      Averaging::kSecondOrder);
  const InputError error =
      ErrorOf([&] { ParseDwellPlan(plan_text + "model: {averaging: second}\n", "plan.yaml"); });
  EXPECT_EQ(error.line(), 4);
  EXPECT_THAT(error.what(), HasSubstr("allowed: first_order, second_order"));

  // A member's truth names its own terms, wherever `model:` stands.
  std::string member = plan_text;
  member.replace(member.find("mu2: 300"), 8, "mu3: 1.0e5");
  const DwellPlan plan = ParseDwellPlan(member + "model: {damping: cubic}\n", "plan.yaml");
  EXPECT_TRUE(plan.form.cubic_damping());
  EXPECT_EQ(plan.truth[kMu3], 1.0e5);
  EXPECT_EQ(plan.truth[kDelta], 1.0e4);
  EXPECT_THAT(ErrorOf([&] { ParseDwellPlan(member, "plan.yaml"); }).what(), HasSubstr("mu3"));
}

}  // namespace
}  // namespace dwellfit
