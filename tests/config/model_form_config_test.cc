// The `model: {averaging: ...}` key of identify's config and of a dwell plan.
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
}

}  // namespace
}  // namespace dwellfit
