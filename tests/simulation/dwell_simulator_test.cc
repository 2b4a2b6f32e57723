#include "dwellfit/estimator/simulation/dwell_simulator.h"

#include <cmath>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "dwellfit/config/dwell_plan_reader.h"
#include "dwellfit/estimator/common/input_error.h"
#include "dwellfit/estimator/data/sweep_csv.h"
#include "dwellfit/estimator/data/sweep_csv_writer.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"

namespace dwellfit {
namespace {

const std::string kDatasetDir = std::string(DWELLFIT_SOURCE_DIR) + "/datasets/thesis-numerical/";

// Table 3.1 truth with w = 2 pi 40 rad/s (docs/model.md).
ParameterVector Truth() { return {100.0, 0.2, 300.0, 1e4, 9e8, HzToRadPerSecond(40.0)}; }

ResponseCoefficients<double> At(double omega_rad_s) {
  const ParameterVector p = Truth();
  return ResponseCoefficients<double>::FromParameters(kFirstOrderForm, p.data(), omega_rad_s);
}

DwellPlan ThesisPlan() { return ReadDwellPlan(kDatasetDir + "plan.yaml"); }

std::map<std::string, Sweep> ByName(const std::vector<Sweep>& sweeps) {
  std::map<std::string, Sweep> by_name;
  for (const Sweep& sweep : sweeps) by_name[sweep.Name()] = sweep;
  return by_name;
}

std::string ReadFile(const std::string& path) {
  std::ifstream file(path, std::ios::binary);
  std::ostringstream text;
  text << file.rdbuf();
  return text.str();
}

SweepPlan AmplitudeSweep(const std::string& id, double hz, double from, double to, double step) {
  SweepPlan sweep;
  sweep.id = id;
  sweep.kind = SweepKind::kAmplitude;
  sweep.held_frequency_hz = hz;
  sweep.from = from;
  sweep.to = to;
  sweep.step = step;
  return sweep;
}

TEST(DwellSimulator, ThesisPlanReadsTheTable31Truth) {
  const DwellPlan plan = ThesisPlan();
  EXPECT_EQ(plan.truth, Truth());
  ASSERT_EQ(plan.sweeps.size(), 4u);
  EXPECT_EQ(plan.sweeps[0].id, "F0.01");
  EXPECT_EQ(plan.sweeps[0].kind, SweepKind::kFrequency);
  EXPECT_EQ(plan.sweeps[0].held_a_base, 0.01);
  EXPECT_EQ(plan.sweeps[0].NumSteps(), 80);
  EXPECT_EQ(plan.sweeps[1].id, "A41.5");
  EXPECT_EQ(plan.sweeps[1].held_frequency_hz, 41.5);
  EXPECT_EQ(plan.sweeps[1].NumSteps(), 48);
  EXPECT_EQ(plan.noise.relative_sigma, 0.0);
}

TEST(DwellSimulator, ControlGridIsExactDecimalsNotAccumulatedSums) {
  const SweepPlan sweep = AmplitudeSweep("A", 41.5, 0.002, 0.05, 0.001);
  const std::vector<double> up = ControlGrid(sweep, SweepDirection::kUp);
  ASSERT_EQ(up.size(), 49u);
  EXPECT_EQ(up.front(), 0.002);
  EXPECT_EQ(up[33], 0.035);  // 0.002 + 33 * 0.001 is 0.035000000000000003 unrounded
  EXPECT_EQ(up.back(), 0.05);
  const std::vector<double> down = ControlGrid(sweep, SweepDirection::kDown);
  EXPECT_EQ(down.front(), 0.05);
  EXPECT_EQ(down.back(), 0.002);

  const std::map<std::string, Sweep> sweeps = ByName(SimulateDwells(ThesisPlan()));
  const Sweep& f_up = sweeps.at("F0.01/up");
  ASSERT_EQ(f_up.points.size(), 81u);
  for (int i = 0; i <= 80; ++i) {
    const double hz = RoundToSignificantDigits(38.0 + i * 0.1, 12);
    EXPECT_EQ(f_up.points[i].drive_frequency_rad_s, HzToRadPerSecond(hz)) << i;
    EXPECT_EQ(f_up.points[i].a_base, 0.01);
  }
  EXPECT_EQ(FormatFrequencyHz(f_up.points[35].drive_frequency_rad_s), "41.5");
  EXPECT_EQ(FormatFrequencyHz(f_up.points[43].drive_frequency_rad_s), "42.3");
}

TEST(DwellSimulator, EveryDwellIsAStableFixedPointOnItsBranch) {
  for (const Sweep& sweep : SimulateDwells(ThesisPlan())) {
    for (const DwellPoint& point : sweep.points) {
      const auto k = At(point.drive_frequency_rad_s);
      const double target = point.a_base * point.a_base;
      EXPECT_NEAR(k.G(point.amplitude) / target, 1.0, 1e-12) << sweep.Name();
      EXPECT_GT(k.dG(point.amplitude), 0.0) << sweep.Name();
      const TurningPoints tp = FindTurningPoints(k);
      if (point.branch == Branch::kLower) {
        ASSERT_TRUE(tp.exist);
        EXPECT_LT(point.amplitude, tp.a_lower_end);
      } else if (point.branch == Branch::kUpper) {
        ASSERT_TRUE(tp.exist);
        EXPECT_GT(point.amplitude, tp.a_upper_end);
      } else {  // single-valued: at most one of the two stable branches exists
        EXPECT_TRUE(!tp.exist || !(k.G(tp.a_upper_end) < target && target < k.G(tp.a_lower_end)))
            << sweep.Name();
      }
      EXPECT_EQ(point.source_line, 0);
      EXPECT_FALSE(point.sigma.has_value());
    }
  }
}

// For every simulated jump, the branch left exists at the dwell before and is
// gone at the dwell after: the model's fold (turning point of G) lies inside
// the bracket.
TEST(DwellSimulator, EveryJumpBracketsTheModelFold) {
  for (const Sweep& sweep : SimulateDwells(ThesisPlan())) {
    ASSERT_EQ(sweep.jumps.size(), 1u) << sweep.Name();
    const JumpBracket& jump = sweep.jumps[0];
    const DwellPoint& before = sweep.points[jump.index_before];
    const DwellPoint& after = sweep.points[jump.index_before + 1];
    EXPECT_EQ(sweep.Control(before), jump.control_before);
    EXPECT_EQ(sweep.Control(after), jump.control_after);
    const auto k_before = At(before.drive_frequency_rad_s);
    const auto k_after = At(after.drive_frequency_rad_s);
    const TurningPoints tp_before = FindTurningPoints(k_before);
    const TurningPoints tp_after = FindTurningPoints(k_after);
    ASSERT_TRUE(tp_before.exist && tp_after.exist) << sweep.Name();
    const double target_before = before.a_base * before.a_base;
    const double target_after = after.a_base * after.a_base;
    if (jump.kind == JumpKind::kJumpDown) {  // the upper branch ended
      EXPECT_LT(k_before.G(tp_before.a_upper_end), target_before) << sweep.Name();
      EXPECT_GT(k_after.G(tp_after.a_upper_end), target_after) << sweep.Name();
      EXPECT_GT(jump.amplitude_before, 5.0 * jump.amplitude_after);
    } else {  // the lower branch ended
      EXPECT_GT(k_before.G(tp_before.a_lower_end), target_before) << sweep.Name();
      EXPECT_LT(k_after.G(tp_after.a_lower_end), target_after) << sweep.Name();
      EXPECT_LT(2.0 * jump.amplitude_before, jump.amplitude_after);
    }
  }
}

TEST(DwellSimulator, ThesisJumpsLandWhereTheModelPutsThem) {
  const std::map<std::string, Sweep> sweeps = ByName(SimulateDwells(ThesisPlan()));
  struct Expected {
    std::string name;
    JumpKind kind;
    double before, after;  // Hz for frequency sweeps, a_base for amplitude sweeps
  };
  // G(a) puts the frequency jump down's fold at 42.215 Hz, between the 42.2
  // and 42.3 Hz dwells (docs/model.md; see stable_root_test.cc).
  const std::vector<Expected> expected = {
      {"F0.01/up", JumpKind::kJumpDown, 42.2, 42.3},
      {"F0.01/down", JumpKind::kJumpUp, 40.7, 40.6},
      {"A41.5/up", JumpKind::kJumpUp, 0.035, 0.036},
      {"A41.5/down", JumpKind::kJumpDown, 0.007, 0.006},
      {"A41.2/up", JumpKind::kJumpUp, 0.025, 0.026},
      {"A41.2/down", JumpKind::kJumpDown, 0.006, 0.005},
      {"A41.8/up", JumpKind::kJumpUp, 0.047, 0.048},
      {"A41.8/down", JumpKind::kJumpDown, 0.009, 0.008},
  };
  for (const Expected& e : expected) {
    const Sweep& sweep = sweeps.at(e.name);
    ASSERT_EQ(sweep.jumps.size(), 1u) << e.name;
    const JumpBracket& jump = sweep.jumps[0];
    EXPECT_EQ(jump.kind, e.kind) << e.name;
    const bool frequency = sweep.kind == SweepKind::kFrequency;
    EXPECT_EQ(jump.control_before, frequency ? HzToRadPerSecond(e.before) : e.before) << e.name;
    EXPECT_EQ(jump.control_after, frequency ? HzToRadPerSecond(e.after) : e.after) << e.name;
  }
  // The amplitude-sweep folds at 41.5 Hz, from the turning points of G.
  const auto k = At(HzToRadPerSecond(41.5));
  const TurningPoints tp = FindTurningPoints(k);
  ASSERT_TRUE(tp.exist);
  const double jump_up_level = std::sqrt(k.G(tp.a_lower_end));
  const double jump_down_level = std::sqrt(k.G(tp.a_upper_end));
  EXPECT_GT(jump_up_level, 0.035);
  EXPECT_LT(jump_up_level, 0.036);
  EXPECT_GT(jump_down_level, 0.006);
  EXPECT_LT(jump_down_level, 0.007);
  // The up sweep rides the resonant branch up to the fold: largest amplitude
  // just before the jump down.
  const Sweep& f_up = sweeps.at("F0.01/up");
  EXPECT_NEAR(f_up.jumps[0].amplitude_before, 4.707e-3, 1e-6);
  EXPECT_EQ(f_up.points[f_up.jumps[0].index_before].branch, Branch::kUpper);
  EXPECT_EQ(f_up.points[f_up.jumps[0].index_before + 1].branch, Branch::kOnly);
}

TEST(DwellSimulator, DownSweepContinuesFromWhereTheUpSweepEnded) {
  const std::map<std::string, Sweep> sweeps = ByName(SimulateDwells(ThesisPlan()));
  for (const std::string id : {"F0.01", "A41.5", "A41.2", "A41.8"}) {
    const Sweep& up = sweeps.at(id + "/up");
    const Sweep& down = sweeps.at(id + "/down");
    EXPECT_EQ(down.points.front().drive_frequency_rad_s, up.points.back().drive_frequency_rad_s);
    EXPECT_EQ(down.points.front().a_base, up.points.back().a_base);
    EXPECT_EQ(down.points.front().amplitude, up.points.back().amplitude) << id;
    EXPECT_EQ(down.points.back().amplitude, up.points.front().amplitude) << id;
  }
}

TEST(DwellSimulator, StartBranchChoosesTheBranchInsideTheBistableRange) {
  DwellPlan plan;
  plan.truth = Truth();
  SweepPlan from_rest = AmplitudeSweep("rest", 41.5, 0.02, 0.03, 0.001);
  SweepPlan from_upper = from_rest;
  from_upper.id = "upper";
  from_upper.start_branch = Branch::kUpper;
  plan.sweeps = {from_rest, from_upper};
  const std::map<std::string, Sweep> sweeps = ByName(SimulateDwells(plan));
  const double omega = HzToRadPerSecond(41.5);
  for (const std::string direction : {"/up", "/down"}) {
    for (const DwellPoint& point : sweeps.at("rest" + direction).points) {
      EXPECT_EQ(point.branch, Branch::kLower);
      EXPECT_NEAR(
          point.amplitude,
          ModelAmplitude(kFirstOrderForm, Truth(), omega, point.a_base, Branch::kLower, 1e-3).a,
          1e-15);
    }
    for (const DwellPoint& point : sweeps.at("upper" + direction).points) {
      EXPECT_EQ(point.branch, Branch::kUpper);
      EXPECT_NEAR(
          point.amplitude,
          ModelAmplitude(kFirstOrderForm, Truth(), omega, point.a_base, Branch::kUpper, 5e-3).a,
          1e-15);
    }
    EXPECT_TRUE(sweeps.at("rest" + direction).jumps.empty());
    EXPECT_TRUE(sweeps.at("upper" + direction).jumps.empty());
  }
}

TEST(SettleDwell, FromAMonotoneResponseTakesTheSideOfTheSaddle) {
  const double omega = HzToRadPerSecond(41.5);
  const double a_base = 0.02;  // bistable at 41.5 Hz
  const double lower = ModelAmplitude(kFirstOrderForm, Truth(), omega, a_base, Branch::kLower, 0).a;
  const double upper =
      ModelAmplitude(kFirstOrderForm, Truth(), omega, a_base, Branch::kUpper, 5e-3).a;
  // The unstable middle root, by bisection on G - a_base^2 (decreasing there).
  const auto k = At(omega);
  const TurningPoints tp = FindTurningPoints(k);
  double lo = tp.a_lower_end, hi = tp.a_upper_end;
  for (int i = 0; i < 200; ++i) {
    const double mid = 0.5 * (lo + hi);
    (k.G(mid) > a_base * a_base ? lo : hi) = mid;
  }
  const double saddle = lo;
  ASSERT_LT(lower, saddle);
  ASSERT_LT(saddle, upper);

  const SettledDwell below =
      SettleDwell(kFirstOrderForm, Truth(), omega, a_base, Branch::kOnly, 0.99 * saddle);
  EXPECT_EQ(below.side, Branch::kLower);
  EXPECT_EQ(below.amplitude, lower);
  EXPECT_FALSE(below.jumped);
  const SettledDwell above =
      SettleDwell(kFirstOrderForm, Truth(), omega, a_base, Branch::kOnly, 1.01 * saddle);
  EXPECT_EQ(above.side, Branch::kUpper);
  EXPECT_EQ(above.branch, Branch::kUpper);
  EXPECT_NEAR(above.amplitude, upper, 1e-15);
  const SettledDwell rest =
      SettleDwell(kFirstOrderForm, Truth(), omega, a_base, Branch::kOnly, 0.0);
  EXPECT_EQ(rest.side, Branch::kLower);
}

TEST(SettleDwell, JumpsWhenTheBranchEnds) {
  const double omega = HzToRadPerSecond(41.5);
  // Above the jump-up level 0.0354 only the upper branch exists.
  const SettledDwell jump =
      SettleDwell(kFirstOrderForm, Truth(), omega, 0.036, Branch::kLower, 2e-3);
  EXPECT_TRUE(jump.jumped);
  EXPECT_EQ(jump.side, Branch::kUpper);
  EXPECT_EQ(jump.branch, Branch::kOnly);
  // The first dwell (from rest) is not a jump even where lower does not exist.
  EXPECT_FALSE(SettleDwell(kFirstOrderForm, Truth(), omega, 0.036, Branch::kLower, 0.0).jumped);
  // Far below resonance G is monotone: one root, no branch.
  const SettledDwell single =
      SettleDwell(kFirstOrderForm, Truth(), HzToRadPerSecond(38.0), 0.01, Branch::kUpper, 1e-3);
  EXPECT_EQ(single.side, Branch::kOnly);
  EXPECT_EQ(single.branch, Branch::kOnly);
  EXPECT_FALSE(single.jumped);
}

TEST(DwellSimulator, SeededNoiseIsReproducibleAndHasTheRequestedSpread) {
  DwellPlan plan = ThesisPlan();
  const std::vector<Sweep> clean = SimulateDwells(plan);
  plan.noise = {0.05, 12345};
  const std::vector<Sweep> noisy = SimulateDwells(plan);
  const std::vector<Sweep> again = SimulateDwells(plan);
  plan.noise.seed = 54321;
  const std::vector<Sweep> other_seed = SimulateDwells(plan);

  double sum = 0.0, sum_squares = 0.0;
  int n = 0, differ_from_other_seed = 0;
  ASSERT_EQ(noisy.size(), clean.size());
  for (std::size_t s = 0; s < clean.size(); ++s) {
    ASSERT_EQ(noisy[s].points.size(), clean[s].points.size());
    for (std::size_t i = 0; i < clean[s].points.size(); ++i) {
      const DwellPoint& c = clean[s].points[i];
      const DwellPoint& x = noisy[s].points[i];
      EXPECT_EQ(x.amplitude, again[s].points[i].amplitude);
      if (x.amplitude != other_seed[s].points[i].amplitude) ++differ_from_other_seed;
      EXPECT_EQ(x.branch, c.branch);  // noise is measurement noise only
      EXPECT_EQ(x.a_base, c.a_base);
      const double relative = x.amplitude / c.amplitude - 1.0;
      sum += relative;
      sum_squares += relative * relative;
      ++n;
    }
    // The jumps stay where the truth puts them; the bracket carries the
    // measured (noisy) amplitudes.
    ASSERT_EQ(noisy[s].jumps.size(), clean[s].jumps.size());
    for (std::size_t j = 0; j < clean[s].jumps.size(); ++j) {
      const JumpBracket& jump = noisy[s].jumps[j];
      EXPECT_EQ(jump.control_before, clean[s].jumps[j].control_before);
      EXPECT_EQ(jump.amplitude_before, noisy[s].points[jump.index_before].amplitude);
    }
  }
  ASSERT_EQ(n, 2 * (81 + 3 * 49));
  EXPECT_EQ(differ_from_other_seed, n);
  const double mean = sum / n;
  const double spread = std::sqrt(sum_squares / n - mean * mean);
  // Sampling error of the spread: 0.05 / sqrt(2 n) = 0.0023; of the mean: 0.0023.
  EXPECT_NEAR(spread, 0.05, 0.006);
  EXPECT_NEAR(mean, 0.0, 0.007);
}

TEST(SweepCsvWriter, WritesRoundTripNumbersAndShortFrequencies) {
  EXPECT_EQ(FormatRoundTrip(0.1), "0.1");
  EXPECT_EQ(FormatRoundTrip(0.035), "0.035");
  EXPECT_EQ(FormatRoundTrip(1.0 / 3.0), "0.3333333333333333");
  EXPECT_EQ(std::stod(FormatRoundTrip(1.0 / 3.0)), 1.0 / 3.0);
  for (double hz : {38.0, 40.6, 41.2, 41.5, 42.3, 45.9, 46.0, 156.25, 0.1}) {
    EXPECT_EQ(std::stod(FormatFrequencyHz(HzToRadPerSecond(hz))), hz);
  }
  EXPECT_EQ(FormatFrequencyHz(HzToRadPerSecond(41.5)), "41.5");
  EXPECT_EQ(FormatFrequencyHz(HzToRadPerSecond(100.0)), "100");
  // A frequency that is no short decimal still maps back to the same rad/s.
  const double omega = 260.123456789012345;
  EXPECT_EQ(HzToRadPerSecond(std::stod(FormatFrequencyHz(omega))), omega);
}

TEST(SweepCsvWriter, ThesisDatasetFileIsTheSimulatorOutput) {
  std::ostringstream text;
  WriteSweepsCsv(SimulateDwells(ThesisPlan()), &text);
  EXPECT_EQ(ReadFile(kDatasetDir + "sweeps.csv"), text.str())
      << "datasets/thesis-numerical/sweeps.csv is stale; regenerate it with the command in "
         "datasets/thesis-numerical/README.md";
  // 41.5 Hz, not 41.500000000000007: the first row of A41.5.
  EXPECT_NE(text.str().find("\nA41.5,up,41.5,0.002,"), std::string::npos);
}

TEST(SweepCsvWriter, NoisyDataWithSigmaRoundTripsThroughTheLoader) {
  DwellPlan plan = ThesisPlan();
  plan.noise = {0.02, 7};
  std::vector<Sweep> sweeps = SimulateDwells(plan);
  for (Sweep& sweep : sweeps) {
    for (DwellPoint& point : sweep.points) point.sigma = 0.02 * point.amplitude;
  }
  const std::string path = ::testing::TempDir() + "dwellfit_dwell_simulator_round_trip.csv";
  WriteSweepsCsvFile(sweeps, path);
  EXPECT_EQ(ReadFile(path).substr(0, 47), "sweep,direction,freq_hz,a_base,a,phase_rad,sigm");

  const LoadedSweeps loaded = LoadSweepsCsv(path);
  EXPECT_EQ(loaded.dropped_nonpositive, 0);
  ASSERT_EQ(loaded.sweeps.size(), sweeps.size());
  for (std::size_t s = 0; s < sweeps.size(); ++s) {
    const Sweep& written = sweeps[s];
    const Sweep& read = loaded.sweeps[s];
    EXPECT_EQ(read.Name(), written.Name());
    EXPECT_EQ(read.kind, written.kind) << written.Name();
    ASSERT_EQ(read.points.size(), written.points.size());
    for (std::size_t i = 0; i < written.points.size(); ++i) {
      const DwellPoint& w = written.points[i];
      const DwellPoint& r = read.points[i];
      EXPECT_EQ(r.drive_frequency_rad_s, w.drive_frequency_rad_s) << written.Name() << " " << i;
      EXPECT_EQ(r.a_base, w.a_base);
      EXPECT_EQ(r.amplitude, w.amplitude);
      ASSERT_TRUE(r.sigma.has_value());
      EXPECT_EQ(*r.sigma, *w.sigma);
      ASSERT_TRUE(r.phase_rad.has_value());
      EXPECT_EQ(*r.phase_rad, *w.phase_rad);
    }
  }
}

TEST(SweepCsvWriter, RejectsSigmaOnSomeDwellsOnly) {
  std::vector<Sweep> sweeps = SimulateDwells(ThesisPlan());
  sweeps[0].points[3].sigma = 1e-5;
  std::ostringstream text;
  EXPECT_THROW(WriteSweepsCsv(sweeps, &text), InputError);
  EXPECT_THROW(WriteSweepsCsvFile(SimulateDwells(ThesisPlan()), "/no/such/dir/out.csv"),
               InputError);
}

// The error a plan text gives, as "line field: message".
std::string PlanError(const std::string& yaml) {
  try {
    ParseDwellPlan(yaml, "plan.yaml");
  } catch (const InputError& e) {
    return std::to_string(e.line()) + " " + e.field() + ": " + e.what();
  }
  return "no error";
}

// A plan text and the error it gives, as PlanError prints it.
struct PlanErrorCase {
  std::string yaml;
  std::string error;
};

void ExpectPlanErrors(const std::vector<PlanErrorCase>& cases) {
  for (const PlanErrorCase& c : cases) EXPECT_EQ(PlanError(c.yaml), c.error) << c.yaml;
}

const char kTruth[] =
    "truth: {eta_e: 100, mu1: 0.2, mu2: 300, delta: 1.0e4, alpha: 9.0e8, omega_hz: 40}\n";

TEST(DwellPlanReader, ParsesAPlanWithNoiseAndStartBranch) {
  const DwellPlan plan =
      ParseDwellPlan(std::string(kTruth) +
                         "sweeps:\n"
                         "  - id: A\n"
                         "    kind: amplitude\n"
                         "    freq_hz: 41.5\n"
                         "    a_base_from: 0.02\n"
                         "    a_base_to: 0.03\n"
                         "    a_base_step: 0.005\n"
                         "    directions: [down]\n"
                         "    start: upper\n"
                         "noise: {relative_sigma: 0.01, seed: 18446744073709551615}\n",
                     "plan.yaml");
  EXPECT_EQ(plan.truth, Truth());
  ASSERT_EQ(plan.sweeps.size(), 1u);
  EXPECT_EQ(plan.sweeps[0].start_branch, Branch::kUpper);
  EXPECT_EQ(plan.sweeps[0].directions, std::vector<SweepDirection>{SweepDirection::kDown});
  EXPECT_EQ(plan.sweeps[0].NumSteps(), 2);
  EXPECT_EQ(plan.noise.relative_sigma, 0.01);
  EXPECT_EQ(plan.noise.seed, 18446744073709551615ull);
}

TEST(DwellPlanReader, ErrorsNameLineFieldAndFix) {
  const std::string sweep_head = std::string(kTruth) + "sweeps:\n  - id: F\n    kind: frequency\n";
  const std::string grid = "    a_base: 0.01\n    from_hz: 38\n    to_hz: 46\n    step_hz: 0.1\n";
  EXPECT_EQ(PlanError(sweep_head + grid).substr(0, 2), "no");

  ExpectPlanErrors({
      {sweep_head + grid + "    stpe: 3\n",
       "9 sweeps[0].stpe: plan.yaml:9: field 'sweeps[0].stpe': unknown key 'stpe' in 'sweeps[0]'; "
       "allowed: id, kind, directions, start, a_base, from_hz, to_hz, step_hz"},
      // A key of the other kind of sweep.
      {sweep_head + grid + "    freq_hz: 41\n",
       "9 sweeps[0].freq_hz: plan.yaml:9: field 'sweeps[0].freq_hz': 'freq_hz' belongs to "
       "amplitude sweeps, and this sweep has kind frequency; allowed: id, kind, directions, start, "
       "a_base, from_hz, to_hz, step_hz (or set kind: amplitude)"},
      {sweep_head + "    a_base: 0.01\n    from_hz: 38\n    to_hz: 46.05\n    step_hz: 0.1\n",
       "3 sweeps[0]: plan.yaml:3: field 'sweeps[0]': to_hz - from_hz (8.05) must be a whole number "
       "of steps of step_hz (0.1), at most 1000000; adjust to_hz or step_hz"},
      {sweep_head + "    a_base: -0.01\n    from_hz: 38\n    to_hz: 46\n    step_hz: 0.1\n",
       "5 sweeps[0].a_base: plan.yaml:5: field 'sweeps[0].a_base': must be positive, got -0.01"},
      {sweep_head + "    from_hz: 38\n    to_hz: 46\n    step_hz: 0.1\n",
       "3 sweeps[0].a_base: plan.yaml:3: field 'sweeps[0].a_base': missing required key 'a_base' "
       "in 'sweeps[0]'; add a_base (the base level held) to this frequency sweep"},
      {sweep_head + grid + "    directions: [up, sideways]\n",
       "9 sweeps[0].directions: plan.yaml:9: field 'sweeps[0].directions': unknown direction "
       "'sideways'; allowed: up, down"},
      {sweep_head + grid + "  - id: F\n    kind: frequency\n" + grid,
       "9 sweeps[1].id: plan.yaml:9: field 'sweeps[1].id': sweep id 'F' is used twice (first at "
       "line 3); ids must be unique"},
      {std::string(kTruth) + "sweeps: []\n",
       "2 sweeps: plan.yaml:2: field 'sweeps': expected a list of one sweep or more, each a block "
       "of keys (- id: F0.01, ...)"},
      {"truth: {eta_e: 100, mu1: 0.2, mu2: 300, delta: 1.0e4, alpha: x, omega_hz: 40}\n"
       "sweeps: []\n",
       "1 truth.alpha: plan.yaml:1: field 'truth.alpha': expected a number (e.g. 130, 0.26 or "
       "1.3e4), got 'x'"},
      {sweep_head + grid + "noise: {relative_sigma: 0.01, seed: -3}\n",
       "9 noise.seed: plan.yaml:9: field 'noise.seed': expected a whole number from 0 to 2^64 - 1, "
       "got '-3'"},
  });
  EXPECT_THAT(PlanError("truth: [1, 2\n"),
              ::testing::StartsWith("2 : plan.yaml:2: YAML syntax error: "));
}

TEST(DwellPlanReader, UnknownKeysGetADidYouMean) {
  const std::string head = std::string(kTruth) + "sweeps:\n  - id: F\n";
  const std::string grid = "    a_base: 0.01\n    from_hz: 38\n    to_hz: 46\n";
  const std::string sweep = head + "    kind: frequency\n" + grid + "    step_hz: 0.1\n";
  ExpectPlanErrors({
      {head + "    kind: frequency\n" + grid + "    step_hx: 0.1\n",
       "8 sweeps[0].step_hx: plan.yaml:8: field 'sweeps[0].step_hx': unknown key 'step_hx' in "
       "'sweeps[0]' (did you mean 'step_hz'?); allowed: id, kind, directions, start, a_base, "
       "from_hz, to_hz, step_hz"},
      {std::string(kTruth) + "sweep:\n  - id: F\n",
       "2 sweep: plan.yaml:2: field 'sweep': unknown key 'sweep' at the top level (did you mean "
       "'sweeps'?); allowed: truth, sweeps, noise, model"},
      {sweep + "noise: {relative_sigma: 0.01, sed: 7}\n",
       "9 noise.sed: plan.yaml:9: field 'noise.sed': unknown key 'sed' in 'noise' (did you mean "
       "'seed'?); allowed: relative_sigma, seed"},
      {head + "    kind: frequncy\n" + grid + "    step_hz: 0.1\n",
       "4 sweeps[0].kind: plan.yaml:4: field 'sweeps[0].kind': unknown sweep kind 'frequncy' (did "
       "you mean 'frequency'?); allowed: frequency, amplitude"},
  });
}

// The kind decides which keys a sweep allows; without it the sweep is still
// read for an InputError (a yaml-cpp exception escaped here once).
TEST(DwellPlanReader, ASweepWithoutKindIsAnInputError) {
  const std::string head = std::string(kTruth) + "sweeps:\n  - id: F\n";
  const std::string grid = "    a_base: 0.01\n    from_hz: 38\n    to_hz: 46\n    step_hz: 0.1\n";
  EXPECT_THAT(PlanError(head + grid),
              ::testing::StartsWith("3 sweeps[0].kind: plan.yaml:3: field 'sweeps[0].kind': "
                                    "missing required key 'kind' in 'sweeps[0]'"));
  EXPECT_THAT(PlanError(head + "    knd: frequency\n" + grid),
              ::testing::StartsWith("4 sweeps[0].knd: plan.yaml:4: field 'sweeps[0].knd': "
                                    "unknown key 'knd' in 'sweeps[0]' (did you mean 'kind'?)"));
}

// The simulator works in rad/s, where these frequencies are infinite.
TEST(DwellPlanReader, FrequenciesOverflowingInRadPerSecondAreErrors) {
  const std::string head = std::string(kTruth) + "sweeps:\n  - id: F\n";
  ExpectPlanErrors({
      {head + "    kind: frequency\n    a_base: 0.01\n    from_hz: 1e308\n    to_hz: 1.5e308\n"
              "    step_hz: 0.5e308\n",
       "3 sweeps[0]: plan.yaml:3: field 'sweeps[0]': to_hz (1.5e+308 Hz) is too large (infinite "
       "in rad/s)"},
      {head + "    kind: amplitude\n    freq_hz: 1e308\n    a_base_from: 0.001\n"
              "    a_base_to: 0.003\n    a_base_step: 0.001\n",
       "3 sweeps[0]: plan.yaml:3: field 'sweeps[0]': the held frequency (1e+308 Hz) is too large "
       "(infinite in rad/s)"},
  });
}

TEST(DwellPlanReader, AFileThatCannotBeReadIsNamedAsThePlanFile) {
  const std::string missing = ::testing::TempDir() + "/no-such-dir/plan.yaml";
  try {
    ReadDwellPlan(missing);
    ADD_FAILURE() << "no error for " << missing;
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()),
              missing + ": no such file; give the path of the YAML plan file");
  }
  try {
    ReadDwellPlan(::testing::TempDir());
    ADD_FAILURE() << "no error for a directory";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), ::testing::EndsWith("is a folder; give the path of the YAML plan file"));
  }
}

TEST(DwellSimulator, RejectsAPlanThatIsNotValid) {
  DwellPlan plan;
  plan.truth = Truth();
  EXPECT_THROW(SimulateDwells(plan), InputError);                // no sweeps
  plan.sweeps = {AmplitudeSweep("A", 41.5, 0.03, 0.02, 0.001)};  // to < from
  EXPECT_THROW(SimulateDwells(plan), InputError);
  plan.sweeps = {AmplitudeSweep("A", 41.5, 0.02, 0.03, 0.001)};
  plan.sweeps[0].directions = {SweepDirection::kUp, SweepDirection::kUp};
  EXPECT_THROW(SimulateDwells(plan), InputError);
  plan.sweeps[0].directions = {SweepDirection::kUp};
  plan.truth[kEtaE] = 0.0;
  EXPECT_THROW(SimulateDwells(plan), InputError);
}

}  // namespace
}  // namespace dwellfit
