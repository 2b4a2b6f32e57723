#include "dwellfit/estimator/run/identify_run.h"

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "dwellfit/config/config_override.h"
#include "dwellfit/config/identify_config.h"
#include "dwellfit/estimator/common/input_error.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "yaml-cpp/yaml.h"

namespace dwellfit {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;
using ::testing::Not;

const std::string kConfig =
    std::string(DWELLFIT_SOURCE_DIR) + "/datasets/thesis-numerical/beam.yaml";

std::string FreshDir(const std::string& name) {
  const fs::path dir = fs::path(::testing::TempDir()) / ("identify_run_" + name);
  fs::remove_all(dir);
  return dir.string();
}

std::string ReadFile(const fs::path& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

// Without rendering, the run writes the data files and the gnuplot script,
// no image, and records its status and the config it ran.
TEST(RunIdentify, WithoutRenderingWritesTheScriptButNoImage) {
  const std::string out_dir = FreshDir("no_figures");
  const IdentifyConfig config = LoadIdentifyConfig(kConfig, {{"output_dir", out_dir, "--test"}});
  std::ostringstream printed;
  IdentifyRunOptions options;
  options.render_figures = false;
  const auto outcome = RunIdentify(config, printed, options);
  const YAML::Node manifest = YAML::LoadFile(out_dir + "/manifest.yaml");
  std::vector<std::string> names;
  for (const YAML::Node& file : manifest["files"]) names.push_back(file["name"].as<std::string>());
  EXPECT_EQ(names,
            (std::vector<std::string>{"result.yaml", "predictions.csv", "modal_properties.csv",
                                      "curves.csv", "figures.gp", "report.html"}));
  const YAML::Node result = YAML::LoadFile(out_dir + "/result.yaml");
  EXPECT_EQ(result["status"].as<std::string>(), "converged");
  EXPECT_FALSE(result["dwellfit_version"].as<std::string>().empty());
  // The configuration as it reads back: every key that can change the result
  // with its value, none that cannot (where the files go, the thread counts).
  const YAML::Node in_effect = result["config_in_effect"];
  EXPECT_EQ(in_effect["fit"].size(), 2u);
  EXPECT_EQ(in_effect["solver"]["function_tolerance"].as<double>(),
            config.identification.solve.solver.function_tolerance);
  EXPECT_EQ(in_effect["initial_guess"]["mu1"].as<double>(), *config.initial_guess[kMu1]);
  EXPECT_FALSE(in_effect["output_dir"]);
  EXPECT_FALSE(in_effect["solver"]["num_threads"]);
  EXPECT_FALSE(in_effect["multi_start"]["threads"]);
  EXPECT_TRUE(in_effect["multi_start"]["starts"]);
  // Written after the rest of the report: the keys before it read as before.
  EXPECT_EQ(result["fitted_points"].as<int>(), outcome->report.result.residual_blocks);
  EXPECT_GT(result["fitted_points"].as<int>(), 100);
}

// A vertical stage run alone begins with the algebraic start stage, and
// result.yaml says so and which start the vertical stage took, with both
// costs: from the config's start 30 % off the start stage's end, whose
// vertical cost is far below the given start's.
TEST(RunIdentify, ResultYamlRecordsTheStartStageAndTheFirstStagesChoice) {
  const std::string out_dir = FreshDir("start_stage");
  const IdentifyConfig config = LoadIdentifyConfig(
      kConfig,
      {{"output_dir", out_dir, "--test"}, ListFlagOverride("stages", "vertical", "--stages")});
  std::ostringstream printed;
  IdentifyRunOptions options;
  options.render_figures = false;
  RunIdentify(config, printed, options);
  const YAML::Node result = YAML::LoadFile(out_dir + "/result.yaml");
  EXPECT_EQ(result["status"].as<std::string>(), "converged");
  const YAML::Node stages = result["stages"];
  ASSERT_EQ(stages.size(), 2u);
  EXPECT_EQ(stages[0]["residual"].as<std::string>(), "algebraic");
  EXPECT_TRUE(stages[0]["start_stage"].as<bool>());
  EXPECT_FALSE(stages[1]["start_stage"]);
  EXPECT_EQ(stages[1]["residual"].as<std::string>(), "vertical");
  const std::string note = stages[1]["note"].as<std::string>();
  EXPECT_THAT(note, testing::StartsWith("started where the start stage ended, since there the "
                                        "dwells' vertical cost is "));
  // The given start's vertical cost, as the note states it, is far above the
  // cost the vertical stage started from.
  const std::string given = "(at the given start: the dwells' vertical cost is ";
  const size_t at = note.find(given);
  ASSERT_NE(at, std::string::npos) << note;
  const double given_cost = std::stod(note.substr(at + given.size()));
  EXPECT_GT(given_cost, 1.0);
  EXPECT_LT(stages[1]["initial_cost"].as<double>(), 1e-20);
  EXPECT_THAT(printed.str(), HasSubstr("algebraic (start stage) stage: cost"));
}

TEST(RunIdentify, WritesResultYamlAndPredictionsForTheThesisCase) {
  const std::string out_dir = FreshDir("thesis");
  const IdentifyConfig config = LoadIdentifyConfig(kConfig, {{"output_dir", out_dir, "--test"}});
  std::ostringstream printed;
  RunIdentify(config, printed);

  EXPECT_THAT(printed.str(), HasSubstr("# config in effect"));
  EXPECT_THAT(printed.str(), HasSubstr("Ceres Solver Report"));
  EXPECT_THAT(printed.str(), HasSubstr("F0.01/up: jump_down between 42.20 and 42.30 Hz"));

  const YAML::Node result = YAML::LoadFile(out_dir + "/result.yaml");
  EXPECT_NEAR(result["parameters"]["eta_e"]["value"].as<double>(), 100.0, 1e-4);
  EXPECT_NEAR(result["parameters"]["mu1"]["value"].as<double>(), 0.2, 1e-7);
  EXPECT_NEAR(result["parameters"]["mu2"]["value"].as<double>(), 300.0, 1e-3);
  EXPECT_NEAR(result["parameters"]["delta"]["value"].as<double>(), 1e4, 1e-2);
  EXPECT_NEAR(result["parameters"]["alpha"]["value"].as<double>(), 9e8, 1e3);
  EXPECT_DOUBLE_EQ(result["parameters"]["omega"]["value"].as<double>(),
                   HzToRadPerSecond(40.0));  // fixed, rad/s
  const double omega_ref = result["effective_nonlinearity"]["omega_ref_rad_s"].as<double>();
  EXPECT_NEAR(omega_ref, HzToRadPerSecond(41.5), 1e-9);
  EXPECT_NEAR(result["effective_nonlinearity"]["value"].as<double>(),
              9e8 - (2.0 / 3.0) * 1e4 * omega_ref * omega_ref, 1e3);
  EXPECT_TRUE(result["converged"].as<bool>());
  EXPECT_GT(result["iterations"].as<int>(), 0);
  EXPECT_LT(result["final_cost"].as<double>(), 1e-20);
  ASSERT_EQ(result["sweeps"].size(), 8u);
  int validation = 0;
  for (const YAML::Node& sweep : result["sweeps"]) {
    EXPECT_LT(sweep["relative_rms_error"].as<double>(), 1e-6);
    validation += sweep["role"].as<std::string>() == "validation";
  }
  EXPECT_EQ(validation, 4);

  const std::string csv = ReadFile(fs::path(out_dir) / "predictions.csv");
  EXPECT_THAT(csv, HasSubstr("sweep,direction,role,freq_hz,a_base,a,a_model,branch,model_status"));
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 1 + 2 * 81 + 6 * 49);

  const YAML::Node manifest = YAML::LoadFile(out_dir + "/manifest.yaml");
  // result.yaml, predictions.csv, modal_properties.csv, curves.csv,
  // figures.gp, report.html, and a PNG and an SVG for each of the four sweep
  // ids, for the modal properties and for the overview (three amplitude sweeps
  // at three frequencies; gnuplot is installed by the deps script).
  ASSERT_EQ(manifest["files"].size(), 18u);
  EXPECT_EQ(manifest["files"][1]["bytes"].as<std::size_t>(), csv.size());
}

// A config with no initial guess at all: the run finds the start from the
// data, says how, and reaches the truth with omega free.
TEST(RunIdentify, WithNoGuessesFindsTheStartFromTheDataAndReachesTheTruth) {
  const std::string out_dir = FreshDir("automatic");
  const IdentifyConfig config = LoadIdentifyConfig(kConfig, {{"output_dir", out_dir, "--test"},
                                                             {"initial_guess", "auto", "--test"},
                                                             {"fixed", "[]", "--test"}});
  std::ostringstream printed;
  RunIdentify(config, printed);
  EXPECT_THAT(printed.str(), HasSubstr("automatic initial guess:\n  "));
  EXPECT_THAT(printed.str(), Not(HasSubstr("automatic start of the multi-start")));
  const YAML::Node result = YAML::LoadFile(out_dir + "/result.yaml");
  ASSERT_TRUE(result["automatic_initial_guess"].IsSequence());
  EXPECT_GE(result["automatic_initial_guess"].size(), 6u);  // a line per parameter at least
  EXPECT_TRUE(result["converged"].as<bool>());
  EXPECT_NEAR(result["parameters"]["eta_e"]["value"].as<double>(), 100.0, 1e-4);
  EXPECT_NEAR(result["parameters"]["mu1"]["value"].as<double>(), 0.2, 1e-7);
  EXPECT_NEAR(result["parameters"]["mu2"]["value"].as<double>(), 300.0, 1e-3);
  EXPECT_NEAR(result["parameters"]["alpha"]["value"].as<double>(), 9e8, 1e3);
  EXPECT_NEAR(result["parameters"]["omega"]["value"].as<double>(), HzToRadPerSecond(40.0), 1e-9);
}

TEST(RunIdentify, SameInputGivesTheSameFiles) {
  std::string first[2];
  for (int run = 0; run < 2; ++run) {
    const std::string out_dir = FreshDir("repeat" + std::to_string(run));
    std::ostringstream printed;
    RunIdentify(LoadIdentifyConfig(kConfig, {{"output_dir", out_dir, "--test"}}), printed);
    first[run] = ReadFile(fs::path(out_dir) / "result.yaml") +
                 ReadFile(fs::path(out_dir) / "predictions.csv");
  }
  EXPECT_EQ(first[0], first[1]);
}

TEST(RunIdentify, AnUnknownSweepFailsBeforeAnythingIsWritten) {
  const std::string out_dir = FreshDir("unknown_sweep");
  const IdentifyConfig config =
      LoadIdentifyConfig(kConfig, {{"output_dir", out_dir, "--test"}, {"fit", "[F9]", "--fit"}});
  std::ostringstream printed;
  try {
    RunIdentify(config, printed);
    FAIL() << "expected InputError";
  } catch (const InputError& error) {
    EXPECT_THAT(error.what(), HasSubstr("beam.yaml"));
    EXPECT_THAT(error.what(), HasSubstr("'fit'"));
    EXPECT_THAT(error.what(), HasSubstr("sweep 'F9' is not in the data; available: F0.01/up"));
  }
  EXPECT_FALSE(fs::exists(out_dir));
}

TEST(RunIdentify, AnUnwritableOutputDirLeavesNoPartialFile) {
  const std::string parent = FreshDir("unwritable");
  fs::create_directories(parent);
  // A regular file where the output directory should be.
  std::ofstream(parent + "/blocked") << "not a directory";
  const IdentifyConfig config =
      LoadIdentifyConfig(kConfig, {{"output_dir", parent + "/blocked/out", "--test"}});
  std::ostringstream printed;
  EXPECT_THROW(RunIdentify(config, printed), InputError);
  // The directory is checked before the data are read and the fit runs.
  EXPECT_THAT(printed.str(), Not(HasSubstr("fit ")));
  EXPECT_THAT(printed.str(), Not(HasSubstr("Ceres Solver Report")));
  for (const auto& entry : fs::recursive_directory_iterator(parent)) {
    EXPECT_EQ(entry.path().filename(), "blocked") << entry.path();
  }
}

}  // namespace
}  // namespace dwellfit
