// The rig one dwell at a time: each dwell continues from the motion the
// previous one ended in, so the path decides the branch, as on a real rig.
#include <cmath>
#include <vector>

#include "dwellfit/estimator/common/input_error.h"
#include "dwellfit/estimator/rig/rig_simulator.h"
#include "dwellfit/residuals/model/stable_root.h"
#include "gtest/gtest.h"

namespace dwellfit {
namespace {

// Table 3.1 (docs/model.md).
const ParameterVector kTruth = {100.0, 0.2, 300.0, 1e4, 9e8, HzToRadPerSecond(40.0)};

RigOptions ShortRig() {
  RigOptions rig;
  rig.sample_rate_hz = 1024.0;
  rig.record_periods = 4;
  rig.settle_window_periods = 20;
  rig.settle_tolerance = 1e-4;
  rig.integration_tolerance = 1e-8;
  return rig;
}

double ModelRoot(double f_hz, double a_base, Branch branch) {
  return ModelAmplitude(kFirstOrderForm, kTruth, HzToRadPerSecond(f_hz), a_base, branch, 0.0).a;
}

// Stepped up in frequency at level 0.01 the response climbs the upper branch
// (at 42 Hz, inside the hysteresis range, the model's upper root 0.00451);
// started from rest at 42 Hz it settles on the lower root (0.00031). Each
// settled amplitude is the model's fixed point within 1 % (the first-order
// averaging's error, docs/model.md), and the rig's clock is the sum of the
// dwells' settling and recording periods.
TEST(VirtualRig, EachDwellContinuesFromTheLastSoThePathPicksTheBranch) {
  VirtualRig rig(kTruth, ShortRig());
  double seconds = 0.0;
  RigDwell last;
  for (double f_hz : {40.6, 41.0, 41.4, 41.8, 42.0}) {
    last = rig.Dwell(f_hz, 0.01);
    EXPECT_TRUE(last.truth.settled) << f_hz;
    seconds += (last.truth.settle_periods + 4) / f_hz;
    EXPECT_NEAR(last.settle_seconds, last.truth.settle_periods / f_hz, 1e-12);
  }
  const double upper = ModelRoot(42.0, 0.01, Branch::kUpper);
  EXPECT_NEAR(last.truth.amplitude, upper, 0.01 * upper);
  EXPECT_NEAR(rig.elapsed_seconds(), seconds, 1e-9 * seconds);
  EXPECT_NEAR(rig.motion().amplitude, last.truth.amplitude, 1e-15);
  EXPECT_EQ(last.trace.base.size(), last.trace.response.size());

  rig.Rest();
  const RigDwell from_rest = rig.Dwell(42.0, 0.01, "rest");
  const double lower = ModelRoot(42.0, 0.01, Branch::kLower);
  EXPECT_NEAR(from_rest.truth.amplitude, lower, 0.01 * lower);
  EXPECT_EQ(from_rest.trace.sweep, "rest");
  // A jump onto the other branch settles longer than a small step along one.
  EXPECT_GT(from_rest.settle_seconds, 0.0);
}

TEST(VirtualRig, ASampleRateTooLowForTheDwellIsRefused) {
  RigOptions options = ShortRig();
  options.sample_rate_hz = 200.0;  // 5 samples per period at 40 Hz
  VirtualRig rig(kTruth, options);
  EXPECT_THROW(rig.Dwell(40.0, 0.01), InputError);
  options.record_periods = 0;
  EXPECT_THROW(VirtualRig(kTruth, options), InputError);
}

}  // namespace
}  // namespace dwellfit
