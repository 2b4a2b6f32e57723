#include "dwellfit/estimator/studies/sensitivity_study.h"

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "dwellfit/config/dwell_plan_reader.h"
#include "dwellfit/estimator/common/input_error.h"
#include "dwellfit/estimator/run/output_files.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"

namespace dwellfit {
namespace {

namespace fs = std::filesystem;
const std::string kThesis = std::string(DWELLFIT_SOURCE_DIR) + "/datasets/thesis-numerical/";

SensitivityOptions NoiseStudy(int replicas) {
  SensitivityOptions options;
  options.config_path = kThesis + "beam.yaml";
  options.plan = ReadDwellPlan(kThesis + "plan.yaml");
  options.replicas = replicas;
  options.noise = 0.01;
  options.first_seed = 11;
  return options;
}

TEST(SensitivityStudy, FitsCsvIsTheSameForOneAndTwoThreads) {
  SensitivityOptions options = NoiseStudy(8);
  options.threads = 1;
  const SensitivityStudy one = RunSensitivityStudy(options);
  options.threads = 2;
  const SensitivityStudy two = RunSensitivityStudy(options);
  EXPECT_EQ(FitsToCsv(one), FitsToCsv(two));
  EXPECT_EQ(SummaryToYaml(one), SummaryToYaml(two));
  ASSERT_EQ(one.rows.size(), 8u);
  for (const FitRow& row : one.rows) {
    EXPECT_EQ(row.status, "converged");
    EXPECT_EQ(row.seed, 11u + row.replica);
    EXPECT_NEAR(row.estimate[kEtaE], 100.0, 1.0);  // 1 % noise: eta_e within 1 %
    EXPECT_GT(row.standard_error[kEtaE], 0.0);
    EXPECT_EQ(row.estimate[kNaturalFrequency], 40.0);  // fixed, in Hz
  }
  // Replicas differ (each its own noise).
  EXPECT_NE(one.rows[0].estimate[kAlpha], one.rows[1].estimate[kAlpha]);
}

// A one-axis study: each fit's dof is the dwells fitted less the free
// parameters (the thesis plan's dwells; omega fixed, five free), the profile
// figure draws the 95 % threshold F_min (1 + 3.84 / dof) of the best fit and
// marks fits by status, and report.html holds the summary and the figures.
TEST(SensitivityStudy, TheProfileDrawsTheThresholdAndTheReportTheSummary) {
  SensitivityOptions options = NoiseStudy(2);
  options.threads = 2;
  options.vary = ParseVaryFlag("initial_guess.delta=8000|12000", "--vary");
  const SensitivityStudy study = RunSensitivityStudy(options);
  int fitted = 0;  // the dwells of the config's fit sweeps, F0.01 and A41.5
  for (const SweepPlan& sweep : options.plan->sweeps) {
    if (sweep.id == "F0.01" || sweep.id == "A41.5") {
      fitted += static_cast<int>(sweep.directions.size()) * (sweep.NumSteps() + 1);
    }
  }
  const FitRow* best = &study.rows[0];
  for (const FitRow& row : study.rows) {
    EXPECT_EQ(row.status, "converged");
    if (row.cost < best->cost) best = &row;
  }
  std::ostringstream warnings;
  const std::vector<std::pair<std::string, std::string>> files = StudyFiles(study, true, warnings);
  std::string script, html;
  for (const auto& [name, content] : files) {
    if (name == "figures.gp") script = content;
    if (name == "report.html") html = content;
  }
  for (const FitRow& row : study.rows) EXPECT_EQ(row.dof, fitted - 5);  // k = 5: omega fixed
  char threshold[64];
  std::snprintf(threshold, sizeof(threshold), "%.17g with lines",
                best->cost * (1.0 + 3.841458820694124 / best->dof));
  EXPECT_THAT(script, ::testing::HasSubstr(threshold));
  EXPECT_THAT(script, ::testing::HasSubstr("title \"95 % threshold\""));
  EXPECT_THAT(script, ::testing::HasSubstr("title \"failed\""));
  EXPECT_THAT(html, ::testing::HasSubstr("<table id=\"summary\">"));
  EXPECT_THAT(html, ::testing::HasSubstr("initial_guess.delta = 12000"));
  EXPECT_THAT(html, ::testing::HasSubstr("<figcaption>profile.svg</figcaption>"));
  EXPECT_THAT(html, ::testing::HasSubstr("<figcaption>histograms.svg</figcaption>"));
}

TEST(SensitivityStudy, FourMergedShardsEqualOneRun) {
  SensitivityOptions options = NoiseStudy(6);
  options.threads = 2;
  options.vary = ParseVaryFlag("residual.error=relative|absolute", "--vary");
  const SensitivityStudy whole = RunSensitivityStudy(options);
  ASSERT_EQ(whole.rows.size(), 12u);
  std::vector<std::string> folders;
  for (int k = 0; k < 4; ++k) {
    options.shard = k;
    options.shards = 4;
    const SensitivityStudy shard = RunSensitivityStudy(options);
    EXPECT_EQ(shard.rows.size(), 3u);
    const fs::path folder =
        fs::path(::testing::TempDir()) / ("sensitivity_shard" + std::to_string(k));
    fs::remove_all(folder);
    std::ostringstream warnings;
    WriteFilesAtomically(folder.string(), StudyFiles(shard, false, warnings));
    folders.push_back(folder.string());
  }
  std::reverse(folders.begin(), folders.end());  // any order
  const SensitivityStudy merged = MergeShards(folders);
  EXPECT_EQ(FitsToCsv(merged), FitsToCsv(whole));
  EXPECT_EQ(SummaryToYaml(merged), SummaryToYaml(whole));
  folders.pop_back();
  EXPECT_THROW(MergeShards(folders), InputError);  // a shard missing
}

// Shards of two studies that differ in one setting do not merge; neither do
// shards with a fit given twice. A CRLF fits.csv merges like its LF original.
TEST(SensitivityStudy, ShardsOfAnotherStudyOrWithAFitTwiceAreRefused) {
  const auto write_shard = [](SensitivityOptions options, int k, const std::string& name) {
    options.shard = k;
    options.shards = 2;
    const fs::path folder = fs::path(::testing::TempDir()) / name;
    fs::remove_all(folder);
    std::ostringstream warnings;
    WriteFilesAtomically(folder.string(),
                         StudyFiles(RunSensitivityStudy(options), false, warnings));
    return folder.string();
  };
  const auto refusal = [](const std::vector<std::string>& folders) {
    try {
      MergeShards(folders);
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  const SensitivityOptions base = NoiseStudy(2);
  const std::string first = write_shard(base, 0, "fingerprint_shard0");
  for (const auto& [name, change] :
       std::vector<std::pair<std::string, std::function<void(SensitivityOptions*)>>>{
           {"noise", [](SensitivityOptions* o) { o->noise = 0.02; }},
           {"seed", [](SensitivityOptions* o) { o->first_seed = 12; }},
           {"set",
            [](SensitivityOptions* o) {
              o->overrides = {{"solver.max_iterations", "77", "--set"}};
            }},
           {"plan", [](SensitivityOptions* o) { o->plan->truth[kMu1] *= 1.01; }}}) {
    SensitivityOptions other = base;
    change(&other);
    EXPECT_THAT(refusal({first, write_shard(other, 1, "fingerprint_" + name)}),
                ::testing::HasSubstr("the shards were run with other settings"))
        << name;
  }
  const std::string second = write_shard(base, 1, "fingerprint_shard1");
  EXPECT_EQ(MergeShards({first, second}).rows.size(), 2u);
  // The second shard's fits.csv with a CRLF line end merges the same.
  std::string text;
  {
    std::ifstream in(fs::path(second) / "fits.csv");
    text.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  }
  std::string crlf;
  for (char c : text) crlf += c == '\n' ? std::string("\r\n") : std::string(1, c);
  std::ofstream(fs::path(second) / "fits.csv", std::ios::binary | std::ios::trunc) << crlf;
  EXPECT_EQ(FitsToCsv(MergeShards({first, second})), FitsToCsv(RunSensitivityStudy(base)));
  // The first shard's fit row again in the second's file.
  const std::string first_rows = [&] {
    std::ifstream in(fs::path(first) / "fits.csv");
    std::string header, row;
    std::getline(in, header);
    std::getline(in, row);
    return row;
  }();
  std::ofstream(fs::path(second) / "fits.csv", std::ios::app) << first_rows << "\n";
  EXPECT_THAT(refusal({first, second}), ::testing::HasSubstr("fit 0 is given twice"));
}

TEST(SensitivityStudy, AStudyTooLargeForOneRunIsRefusedBeforeItStarts) {
  SensitivityOptions options = NoiseStudy(2147483647);
  options.vary = ParseVaryFlag("residual.error=relative|absolute", "--vary");
  try {
    RunSensitivityStudy(options);
    ADD_FAILURE() << "2 x (2^31 - 1) fits were accepted";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), ::testing::HasSubstr("2 cases x 2147483647 replicas = 4294967294 fits"));
  }
}

// A profile: delta fixed on a grid; the cost is lowest at the truth.
TEST(SensitivityStudy, ProfilesAFixedParameterOnTheConfigsData) {
  SensitivityOptions options;
  options.config_path = kThesis + "beam.yaml";
  options.overrides = {{"fixed", "[omega, delta]", "--set"}};
  options.vary = ParseVaryFlag("initial_guess.delta=5000|10000|15000", "--vary");
  options.threads = 2;
  const SensitivityStudy study = RunSensitivityStudy(options);
  ASSERT_EQ(study.rows.size(), 3u);
  EXPECT_EQ(study.rows[0].settings, std::vector<std::string>{"5000"});
  EXPECT_EQ(study.rows[1].estimate[kDelta], 10000.0);
  EXPECT_LT(study.rows[1].cost, 1e-20);  // noise-free data at the true delta
  EXPECT_GT(study.rows[0].cost, 1e3 * study.rows[1].cost);
  EXPECT_GT(study.rows[2].cost, 1e3 * study.rows[1].cost);
  EXPECT_THAT(FitsToCsv(study), ::testing::HasSubstr(",initial_guess.delta,status,"));
}

TEST(SensitivityStudy, RejectsBadFlags) {
  EXPECT_THROW(ParseVaryFlag("no_equals", "--vary"), InputError);
  EXPECT_THROW(ParseVaryFlag("a=1||2", "--vary"), InputError);
  EXPECT_THROW(ParseVaryFlag("a=1;a=2", "--vary"), InputError);
  const auto axes = ParseVaryFlag("fit=[F0.01, A41.5]|[F0.01]; solver.max_iterations=5", "--vary");
  ASSERT_EQ(axes.size(), 2u);
  EXPECT_EQ(axes[0].values[0], "[F0.01, A41.5]");
  SensitivityOptions options;
  options.config_path = kThesis + "beam.yaml";
  options.replicas = 3;  // replicas need a plan
  EXPECT_THROW(RunSensitivityStudy(options), InputError);
}

}  // namespace
}  // namespace dwellfit
