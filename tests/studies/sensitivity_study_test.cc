#include "dwellfit/estimator/studies/sensitivity_study.h"

#include <filesystem>
#include <sstream>
#include <string>

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
