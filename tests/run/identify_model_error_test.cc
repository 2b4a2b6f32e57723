// identify's model-error sections on the measured beam: the validation
// sweeps' prediction intervals, and the leave-one-level-out refits when
// three levels are fitted.
#include <cmath>
#include <filesystem>
#include <iostream>
#include <sstream>
#include <string>

#include "dwellfit/config/config_override.h"
#include "dwellfit/config/identify_config.h"
#include "dwellfit/estimator/run/identify_run.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "yaml-cpp/yaml.h"

namespace dwellfit {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

const std::string kBeam = std::string(DWELLFIT_SOURCE_DIR) + "/datasets/clamped-beam-27C/beam.yaml";

std::string FreshDir(const std::string& name) {
  const fs::path dir = fs::path(::testing::TempDir()) / ("identify_model_error_" + name);
  fs::remove_all(dir);
  return dir.string();
}

// beam.yaml with three fitted levels (0.060, 0.070, 0.080 g) and the other
// nine validated: three refits, each without one level.
TEST(IdentifyModelError, ThreeFittedLevelsReportTheLeaveOneLevelOutSpread) {
  const std::string out_dir = FreshDir("three_levels");
  const IdentifyConfig config = LoadIdentifyConfig(
      kBeam, {{"output_dir", out_dir, "--test"},
              ListFlagOverride("fit", "L0.060g,L0.070g,L0.080g", "--fit"),
              ListFlagOverride("validate",
                               "L0.040g,L0.045g,L0.050g,L0.055g,L0.065g,L0.075g,L0.085g,L0.090g,"
                               "L0.095g",
                               "--validate")});
  std::ostringstream printed;
  IdentifyRunOptions options;
  options.render_figures = false;
  const auto outcome = RunIdentify(config, printed, options);
  const IdentificationReport& report = outcome->report;
  const LevelRefits& refits = report.level_refits;
  ASSERT_TRUE(refits.computed) << refits.message;
  ASSERT_EQ(refits.refits.size(), 3u);
  EXPECT_EQ(refits.usable, 3);
  int free = 0;
  for (int j = 0; j < kNumParameters; ++j) free += !report.options.fixed[j];
  ASSERT_EQ(refits.spread.size(), static_cast<std::size_t>(free + 1));  // and alpha_e
  for (const RefitSpread& s : refits.spread) {
    EXPECT_TRUE(std::isfinite(s.jackknife_standard_error)) << s.name;
    EXPECT_GE(s.jackknife_standard_error, 0.0) << s.name;
    EXPECT_LE(s.min, s.max) << s.name;
    std::cout << s.name << ": estimate " << s.estimate << ", refits " << s.min << ".." << s.max
              << ", jackknife se " << s.jackknife_standard_error << "\n";
  }
  // w is determined by every level alike: each refit's within 1 % of the
  // all-level estimate.
  for (const LevelRefit& refit : refits.refits) {
    EXPECT_NEAR(refit.parameters[kNaturalFrequency], report.result.parameters[kNaturalFrequency],
                0.01 * report.result.parameters[kNaturalFrequency])
        << refit.left_out;
  }
  EXPECT_THAT(printed.str(), HasSubstr("leave-one-level-out refits: 3 refits"));
  EXPECT_THAT(printed.str(), HasSubstr("jump-down: "));
  const YAML::Node result = YAML::LoadFile(out_dir + "/result.yaml");
  const YAML::Node lolo = result["leave_one_level_out"];
  ASSERT_TRUE(lolo);
  EXPECT_TRUE(lolo["computed"].as<bool>());
  EXPECT_EQ(lolo["refits"].size(), 3u);
  EXPECT_EQ(lolo["spread"]["mu1"]["min"].as<double>(), refits.spread[1].min);
  const YAML::Node intervals = result["validation_intervals"];
  ASSERT_TRUE(intervals);
  EXPECT_EQ(intervals["coverage"]["jump_down"]["total"].as<int>(), 9);
  EXPECT_EQ(intervals["coverage"]["jump_down"]["inside"].as<int>(),
            report.validation_intervals.coverage.jump_down.inside);
}

}  // namespace
}  // namespace dwellfit
