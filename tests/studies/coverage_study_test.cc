// The coverage study takes the path of a measured run (resolved_run.h): the
// start found from each replica's data where the config leaves it out, and
// the config's `jumps:` applied to the simulated sweeps.
#include "dwellfit/estimator/studies/coverage_study.h"

#include <cmath>
#include <fstream>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include "dwellfit/config/config_override.h"
#include "dwellfit/config/dwell_plan_reader.h"
#include "dwellfit/config/identify_config.h"
#include "dwellfit/estimator/common/input_error.h"
#include "dwellfit/estimator/data/sweep_csv_writer.h"
#include "dwellfit/estimator/fit/multi_start.h"
#include "dwellfit/estimator/run/resolved_run.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "tests/config_test_support.h"

namespace dwellfit {
namespace {

using ::testing::AllOf;
using ::testing::EndsWith;
using ::testing::HasSubstr;
using ::testing::Not;
using ::testing::StartsWith;

const std::string kDataset = std::string(DWELLFIT_SOURCE_DIR) + "/datasets/thesis-numerical";

CoverageStudy Study(const std::vector<ConfigOverride>& overrides, int replicas) {
  CoverageStudyOptions options;
  options.replicas = replicas;
  options.relative_noise = 0.01;
  options.first_seed = 1;
  return RunCoverageStudy(LoadIdentifyConfig(kDataset + "/beam.yaml", overrides),
                          ReadDwellPlan(kDataset + "/plan.yaml"), options);
}

// A new user's config: no initial guess at all (and so nothing fixed). The
// study once started every replica from the placeholders {1, 0, 0, 0, 0, 1}
// instead, and no replica had a covariance ("mu1 = 0 has no first-order
// effect"). Found from each replica's data, the start leads every fit to a
// minimum with a covariance, and the intervals cover the truth.
TEST(CoverageStudy, WithNoInitialGuessesEveryReplicaConvergesWithACovariance) {
  const CoverageStudy study = Study(ParseSetFlag("initial_guess=auto,fixed=[]", "--test"), 40);
  PrintCoverageStudy(study, std::cout);
  EXPECT_TRUE(study.start_from_data);
  EXPECT_EQ(study.converged, study.replicas);
  EXPECT_EQ(study.available, study.replicas);
  EXPECT_THAT(study.messages, ::testing::IsEmpty());
  EXPECT_NEAR(study.mean_noise_sigma, 0.01, 0.001);
  ASSERT_EQ(study.rows.size(), 7u);  // six free parameters and alpha_e
  for (const CoverageRow& row : study.rows) {
    // 40 replicas: a rate of 95 % has a binomial sd of 3.4 %.
    EXPECT_GE(row.Coverage(), 0.85) << row.name;
    EXPECT_LT(std::abs(row.mean_estimate - row.truth), 0.5 * row.empirical_std) << row.name;
  }
}

// With the bifurcation-range penalty on, the reported intervals are the
// profile's of the penalised cost, and the linearised standard errors
// beside them take the penalty's curvature (parameter_uncertainty.h).
TEST(CoverageStudy, WithThePenaltyTheIntervalsMatchTheSpreadOfTheEstimates) {
  const CoverageStudy study =
      Study(ParseSetFlag("penalties={bifurcation_range: {enabled: true}}", "--test"), 40);
  PrintCoverageStudy(study, std::cout);
  EXPECT_TRUE(study.penalty);
  EXPECT_EQ(study.method, IntervalMethod::kProfile);
  EXPECT_EQ(study.with_penalty_terms, study.replicas);
  EXPECT_EQ(study.available, study.replicas);
  ASSERT_EQ(study.rows.size(), 6u);  // five free parameters and alpha_e
  for (const CoverageRow& row : study.rows) {
    // 40 replicas: a rate of 95 % has a binomial sd of 3.4 %.
    EXPECT_GE(row.Coverage(), 0.85) << row.name;
    EXPECT_GT(row.mean_standard_error, 0.7 * row.empirical_std) << row.name;
    EXPECT_LT(row.mean_standard_error, 1.45 * row.empirical_std) << row.name;
  }
}

const std::string kSoftening = std::string(DWELLFIT_SOURCE_DIR) + "/datasets/softening-numerical";

// The softening case of docs/uncertainty.md: its file is what its plan
// simulates, every fitted sweep has its jump, and its config recovers the
// truth from the noise-free dwells.
TEST(CoverageStudy, SofteningDatasetIsItsPlansOutputAndItsConfigRecoversTheTruth) {
  const DwellPlan plan = ReadDwellPlan(kSoftening + "/plan.yaml");
  std::ostringstream simulated;
  WriteSweepsCsv(SimulateDwells(plan), &simulated);
  std::ifstream file(kSoftening + "/sweeps.csv");
  std::stringstream stored;
  stored << file.rdbuf();
  EXPECT_EQ(stored.str(), simulated.str())
      << "datasets/softening-numerical/sweeps.csv is stale; regenerate it with the command in "
         "its plan.yaml";

  const IdentifyConfig config = LoadIdentifyConfig(kSoftening + "/beam.yaml");
  const ResolvedRun run = ResolveRun(config);
  ASSERT_EQ(run.fitted.size(), 4u);
  for (const Sweep* sweep : run.fitted) EXPECT_EQ(sweep->jumps.size(), 1u) << sweep->Name();
  const IdentificationResult result = FitRun(run).best;
  EXPECT_TRUE(result.converged) << result.message;
  for (int i = 0; i < kNumParameters; ++i) {
    EXPECT_NEAR(result.parameters[i], plan.truth[i], 1e-6 * std::abs(plan.truth[i]))
        << ParameterName(i);
  }
  EXPECT_LT(EffectiveNonlinearity(plan.truth, HzToRadPerSecond(59.5)), 0.0);  // softening
}

// The config's `jumps:` label the simulated sweeps as they label measured
// ones: the stated sweep is marked [config], the others keep detection.
TEST(CoverageStudy, AppliesTheConfigsJumps) {
  const CoverageStudy study =
      Study(ParseSetFlag("jumps=[{sweep: F0.01/up, kind: jump_down, between_hz: [42.2, 42.3]}]",
                         "--test"),
            2);
  ASSERT_EQ(study.first_replica_jumps.size(), 4u);
  EXPECT_THAT(
      study.first_replica_jumps[0],
      AllOf(StartsWith("F0.01/up: jump_down between 42.20 and 42.30 Hz"), EndsWith("[config]")));
  for (size_t i = 1; i < study.first_replica_jumps.size(); ++i) {
    EXPECT_THAT(study.first_replica_jumps[i], Not(HasSubstr("[config]")));
  }
  EXPECT_EQ(study.available, study.replicas);

  // A stated jump of a sweep the plan does not simulate is the config's error.
  const InputError missing =
      ErrorOf([] { Study(ParseSetFlag("jumps=[{sweep: F0.02/down, none: true}]", "--test"), 1); });
  EXPECT_EQ(missing.field(), "jumps[0]");
  EXPECT_THAT(missing.what(), HasSubstr("sweep 'F0.02/down' is not in the data; available: "
                                        "F0.01/up, F0.01/down"));
  // A bracket across a dwell, as for measured data.
  const InputError across = ErrorOf([] {
    Study(ParseSetFlag("jumps=[{sweep: F0.01/up, kind: jump_down, between_hz: [42.1, 42.3]}]",
                       "--test"),
          1);
  });
  EXPECT_THAT(across.what(), HasSubstr("does not lie between two consecutive dwells"));
}

}  // namespace
}  // namespace dwellfit
