// PredictSweep: each dwell's model amplitude, solved from the measured
// amplitude (SolveStableRootNear), is the root the full bracketing solve
// (ModelAmplitude) finds, on both bundled measured and simulated sweeps.
#include "dwellfit/estimator/analysis/sweep_prediction.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "dwellfit/config/identify_config.h"
#include "dwellfit/estimator/run/resolved_run.h"
#include "dwellfit/residuals/model/stable_root.h"

namespace dwellfit {
namespace {

// Every sweep of the dataset's config predicted at `parameters`, each dwell
// against ModelAmplitude from the same guess; returns how many dwells took
// each status.
void ExpectTheFullSolversRoots(const ResolvedRun& run, const ParameterVector& parameters,
                               int* on_branch, int* branch_end) {
  for (const Sweep& sweep : run.sweeps) {
    const SweepPrediction prediction = PredictSweep(kFirstOrderForm, parameters, sweep, false);
    ASSERT_EQ(prediction.model.size(), sweep.points.size());
    for (size_t i = 0; i < sweep.points.size(); ++i) {
      const DwellPoint& point = sweep.points[i];
      const StableRoot full =
          ModelAmplitude(kFirstOrderForm, parameters, point.drive_frequency_rad_s, point.a_base,
                         point.branch, point.amplitude);
      const StableRoot& near = prediction.model[i];
      ASSERT_EQ(near.status, full.status) << sweep.Name() << " dwell " << i;
      EXPECT_NEAR(near.a, full.a, 1e-14 * full.a) << sweep.Name() << " dwell " << i;
      *on_branch += near.status == RootStatus::kOnBranch;
      *branch_end += near.status == RootStatus::kBranchEnd;
    }
  }
}

TEST(PredictSweep, IsTheFullRootSolveOnTheMeasuredBeam) {
  const ResolvedRun run = ResolveRun(LoadIdentifyConfig(std::string(DWELLFIT_SOURCE_DIR) +
                                                        "/datasets/clamped-beam-27C/beam.yaml"));
  // At the config's start (far from most dwells: the near solve falls back
  // often) and with the nonlinearity doubled (other branches end).
  ParameterVector doubled = run.options.initial;
  doubled[kAlpha] *= 2.0;
  for (const ParameterVector& parameters : {run.options.initial, doubled}) {
    int on_branch = 0;
    int branch_end = 0;
    ExpectTheFullSolversRoots(run, parameters, &on_branch, &branch_end);
    EXPECT_GT(on_branch, 10000);
    EXPECT_GT(branch_end, 0);
  }
}

TEST(PredictSweep, IsTheFullRootSolveOnTheThesisSweepsAtTheTruth) {
  const ResolvedRun run = ResolveRun(LoadIdentifyConfig(std::string(DWELLFIT_SOURCE_DIR) +
                                                        "/datasets/thesis-numerical/beam.yaml"));
  const ParameterVector truth = {100.0, 0.2, 300.0, 1e4, 9e8, 2.0 * kPi * 40.0};
  int on_branch = 0;
  int branch_end = 0;
  ExpectTheFullSolversRoots(run, truth, &on_branch, &branch_end);
  EXPECT_GT(on_branch, 400);
  // Noise-free dwells on the truth's own branches: every one on its branch,
  // at its measured amplitude.
  EXPECT_EQ(branch_end, 0);
  for (const Sweep& sweep : run.sweeps) {
    const SweepPrediction prediction = PredictSweep(kFirstOrderForm, truth, sweep, true);
    for (size_t i = 0; i < sweep.points.size(); ++i) {
      EXPECT_NEAR(prediction.model[i].a, sweep.points[i].amplitude,
                  1e-9 * sweep.points[i].amplitude);
    }
  }
}

}  // namespace
}  // namespace dwellfit
