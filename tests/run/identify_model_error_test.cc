// identify's model-error sections: the validation sweeps' prediction
// intervals (the measured beam), and the leave-one-level-out refits when
// three levels are fitted (the virtual beam).
#include <cmath>
#include <filesystem>
#include <iostream>
#include <sstream>
#include <string>

#include "dwellfit/config/config_override.h"
#include "dwellfit/config/identify_config.h"
#include "dwellfit/estimator/run/identify_run.h"
#include "dwellfit/estimator/run/resolved_run.h"
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

// The virtual beam (simulated through the rig, omega fixed) with three
// fitted levels -- F0.01, A41.5 and A41.2 -- and A41.8 validated: three
// refits, each without one level. On data whose noise is independent the
// refits' spread is of the statistical uncertainty's size: the all-level
// estimate lies within the refits' range and each jackknife standard error
// is within a factor 4 of the linearised one (0.015 against 0.044 for
// eta_e, 133 against 52 for mu2).
TEST(IdentifyModelError, ThreeFittedLevelsReportTheLeaveOneLevelOutSpread) {
  const std::string out_dir = FreshDir("three_levels");
  const IdentifyConfig config =
      LoadIdentifyConfig(std::string(DWELLFIT_SOURCE_DIR) + "/datasets/virtual-beam/beam.yaml",
                         {{"output_dir", out_dir, "--test"},
                          ListFlagOverride("fit", "F0.01,A41.5,A41.2", "--fit"),
                          ListFlagOverride("validate", "A41.8", "--validate")});
  std::ostringstream printed;
  IdentifyRunOptions options;
  options.render_figures = false;
  const auto outcome = RunIdentify(config, printed, options);
  const IdentificationReport& report = outcome->report;
  ASSERT_EQ(report.result.status, FitStatus::kConverged) << report.result.message;
  const LevelRefits& refits = report.level_refits;
  ASSERT_TRUE(refits.computed) << refits.message;
  ASSERT_EQ(refits.levels, (std::vector<std::string>{"F0.01", "A41.5", "A41.2"}));
  ASSERT_EQ(refits.refits.size(), 3u);
  EXPECT_EQ(refits.usable, 3);
  int free = 0;
  for (int j = 0; j < kNumParameters; ++j) free += !report.options.fixed[j];
  ASSERT_EQ(free, 5);                                                   // omega fixed
  ASSERT_EQ(refits.spread.size(), static_cast<std::size_t>(free + 1));  // and alpha_e
  const ParameterUncertainty& u = report.uncertainty;
  for (const RefitSpread& s : refits.spread) {
    std::cout << s.name << ": estimate " << s.estimate << ", refits " << s.min << ".." << s.max
              << ", jackknife se " << s.jackknife_standard_error << "\n";
    EXPECT_TRUE(std::isfinite(s.jackknife_standard_error)) << s.name;
    EXPECT_LE(s.min, s.estimate) << s.name;
    EXPECT_GE(s.max, s.estimate) << s.name;
    const double statistical = s.index == kNumParameters ? u.effective_nonlinearity_standard_error
                                                         : u.standard_error[s.index];
    EXPECT_GT(s.jackknife_standard_error, statistical / 4.0) << s.name;
    EXPECT_LT(s.jackknife_standard_error, statistical * 4.0) << s.name;
  }
  EXPECT_TRUE(refits.warnings.empty()) << refits.warnings.front();
  EXPECT_THAT(printed.str(), HasSubstr("leave-one-level-out refits: 3 refits"));
  const YAML::Node result = YAML::LoadFile(out_dir + "/result.yaml");
  const YAML::Node lolo = result["leave_one_level_out"];
  ASSERT_TRUE(lolo);
  EXPECT_TRUE(lolo["computed"].as<bool>());
  EXPECT_EQ(lolo["refits"].size(), 3u);
  EXPECT_EQ(lolo["refits"][1]["left_out"].as<std::string>(), "A41.5");
  EXPECT_EQ(lolo["spread"]["mu2"]["max"].as<double>(), refits.spread[2].max);
  // A41.8 is an amplitude sweep: no validation interval (frequency sweeps only).
  EXPECT_FALSE(result["validation_intervals"]);
}

// The bundled beam.yaml (two fitted levels), fitted as identify fits it and
// its report's model error added as identify adds it (without the
// profiles, which take most of identify's 4.5 s): no refits, and why; its
// ten validation levels' jump-down intervals hold the measured bracket
// centre at 9 of them (docs/uncertainty.md, "Model error"), with a median
// half-width of about 12 Hz.
TEST(IdentifyModelError, BeamValidationJumpDownsFallInsideTheirIntervals) {
  const IdentifyConfig config = LoadIdentifyConfig(kBeam, {});
  const ResolvedRun run = ResolveRun(config);
  const MultiStartResult fit = FitRun(run);
  ASSERT_EQ(fit.best.status, FitStatus::kConverged) << fit.best.message;
  IdentificationReport report;
  report.options = run.options;
  report.result = fit.best;
  report.omega_ref_rad_s = fit.best.parameters[kNaturalFrequency];
  AddModelError(run.fitted, run.validation, 2, &report);
  EXPECT_FALSE(report.level_refits.computed);
  EXPECT_THAT(report.level_refits.message, HasSubstr("2 levels fitted"));
  const ValidationIntervals& v = report.validation_intervals;
  EXPECT_TRUE(v.parameter_covariance) << v.note;
  ASSERT_EQ(v.levels.size(), 10u);
  EXPECT_EQ(v.coverage.jump_down.total, 10);
  EXPECT_GE(v.coverage.jump_down.inside, 8);
  EXPECT_GT(v.coverage.jump_down.median_half_width, 5.0);   // Hz
  EXPECT_LT(v.coverage.jump_down.median_half_width, 20.0);  // Hz
  EXPECT_EQ(v.coverage.upper_branch.total, 10);
  std::cout << "jump-down: " << v.coverage.jump_down.inside << " of 10 inside, median half-width "
            << v.coverage.jump_down.median_half_width << " Hz\n";
  std::ostringstream printed;
  PrintReport(report, printed);
  EXPECT_THAT(printed.str(), ::testing::ContainsRegex("jump-down: median \\|error\\| [0-9.]+ %, " +
                                                      std::to_string(v.coverage.jump_down.inside) +
                                                      " of 10 measured inside"));
  const YAML::Node result = YAML::Load(ReportToYaml(report));
  const YAML::Node coverage = result["validation_intervals"]["coverage"]["jump_down"];
  EXPECT_EQ(coverage["inside"].as<int>(), v.coverage.jump_down.inside);
  // 10 levels x (jump-down, upper-branch amplitude, jump-up).
  ASSERT_EQ(result["validation_intervals"]["predictions"].size(), 30u);
  const YAML::Node first = result["validation_intervals"]["predictions"][0];
  EXPECT_EQ(first["quantity"].as<std::string>(), "jump_down");
  EXPECT_EQ(first["unit"].as<std::string>(), "Hz");
  EXPECT_EQ(first["half_width"].as<double>(), v.levels[0].predictions[0].half_width);
  EXPECT_FALSE(result["leave_one_level_out"]["computed"].as<bool>());
}

}  // namespace
}  // namespace dwellfit
