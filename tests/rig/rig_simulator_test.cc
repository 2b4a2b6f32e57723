// The virtual rig against the model: jumps at the folds, phases through the
// channel corrections, settling, and harmonic balance on its traces.
#include "dwellfit/estimator/rig/rig_simulator.h"

#include <cmath>
#include <iostream>
#include <string>
#include <vector>

#include "dwellfit/estimator/common/input_error.h"
#include "dwellfit/estimator/traces/harmonic_balance.h"
#include "dwellfit/estimator/traces/trace_processing.h"
#include "dwellfit/residuals/model/fold_point.h"
#include "dwellfit/residuals/model/stable_root.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"

namespace dwellfit {
namespace {

using ::testing::HasSubstr;

// Table 3.1 (docs/model.md).
const ParameterVector kTruth = {100.0, 0.2, 300.0, 1e4, 9e8, HzToRadPerSecond(40.0)};

SweepPlan FrequencySweep(const std::string& id, double a_base, double from, double to, double step,
                         std::vector<SweepDirection> directions) {
  SweepPlan sweep;
  sweep.id = id;
  sweep.kind = SweepKind::kFrequency;
  sweep.held_a_base = a_base;
  sweep.from = from;
  sweep.to = to;
  sweep.step = step;
  sweep.directions = directions;
  return sweep;
}

SweepPlan AmplitudeSweep(const std::string& id, double f_hz, double from, double to, double step,
                         std::vector<SweepDirection> directions) {
  SweepPlan sweep = FrequencySweep(id, 0.0, from, to, step, directions);
  sweep.kind = SweepKind::kAmplitude;
  sweep.held_frequency_hz = f_hz;
  return sweep;
}

// Short records at a modest rate: the tests stay fast.
RigOptions ShortRig() {
  RigOptions rig;
  rig.sample_rate_hz = 1024.0;
  rig.record_periods = 4;
  rig.settle_window_periods = 20;
  rig.integration_tolerance = 1e-8;
  return rig;
}

// The control after which the largest amplitude step of `sweep` happens.
double JumpControlBefore(const Sweep& sweep, double* after) {
  double largest = 0.0;
  double before = 0.0;
  for (std::size_t i = 0; i + 1 < sweep.points.size(); ++i) {
    const double step =
        std::abs(std::log(sweep.points[i + 1].amplitude / sweep.points[i].amplitude));
    if (step <= largest) continue;
    largest = step;
    before = sweep.Control(sweep.points[i]);
    *after = sweep.Control(sweep.points[i + 1]);
  }
  return before;
}

// An up and down frequency sweep through the bistable band and an amplitude
// sweep up through the jump-up, each started from rest below the bistable
// band (from rest inside it the response may land on either branch): the first dwell after each
// simulated jump lies within one control step of the model's fold (fold_point.h). (The integrated
// upper branch ends a little before the first-order model's: at 0.2 Hz steps F0.01/up drops
// between 42.0 and 42.2 Hz, the model's fold is 42.215 Hz.)
TEST(RigSimulator, JumpsHappenWithinOneStepOfTheModelsFolds) {
  DwellPlan plan;
  plan.truth = kTruth;
  plan.sweeps = {
      FrequencySweep("F0.01", 0.01, 40.4, 42.4, 0.2, {SweepDirection::kUp, SweepDirection::kDown}),
      AmplitudeSweep("A41.5", 41.5, 0.004, 0.040, 0.002, {SweepDirection::kUp})};
  RigOptions rig = ShortRig();
  rig.settle_tolerance = 1e-3;  // enough to tell the branches apart, and fast
  const RigRun run = SimulateRig(plan, rig);
  for (const RigDwellTruth& truth : run.dwell_truth) EXPECT_TRUE(truth.settled);
  ASSERT_EQ(run.truth.size(), 3u);
  struct Expected {
    JumpKind kind;
    double step;
  };
  const Expected expected[] = {{JumpKind::kJumpDown, HzToRadPerSecond(0.2)},
                               {JumpKind::kJumpUp, HzToRadPerSecond(0.2)},
                               {JumpKind::kJumpUp, 0.002}};
  for (int s = 0; s < 3; ++s) {
    const Sweep& sweep = run.truth[s];
    double after = 0.0;
    const double before = JumpControlBefore(sweep, &after);
    FoldPoint fold;
    if (sweep.kind == SweepKind::kFrequency) {
      fold = SolveFrequencyFold(kFirstOrderForm, kTruth.data(), 0.01, expected[s].kind,
                                0.5 * (before + after), HzToRadPerSecond(0.01));
    } else {
      fold = SolveAmplitudeFold(kFirstOrderForm, kTruth.data(), HzToRadPerSecond(41.5),
                                expected[s].kind);
    }
    ASSERT_TRUE(fold.exists) << sweep.Name();
    // The first dwell after the jump lies within one control step of the fold.
    std::cout << "  " << sweep.Name() << ": jump between " << before << " and " << after
              << ", model fold " << fold.control << "\n";
    EXPECT_LE(std::abs(after - fold.control), expected[s].step) << sweep.Name();
  }
}

// The model's lag gamma = atan2(P(a), Q(a)) at the model's amplitude.
double ModelLag(double omega, double a_base, double a_guess) {
  const StableRoot root =
      ModelAmplitude(kFirstOrderForm, kTruth, omega, a_base, Branch::kOnly, a_guess);
  const auto k =
      ResponseCoefficients<double>::FromParameters(kFirstOrderForm, kTruth.data(), omega);
  return std::atan2(k.P(root.a), k.Q(root.a));
}

// Section 3.1.1: a filter on the strain-gauge channel only and the skew of
// multiplexed sampling shift the measured phase; corrected, the lag is the
// model's within 0.5 degree. The uncorrected error is the filter's lag
// atan(f / f_c) less the skew's Omega tau (11.3 - 7.0 degrees at 40 Hz).
TEST(RigSimulator, CorrectedPhasesAgreeWithTheModelsLag) {
  DwellPlan plan;
  plan.truth = kTruth;
  plan.sweeps = {FrequencySweep("F0.002", 0.002, 39.6, 40.4, 0.4, {SweepDirection::kUp})};
  RigOptions rig = ShortRig();
  rig.channels.skew_samples = 0.5;
  rig.channels.response_filter_cutoff_hz = 200.0;
  const RigRun run = SimulateRig(plan, rig);
  TraceProcessingOptions options;
  options.channels = rig.channels;
  options.gauge = rig.gauge;
  const ProcessedTraces corrected = ProcessTraces(run.traces, options);
  options.correct_channels = false;
  const ProcessedTraces raw = ProcessTraces(run.traces, options);
  const double degree = kTwoPi / 360.0;
  for (std::size_t i = 0; i < run.traces.size(); ++i) {
    const DwellPoint& point = corrected.sweeps[0].points[i];
    const double f_hz = RadPerSecondToHz(point.drive_frequency_rad_s);
    const double model = ModelLag(point.drive_frequency_rad_s, 0.002, point.amplitude);
    const double error = *point.phase_rad - model;
    const double raw_error = *raw.sweeps[0].points[i].phase_rad - model;
    // The filter delays the response; sampled half a sample late, it looks early.
    const double shift = std::atan(f_hz / 200.0) - kTwoPi * f_hz * 0.5 / rig.sample_rate_hz;
    std::cout << "  " << f_hz << " Hz: model lag " << model / degree << " deg, corrected error "
              << error / degree << " deg, uncorrected error " << raw_error / degree << " deg\n";
    EXPECT_LT(std::abs(error), 0.5 * degree) << f_hz << " Hz";
    EXPECT_GT(raw_error, 4.0 * degree) << f_hz << " Hz";
    EXPECT_NEAR(raw_error, shift, 0.5 * degree) << f_hz << " Hz";
  }
}

TEST(RigSimulator, ADwellCutShortIsMarkedUnsettledAndProcessingWarns) {
  DwellPlan plan;
  plan.truth = kTruth;
  plan.sweeps = {FrequencySweep("F0.01", 0.01, 40.0, 40.1, 0.1, {SweepDirection::kUp})};
  RigOptions rig = ShortRig();
  rig.settle_window_periods = 2;
  rig.max_settle_periods = 4;
  rig.record_periods = 8;
  const RigRun run = SimulateRig(plan, rig);
  ASSERT_EQ(run.dwell_truth.size(), 2u);
  EXPECT_FALSE(run.dwell_truth[0].settled);
  EXPECT_EQ(run.dwell_truth[0].settle_periods, 4);
  TraceProcessingOptions options;
  options.gauge = rig.gauge;
  const ProcessedTraces out = ProcessTraces(run.traces, options);
  EXPECT_GE(out.unsettled_dwells, 1);
  ASSERT_FALSE(out.warnings.empty());
  EXPECT_THAT(out.warnings[0], HasSubstr("unsettled: dwell F0.01/up @ 40 Hz"));
}

TEST(RigSimulator, APlanWithItsOwnNoiseOrAnUpperStartIsRefused) {
  DwellPlan plan;
  plan.truth = kTruth;
  plan.sweeps = {FrequencySweep("F0.01", 0.01, 40.0, 40.2, 0.1, {SweepDirection::kUp})};
  plan.noise.relative_sigma = 0.01;
  EXPECT_THROW(SimulateRig(plan, ShortRig()), InputError);
  plan.noise.relative_sigma = 0.0;
  plan.sweeps[0].start_branch = Branch::kUpper;
  try {
    SimulateRig(plan, ShortRig());
    ADD_FAILURE() << "an upper start was accepted";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("starts every sweep from rest"));
  }
}

// Rig settings that cannot give a usable record are refused before the
// simulation allocates or integrates anything: too few samples per period,
// records larger than memory, a settling window whose double overflows an int,
// and channel settings that push the samples out of float32's range.
TEST(RigSimulator, SettingsThatGiveNoUsableRecordAreRefused) {
  DwellPlan plan;
  plan.truth = kTruth;
  plan.sweeps = {FrequencySweep("F0.01", 0.01, 40.0, 40.2, 0.1, {SweepDirection::kUp})};
  const auto refusal = [&plan](const RigOptions& rig) {
    try {
      SimulateRig(plan, rig);
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  RigOptions rig = ShortRig();
  rig.sample_rate_hz = 1.0;
  EXPECT_THAT(refusal(rig), HasSubstr("sample_rate_hz 1 gives 0.0249 samples per period at the "
                                      "plan's highest drive frequency, 40.2 Hz; give at least 8"));
  rig = ShortRig();
  rig.record_periods = 100000000;  // 2 x 1e8 x 25 samples per dwell
  EXPECT_THAT(refusal(rig), HasSubstr("more than 4 GiB"));
  rig = ShortRig();
  rig.sample_rate_hz = 1e12;
  EXPECT_THAT(refusal(rig), HasSubstr("more than 4 GiB"));
  rig = ShortRig();
  rig.settle_window_periods = 1500000000;
  std::string why;
  EXPECT_FALSE(rig.IsValid(&why));
  EXPECT_THAT(why, HasSubstr("max_periods at least twice window_periods"));
  rig = ShortRig();
  rig.gauge.gain = 1e300;
  EXPECT_THAT(refusal(rig), HasSubstr("the simulated response channel is not finite"));
  rig.gauge.gain = 1e-300;
  EXPECT_THAT(refusal(rig), HasSubstr("the simulated response channel is constant"));
  rig = ShortRig();
  rig.channels.response_filter_cutoff_hz = 1e300;
  EXPECT_THAT(refusal(rig), HasSubstr("the simulated response channel is not finite"));
}

// The base channel's own noise: at 0 its samples are the noise-free run's,
// at twice the response's its noise is twice the shared run's, and the
// response channel's samples stay those of the run with one sigma for both.
TEST(RigSimulator, TheBaseChannelTakesItsOwnNoiseFromTheSameDraws) {
  DwellPlan plan;
  plan.truth = kTruth;
  plan.sweeps = {FrequencySweep("F0.01", 0.01, 39.0, 41.0, 1.0, {SweepDirection::kUp})};
  RigOptions rig = ShortRig();
  rig.record_periods = 4;
  const RigRun clean = SimulateRig(plan, rig);
  rig.noise_relative_sigma = 0.001;
  rig.noise_seed = 5;
  const RigRun shared = SimulateRig(plan, rig);
  rig.base_noise_relative_sigma = 0.0;
  const RigRun quiet_base = SimulateRig(plan, rig);
  rig.base_noise_relative_sigma = 0.002;
  const RigRun loud_base = SimulateRig(plan, rig);
  ASSERT_EQ(clean.traces.size(), 3u);
  for (std::size_t d = 0; d < clean.traces.size(); ++d) {
    const DwellTrace& c = clean.traces[d];
    EXPECT_EQ(quiet_base.traces[d].base, c.base);
    EXPECT_EQ(quiet_base.traces[d].response, shared.traces[d].response);
    EXPECT_EQ(loud_base.traces[d].response, shared.traces[d].response);
    double noise = 0.0;
    for (std::size_t i = 0; i < c.base.size(); ++i) {
      const double shared_noise = shared.traces[d].base[i] - c.base[i];
      const double loud_noise = loud_base.traces[d].base[i] - c.base[i];
      EXPECT_NEAR(loud_noise, 2.0 * shared_noise, 1e-6 * std::abs(c.base[i]) + 1e-9)
          << d << " " << i;
      noise = std::max(noise, std::abs(shared_noise));
    }
    EXPECT_GT(noise, 0.0);
  }
  rig.base_noise_relative_sigma = 1.5;
  std::string error;
  EXPECT_FALSE(rig.IsValid(&error));
  EXPECT_THAT(error, HasSubstr("noise base_relative_sigma must lie in [0, 1), got 1.5"));
}

// The levels process_traces reports carry their noise: an amplitude sweep's
// dwells the rig's per-dwell sigma (0.5 % of the level: rig_simulator.h),
// whose measured errors (against the noise-free run) spread as stated, and a
// frequency sweep's mean level that sigma over sqrt(n).
TEST(RigSimulator, ProcessedLevelsStateTheBaseChannelsNoise) {
  DwellPlan plan;
  plan.truth = kTruth;
  plan.sweeps = {FrequencySweep("F0.01", 0.01, 36.0, 38.9, 0.1, {SweepDirection::kUp}),
                 AmplitudeSweep("A37", 37.0, 0.005, 0.0109, 0.0001, {SweepDirection::kUp})};
  RigOptions rig = ShortRig();
  TraceProcessingOptions options;
  options.gauge = rig.gauge;
  const ProcessedTraces clean = ProcessTraces(SimulateRig(plan, rig).traces, options);
  rig.noise_relative_sigma = 0.005;
  rig.noise_seed = 11;
  const ProcessedTraces noisy = ProcessTraces(SimulateRig(plan, rig).traces, options);
  ASSERT_EQ(noisy.sweeps.size(), 2u);
  const Sweep& frequency = noisy.sweeps[0];
  const Sweep& amplitude = noisy.sweeps[1];
  ASSERT_EQ(frequency.points.size(), 30u);
  ASSERT_EQ(amplitude.points.size(), 60u);
  // Each sigma is estimated from the few noise bins of a short record: its
  // mean is near the rig's, each within half of it.
  double z2 = 0.0, mean = 0.0;
  for (std::size_t i = 0; i < amplitude.points.size(); ++i) {
    const DwellPoint& point = amplitude.points[i];
    ASSERT_TRUE(point.a_base_sigma.has_value()) << i;
    const double relative = *point.a_base_sigma / point.a_base;
    EXPECT_NEAR(relative, 0.005, 0.0025) << i;
    mean += relative / amplitude.points.size();
    const double error = point.a_base - clean.sweeps[1].points[i].a_base;
    z2 += std::pow(error / *point.a_base_sigma, 2) / amplitude.points.size();
  }
  EXPECT_NEAR(mean, 0.005, 0.0005);
  EXPECT_GT(std::sqrt(z2), 0.7);  // 60 draws: the RMS of z is 1 +/- 0.09
  EXPECT_LT(std::sqrt(z2), 1.3);
  for (const DwellPoint& point : frequency.points) {
    ASSERT_TRUE(point.a_base_sigma.has_value());
    EXPECT_NEAR(*point.a_base_sigma / point.a_base, 0.005 / std::sqrt(30.0),
                0.15 * 0.005 / std::sqrt(30.0));
  }
  // Without noise what is left is the window's leakage (4 periods, 27.7
  // samples per period, whole to within half a sample): well below the noise.
  for (const DwellPoint& point : clean.sweeps[1].points) {
    EXPECT_LT(point.a_base_sigma.value_or(0.0) / point.a_base, 0.4 * 0.005);
  }
}

// Harmonic balance (eqs. 3.12-3.13) on traces of ten dwells with 0.1 % noise
// recovers eta_e, w and the effective nonlinearity within 1 % (with 0.5 %,
// ten dwells are too few for the nonlinearity: datasets/virtual-beam has 456).
TEST(RigSimulator, HarmonicBalanceRecoversTheTruthFromNoisyTraces) {
  DwellPlan plan;
  plan.truth = kTruth;
  plan.sweeps = {FrequencySweep("F0.01", 0.01, 39.0, 42.0, 0.5, {SweepDirection::kUp}),
                 AmplitudeSweep("A41.5", 41.5, 0.01, 0.03, 0.01, {SweepDirection::kUp})};
  RigOptions rig = ShortRig();
  rig.record_periods = 8;
  rig.noise_relative_sigma = 0.001;
  rig.noise_seed = 3;
  rig.channels.skew_samples = 0.5;
  const RigRun run = SimulateRig(plan, rig);
  TraceProcessingOptions options;
  options.channels = rig.channels;
  options.gauge = rig.gauge;
  const ProcessedTraces processed = ProcessTraces(run.traces, options);
  const double reference = HzToRadPerSecond(41.5);
  const HarmonicBalanceResult result =
      IdentifyHarmonicBalance(processed.harmonics, options.harmonics, reference);
  const double true_effective = kTruth[kAlpha] - 2.0 / 3.0 * kTruth[kDelta] * reference * reference;
  std::cout << "  eta_e " << result.estimate[kEtaE] << ", w/2pi "
            << RadPerSecondToHz(result.estimate[kNaturalFrequency]) << " Hz, effective "
            << result.effective_nonlinearity << " (true " << true_effective << "), mu1 "
            << result.estimate[kMu1] << ", mu2 " << result.estimate[kMu2] << "\n";
  EXPECT_NEAR(result.estimate[kEtaE] / kTruth[kEtaE], 1.0, 0.01);
  EXPECT_NEAR(result.estimate[kNaturalFrequency] / kTruth[kNaturalFrequency], 1.0, 0.01);
  EXPECT_NEAR(result.effective_nonlinearity / true_effective, 1.0, 0.01);
}

}  // namespace
}  // namespace dwellfit
