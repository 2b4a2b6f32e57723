// Hostile input end to end: a run of `identify` (RunIdentify) on data or a
// config built to break it either stops with a message naming the file, the
// line and the field and saying what to do, and writes nothing, or gives a
// usable result. The loaders' own rows are in sweep_csv_test.cc,
// identify_config_test.cc and config_override_test.cc; docs/troubleshooting.md
// lists the messages.
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "dwellfit/config/identify_config.h"
#include "dwellfit/estimator/common/input_error.h"
#include "dwellfit/estimator/data/sweep_csv.h"
#include "dwellfit/estimator/fit/identification.h"
#include "dwellfit/estimator/run/identify_run.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "yaml-cpp/yaml.h"

namespace dwellfit {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;
using ::testing::StartsWith;

const std::string kThesis = std::string(DWELLFIT_SOURCE_DIR) + "/datasets/thesis-numerical";

std::string ReadFile(const fs::path& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

// A fresh directory for one test, with the thesis sweeps as lines to edit.
class HostileInput : public ::testing::Test {
 protected:
  void SetUp() override {
    const testing::TestInfo* test = testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::path(testing::TempDir()) / "dwellfit_hostile" / test->name();
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    std::istringstream sweeps(ReadFile(kThesis + "/sweeps.csv"));
    for (std::string line; std::getline(sweeps, line);) lines_.push_back(line);
  }

  // Writes the (edited) sweeps to `name` in the directory; returns the path.
  std::string WriteSweeps(const std::vector<std::string>& lines,
                          const std::string& name = "sweeps.csv") const {
    std::ofstream out(dir_ / name);
    for (const std::string& line : lines) out << line << "\n";
    return (dir_ / name).string();
  }

  // The thesis config (beam.yaml) reading `data` and writing into out/, with
  // `overrides` on top.
  IdentifyConfig Config(const std::string& data, std::vector<ConfigOverride> overrides = {},
                        const std::string& out = "out") const {
    overrides.insert(overrides.begin(),
                     {{"data", data, "--test"}, {"output_dir", (dir_ / out).string(), "--test"}});
    return LoadIdentifyConfig(kThesis + "/beam.yaml", overrides);
  }

  // The InputError RunIdentify throws; fails when it throws none, or when it
  // left an output directory behind.
  InputError RunError(const IdentifyConfig& config) const {
    std::ostringstream printed;
    try {
      RunIdentify(config, printed);
      ADD_FAILURE() << "no InputError thrown";
    } catch (const InputError& error) {
      EXPECT_FALSE(fs::exists(dir_ / "out")) << "a failed run wrote output";
      return error;
    }
    return InputError("none");
  }

  fs::path dir_;
  std::vector<std::string> lines_;  // the thesis sweeps.csv, header first
};

TEST_F(HostileInput, AHugeAmplitudeStopsTheRunNamingRowAndColumn) {
  // Before: a = 1e308 gave final_cost -1 and the start reported as the estimate.
  std::vector<std::string> lines = lines_;
  lines[6] = "F0.01,up,38.5,0.01,1e308,0.02";
  const std::string data = WriteSweeps(lines);
  const InputError error = RunError(Config(data));
  EXPECT_EQ(error.file(), data);
  EXPECT_EQ(error.line(), 7);
  EXPECT_EQ(error.field(), "a");
  EXPECT_THAT(error.what(), HasSubstr("the amplitude a 1e308 is outside the accepted range"));
}

TEST_F(HostileInput, ASubnormalFrequencyStopsTheRun) {
  // Before: a garbage fit marked converged.
  std::vector<std::string> lines = lines_;
  lines[6] = "F0.01,up,1e-320,0.01,0.0004,0.02";
  const InputError error = RunError(Config(WriteSweeps(lines)));
  EXPECT_EQ(error.line(), 7);
  EXPECT_EQ(error.field(), "freq_hz");
  EXPECT_THAT(error.what(), HasSubstr("freq_hz is in Hz"));
}

TEST_F(HostileInput, AFileAppendedToItselfIsAnErrorNotAWrongFit) {
  // Before: a wrong-sign alpha marked converged, with a jump at the wrap-around.
  std::vector<std::string> lines = lines_;
  lines.insert(lines.end(), lines_.begin() + 1, lines_.end());
  const InputError error = RunError(Config(WriteSweeps(lines)));
  EXPECT_EQ(error.line(), static_cast<int>(lines_.size()) + 1);  // the first copied row
  EXPECT_EQ(error.field(), "freq_hz");
  EXPECT_THAT(error.what(),
              HasSubstr("sweep 'F0.01/up' is an up-sweep, but freq_hz falls from 46 (line 82) "
                        "to 38; rows must be in measurement order"));
}

TEST_F(HostileInput, AReversedFileIsAnError) {
  std::vector<std::string> lines = {lines_[0]};
  lines.insert(lines.end(), lines_.rbegin(), lines_.rend() - 1);
  const InputError error = RunError(Config(WriteSweeps(lines)));
  EXPECT_EQ(error.line(), 3);
  EXPECT_EQ(error.field(), "a_base");
  EXPECT_THAT(error.what(), HasSubstr("sweep 'A41.8/down' is a down-sweep, but a_base rises"));
}

TEST_F(HostileInput, EveryRowTwiceIsAnError) {
  std::vector<std::string> lines = {lines_[0]};
  for (std::size_t i = 1; i < lines_.size(); ++i) lines.insert(lines.end(), 2, lines_[i]);
  const InputError error = RunError(Config(WriteSweeps(lines)));
  EXPECT_EQ(error.line(), 3);
  EXPECT_THAT(error.what(), HasSubstr("row repeats line 2 value for value (sweep 'F0.01/up')"));
}

TEST_F(HostileInput, AOnePointSweepCannotBeFittedAlone) {
  // Before: six parameters fitted to one dwell, "converged", result written.
  std::vector<std::string> lines = lines_;
  lines.push_back("ONE,up,40,0.01,0.001,1.5");
  const InputError error = RunError(Config(WriteSweeps(lines), {{"fit", "[ONE]", "--fit"}}));
  EXPECT_EQ(error.file(), kThesis + "/beam.yaml");
  EXPECT_EQ(error.field(), "fit");
  EXPECT_THAT(error.what(),
              HasSubstr("the fitted sweeps hold 1 measured dwell(s) (ONE/up (1)) for 5 free "
                        "parameters; a fit needs more dwells than free parameters: fit more "
                        "sweeps, or fix parameters"));
}

TEST_F(HostileInput, AStartWhereTheCostCannotBeEvaluatedFailsWithoutAResult) {
  // Before: final_cost -1, RMS -nan, the start reported as the estimate, exit 0.
  const InputError error =
      RunError(Config(WriteSweeps(lines_), {{"initial_guess.alpha", "1e300", "--set"}}));
  EXPECT_EQ(error.field(), "initial_guess");
  EXPECT_THAT(error.what(),
              HasSubstr("the fit cannot proceed: the algebraic stage cannot evaluate its cost at "
                        "eta_e 130, mu1 0.14, mu2 390, delta 7000, alpha 1e+300, omega 251.327 "
                        "rad/s: no dwell's residual is finite there, so the parameters are at "
                        "fault"));
  EXPECT_THAT(error.what(), HasSubstr("give initial guesses closer to the data"));
}

TEST_F(HostileInput, AFailedStageEndsTheFitWithItsFailure) {
  LoadedSweeps loaded = LoadSweepsCsv(WriteSweeps(lines_));
  std::vector<const Sweep*> fitted = {&loaded.sweeps[0]};
  IdentificationOptions options;
  options.initial = {100.0, 0.2, 300.0, 1e4, 9e8, HzToRadPerSecond(40.0)};
  options.initial[kMu2] = 1e300;
  const IdentificationResult result = Identify(fitted, options);
  ASSERT_EQ(result.stages.size(), 1u);  // the vertical stage did not run
  EXPECT_FALSE(result.converged);
  EXPECT_EQ(result.status, FitStatus::kFailure);
  EXPECT_FALSE(result.IsSolutionUsable());
  EXPECT_THAT(result.message, StartsWith("the algebraic stage cannot evaluate its cost at"));
}

TEST_F(HostileInput, AFailedStartIsNeverTheBest) {
  // Before: a failed start's cost (Ceres' -1) beat every other start.
  LoadedSweeps loaded = LoadSweepsCsv(WriteSweeps(lines_));
  std::vector<const Sweep*> fitted = {&loaded.sweeps[0]};
  IdentificationOptions options;
  options.initial = {130.0, 0.14, 390.0, 7e3, 1e300, HzToRadPerSecond(40.0)};
  options.fixed[kNaturalFrequency] = true;
  const ParameterVector reachable = {130.0, 0.14, 390.0, 7e3, 1.17e9, HzToRadPerSecond(40.0)};
  MultiStartOptions multi_start;
  multi_start.starts = 2;
  const MultiStartResult result = IdentifyMultiStart(fitted, options, reachable, multi_start);
  EXPECT_EQ(result.failed, 1);
  EXPECT_EQ(result.best_start, 1);
  EXPECT_TRUE(result.best.IsSolutionUsable()) << result.best.message;
  EXPECT_GT(result.best.final_cost, 0.0);
  EXPECT_EQ(result.reached_best, 1);

  multi_start.starts = 1;  // start 0 alone: the failure is the result
  const MultiStartResult alone = IdentifyMultiStart(fitted, options, reachable, multi_start);
  EXPECT_EQ(alone.failed, 1);
  EXPECT_EQ(alone.best.status, FitStatus::kFailure);
  EXPECT_THAT(alone.best.message, HasSubstr("alpha 1e+300"));
}

TEST_F(HostileInput, ResultFilesAreByteIdenticalAcrossThreadCounts) {
  const std::string data = WriteSweeps(lines_);
  std::string files[2];
  for (int run = 0; run < 2; ++run) {
    const std::string out = "out" + std::to_string(run);
    std::ostringstream printed;
    RunIdentify(
        Config(data,
               {{"solver.num_threads", run == 0 ? "1" : "3", "--set"},
                {"multi_start", run == 0 ? "{starts: 3, threads: 1}" : "{starts: 3, threads: 2}",
                 "--set"}},
               out),
        printed);
    // Every file. This case (260 fitted dwells) is too small for the
    // library to share a fit's work among threads; what runs on two
    // threads here is the multi-start's three starts. The measured beam
    // below checks a case large enough to thread.
    for (const char* name : {"result.yaml", "predictions.csv", "curves.csv", "figures.gp"}) {
      const std::string text = ReadFile(dir_ / out / name);
      EXPECT_FALSE(text.empty()) << name;
      files[run] += text;
    }
  }
  EXPECT_FALSE(files[0].empty());
  EXPECT_EQ(files[0], files[1]);
}

// The measured beam (4096 fitted dwells, 24,226 in all): large enough for
// the library to share the fit's residuals, and the covariance, predictions
// and curves after it, among two threads. Whatever the library chooses,
// every result file must be the same byte for byte as on one thread.
TEST_F(HostileInput, MeasuredBeamFilesAreByteIdenticalOnOneAndTwoThreads) {
  const std::string beam = std::string(DWELLFIT_SOURCE_DIR) + "/datasets/clamped-beam-27C";
  std::string files[2];
  IdentifyRunOptions run_options;
  run_options.render_figures = false;
  for (int run = 0; run < 2; ++run) {
    const fs::path out = dir_ / ("out" + std::to_string(run));
    const IdentifyConfig config = LoadIdentifyConfig(
        beam + "/beam.yaml", {{"output_dir", out.string(), "--test"},
                              {"solver.num_threads", run == 0 ? "1" : "2", "--set"}});
    std::ostringstream printed;
    const auto outcome = RunIdentify(config, printed, run_options);
    ASSERT_EQ(outcome->report.result.status, FitStatus::kConverged)
        << outcome->report.result.message;
    for (const char* name : {"result.yaml", "predictions.csv", "curves.csv"}) {
      const std::string text = ReadFile(out / name);
      EXPECT_FALSE(text.empty()) << name;
      files[run] += text;
    }
  }
  // The files hold the fit: predictions of every level and its curves.
  EXPECT_THAT(files[0], HasSubstr("L0.095g,up,validation"));
  EXPECT_EQ(files[0], files[1]);
}

TEST_F(HostileInput, AbsurdThreadCountsAreBoundedByTheWork) {
  // Threads are capped by the dwells and the starts, so 2^31 - 1 is harmless
  // and the result the same as on one thread.
  const std::string data = WriteSweeps(lines_);
  std::string files[2];
  for (int run = 0; run < 2; ++run) {
    const std::string threads = run == 0 ? "1" : "2147483647";
    const std::string out = "out" + std::to_string(run);
    std::ostringstream printed;
    RunIdentify(Config(data,
                       {{"solver.num_threads", threads, "--set"},
                        {"multi_start", "{starts: 2, threads: " + threads + "}", "--set"}},
                       out),
                printed);
    files[run] = ReadFile(dir_ / out / "result.yaml");
  }
  EXPECT_FALSE(files[0].empty());
  EXPECT_EQ(files[0], files[1]);
}

}  // namespace
}  // namespace dwellfit
