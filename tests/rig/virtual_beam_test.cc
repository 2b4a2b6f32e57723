// End to end on datasets/virtual-beam: the committed time traces through
// process_traces' path, then identify's path and harmonic balance, against
// the truth of Table 3.1 with 0.5 % noise.
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>

#include "dwellfit/config/identify_config.h"
#include "dwellfit/config/rig_config_reader.h"
#include "dwellfit/estimator/analysis/parameter_uncertainty.h"
#include "dwellfit/estimator/data/sweep_csv_writer.h"
#include "dwellfit/estimator/run/resolved_run.h"
#include "dwellfit/estimator/traces/harmonic_balance.h"
#include "dwellfit/estimator/traces/trace_processing.h"
#include "gtest/gtest.h"

namespace dwellfit {
namespace {

const std::string kDataset = std::string(DWELLFIT_SOURCE_DIR) + "/datasets/virtual-beam";
const ParameterVector kTruth = {100.0, 0.2, 300.0, 1e4, 9e8, HzToRadPerSecond(40.0)};

double TrueEffectiveNonlinearity(double omega_ref) {
  return kTruth[kAlpha] - 2.0 / 3.0 * kTruth[kDelta] * omega_ref * omega_ref;
}

// The traces are processed once for the suite.
class VirtualBeam : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    rig_ = new RigConfig(ReadRigConfig(kDataset + "/rig.yaml"));
    processed_ =
        new ProcessedTraces(ProcessTraces(ReadTraceSet(kDataset + "/traces"), rig_->processing));
  }
  static void TearDownTestSuite() {
    delete rig_;
    delete processed_;
  }
  static RigConfig* rig_;
  static ProcessedTraces* processed_;
};

RigConfig* VirtualBeam::rig_ = nullptr;
ProcessedTraces* VirtualBeam::processed_ = nullptr;

// process_traces writes each level's standard deviation (a_base_sigma) as
// the last column, which the committed file predates: the written file less
// that column is the committed one, byte for byte.
TEST_F(VirtualBeam, ProcessingTheCommittedTracesGivesTheCommittedSweepsWithoutWarnings) {
  EXPECT_TRUE(processed_->warnings.empty()) << processed_->warnings.front();
  std::ostringstream written;
  WriteSweepsCsv(processed_->sweeps, &written);
  std::ifstream file(kDataset + "/sweeps.csv");
  std::stringstream committed;
  committed << file.rdbuf();
  std::istringstream lines(written.str());
  std::string line, without_level_sigma;
  for (int i = 0; std::getline(lines, line); ++i) {
    const std::size_t comma = line.rfind(',');
    ASSERT_NE(comma, std::string::npos) << line;
    const std::string last = line.substr(comma + 1);
    if (i == 0) {
      EXPECT_EQ(last, "a_base_sigma");
    } else {
      EXPECT_GT(std::strtod(last.c_str(), nullptr), 0.0) << line;
    }
    without_level_sigma += line.substr(0, comma) + "\n";
  }
  EXPECT_EQ(without_level_sigma, committed.str()) << "run datasets/virtual-beam/regenerate.sh";
}

TEST_F(VirtualBeam, IdentifyRecoversEtaAndTheEffectiveNonlinearityAndCoversTheDamping) {
  const IdentifyConfig config = LoadIdentifyConfig(kDataset + "/beam.yaml");
  const ResolvedRun run = ResolveRun(config, processed_->sweeps);
  const MultiStartResult fit = FitRun(run);
  ASSERT_TRUE(fit.best.converged);
  const ParameterVector& p = fit.best.parameters;
  const double omega_ref = HzToRadPerSecond(41.5);
  const ParameterUncertainty u = EstimateUncertainty(run.fitted, run.options, p, omega_ref);
  ASSERT_TRUE(u.available) << u.message;
  EXPECT_NEAR(p[kEtaE] / kTruth[kEtaE], 1.0, 0.01);
  EXPECT_NEAR(u.effective_nonlinearity / TrueEffectiveNonlinearity(omega_ref), 1.0, 0.01);
  for (ParameterIndex i : {kMu1, kMu2}) {
    EXPECT_LE(u.ci95_low[i], kTruth[i]) << ParameterName(i);
    EXPECT_GE(u.ci95_high[i], kTruth[i]) << ParameterName(i);
  }
}

TEST_F(VirtualBeam, HarmonicBalanceRecoversEtaOmegaAndTheEffectiveNonlinearity) {
  const double omega_ref = HzToRadPerSecond(41.5);
  const HarmonicBalanceResult result =
      IdentifyHarmonicBalance(processed_->harmonics, rig_->processing.harmonics, omega_ref);
  EXPECT_NEAR(result.estimate[kEtaE] / kTruth[kEtaE], 1.0, 0.01);
  EXPECT_NEAR(result.estimate[kNaturalFrequency] / kTruth[kNaturalFrequency], 1.0, 0.01);
  EXPECT_NEAR(result.effective_nonlinearity / TrueEffectiveNonlinearity(omega_ref), 1.0, 0.01);
}

}  // namespace
}  // namespace dwellfit
