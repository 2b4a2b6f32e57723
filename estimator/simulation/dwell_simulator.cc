#include "dwellfit/estimator/simulation/dwell_simulator.h"

#include <algorithm>
#include <boost/random/normal_distribution.hpp>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <set>

#include "dwellfit/estimator/common/input_error.h"
#include "dwellfit/estimator/common/string_printf.h"
#include "dwellfit/residuals/model/bracketed_newton.h"
#include "dwellfit/residuals/model/response_model.h"
#include "glog/logging.h"

namespace dwellfit {
namespace {

constexpr int kMaxGridSteps = 1000000;
// More dwells than a plan may hold: 1e7 (some 1 GB of simulated sweeps).
constexpr double kMaxPlanDwells = 1e7;
// A grid must close on `to` to this fraction of the span: (to - from) / step
// is an integer up to rounding of the decimal inputs.
constexpr double kGridClosureTolerance = 1e-9;

std::string G12(double value) { return StringPrintf("%.12g", value); }

// The unstable middle root of G(a) = a_base^2, between the turning points;
// requires both stable branches to exist there (G(a_lower_end) > a_base^2 >
// G(a_upper_end)).
double MiddleRoot(const ResponseCoefficients<double>& k, const TurningPoints& tp, double a_base) {
  const double target = a_base * a_base;
  auto residual = [&k, target](double a, double* value, double* slope) {
    *value = k.G(a) - target;
    *slope = k.dG(a);
  };
  return BracketedNewton(residual, tp.a_lower_end, tp.a_upper_end,
                         0.5 * (tp.a_lower_end + tp.a_upper_end));
}

}  // namespace

double RoundToSignificantDigits(double value, int digits) {
  char buffer[64];
  std::snprintf(buffer, sizeof(buffer), "%.*g", digits, value);
  return std::strtod(buffer, nullptr);
}

int SweepPlan::NumSteps() const {
  if (!std::isfinite(from) || !std::isfinite(to) || !std::isfinite(step) || !(step > 0.0) ||
      !(to > from)) {
    return -1;
  }
  const double steps = (to - from) / step;
  if (!(steps <= kMaxGridSteps)) return -1;
  const long n = std::lround(steps);
  if (n < 1) return -1;
  if (std::abs(from + static_cast<double>(n) * step - to) > kGridClosureTolerance * (to - from)) {
    return -1;
  }
  return static_cast<int>(n);
}

bool SweepPlan::IsValid(std::string* error) const {
  auto fail = [error](const std::string& what) {
    *error = what;
    return false;
  };
  if (id.empty()) return fail("the sweep id is empty; give every sweep an id");
  if (id.find_first_of(",\"\r\n") != std::string::npos) {
    return fail("sweep id '" + id + "' holds a comma, quote or line break; use plain text");
  }
  const bool frequency = kind == SweepKind::kFrequency;
  const double held = frequency ? held_a_base : held_frequency_hz;
  if (!(held > 0.0) || !std::isfinite(held)) {
    return fail(std::string(frequency ? "the held a_base" : "the held frequency [Hz]") +
                " must be a positive number, got " + G12(held));
  }
  // Named as in a plan file (config/dwell_plan_reader.h).
  const std::string from_key = frequency ? "from_hz" : "a_base_from";
  const std::string to_key = frequency ? "to_hz" : "a_base_to";
  const std::string step_key = frequency ? "step_hz" : "a_base_step";
  if (!(from > 0.0) || !std::isfinite(from)) {
    return fail(from_key + " must be positive, got " + G12(from));
  }
  if (!(to > from) || !std::isfinite(to)) {
    return fail(to_key + " (" + G12(to) + ") must be larger than " + from_key + " (" + G12(from) +
                ")");
  }
  if (!(step > 0.0) || !std::isfinite(step)) {
    return fail(step_key + " must be positive, got " + G12(step));
  }
  // The simulator works in rad/s: the highest frequency must be finite there.
  const double highest_hz = frequency ? to : held_frequency_hz;
  if (!std::isfinite(HzToRadPerSecond(highest_hz))) {
    return fail((frequency ? to_key : std::string("the held frequency")) + " (" + G12(highest_hz) +
                " Hz) is too large (infinite in rad/s)");
  }
  if (NumSteps() < 0) {
    return fail(to_key + " - " + from_key + " (" + G12(to - from) +
                ") must be a whole number of steps of " + step_key + " (" + G12(step) +
                "), at most " + std::to_string(kMaxGridSteps) + "; adjust " + to_key + " or " +
                step_key);
  }
  if (directions.empty()) return fail("no directions; give [up], [down] or [up, down]");
  std::set<SweepDirection> seen;
  for (SweepDirection direction : directions) {
    if (!seen.insert(direction).second) {
      return fail(std::string("direction '") + SweepDirectionName(direction) +
                  "' is given twice; each direction runs once");
    }
  }
  if (start_branch == Branch::kOnly) {
    return fail("the start branch must be 'lower' or 'upper'");
  }
  return true;
}

bool DwellPlan::IsValid(std::string* error) const {
  auto fail = [error](const std::string& what) {
    *error = what;
    return false;
  };
  for (int i = 0; i < kNumParameters; ++i) {
    if (!std::isfinite(truth[i])) {
      return fail(std::string("truth parameter ") + ParameterName(form, i) + " is not finite");
    }
  }
  if (!(truth[kEtaE] > 0.0)) return fail("truth eta_e must be positive, got " + G12(truth[kEtaE]));
  if (!(truth[kNaturalFrequency] > 0.0)) {
    return fail("truth omega must be positive, got " + G12(truth[kNaturalFrequency]) + " rad/s");
  }
  if (truth[kMu1] < 0.0 || truth[kMu2] < 0.0) {
    return fail(std::string("truth damping mu1 and ") + ParameterName(form, kMu2) +
                " must not be negative");
  }
  if (sweeps.empty()) return fail("the plan has no sweeps");
  std::set<std::string> ids;
  double dwells = 0.0;  // of the whole plan, every direction
  for (const SweepPlan& sweep : sweeps) {
    std::string why;
    if (!sweep.IsValid(&why)) return fail("sweep '" + sweep.id + "': " + why);
    if (!ids.insert(sweep.id).second) {
      return fail("sweep id '" + sweep.id + "' is used twice; ids must be unique");
    }
    dwells += (sweep.NumSteps() + 1.0) * static_cast<double>(sweep.directions.size());
  }
  if (dwells > kMaxPlanDwells) {
    return fail("the plan has " + G12(dwells) + " dwells, more than " + G12(kMaxPlanDwells) +
                " (a test of years, and more memory than a run has); give larger steps or "
                "fewer sweeps");
  }
  if (!(noise.relative_sigma >= 0.0 && noise.relative_sigma < 1.0)) {
    return fail("noise relative_sigma must be in [0, 1), got " + G12(noise.relative_sigma));
  }
  return true;
}

std::vector<double> ControlGrid(const SweepPlan& sweep, SweepDirection direction) {
  const int n = sweep.NumSteps();
  CHECK_GE(n, 1) << "sweep '" << sweep.id << "' is not valid";
  std::vector<double> grid(n + 1);
  for (int i = 0; i <= n; ++i) {
    grid[i] = RoundToSignificantDigits(sweep.from + static_cast<double>(i) * sweep.step,
                                       kGridSignificantDigits);
  }
  if (direction == SweepDirection::kDown) std::reverse(grid.begin(), grid.end());
  return grid;
}

SettledDwell SettleDwell(ModelForm form, const ParameterVector& truth, double omega_drive_rad_s,
                         double a_base, Branch side_before, double a_before) {
  const bool from_rest = !(a_before > 0.0);
  const double guess = from_rest ? 0.0 : a_before;
  const StableRoot lower =
      ModelAmplitude(form, truth, omega_drive_rad_s, a_base, Branch::kLower, guess);
  if (lower.status == RootStatus::kFailed) {
    throw InputError("the model has no stable root at " + G12(RadPerSecondToHz(omega_drive_rad_s)) +
                     " Hz, a_base " + G12(a_base) +
                     "; check that the truth parameters are finite and eta_e > 0");
  }
  SettledDwell dwell;
  if (lower.branch == Branch::kOnly) {  // G monotone: one root, no branches
    dwell.amplitude = lower.a;
    return dwell;
  }
  const StableRoot upper =
      ModelAmplitude(form, truth, omega_drive_rad_s, a_base, Branch::kUpper, guess);
  CHECK(upper.status != RootStatus::kFailed);
  const bool lower_exists = lower.status == RootStatus::kOnBranch;
  const bool upper_exists = upper.status == RootStatus::kOnBranch;
  CHECK(lower_exists || upper_exists) << "G always has a stable root";

  Branch side = side_before;
  if (side == Branch::kOnly) {
    // Coming from a monotone G: stay on the side of the saddle the previous
    // amplitude was on.
    if (lower_exists && upper_exists) {
      const auto k =
          ResponseCoefficients<double>::FromParameters(form, truth.data(), omega_drive_rad_s);
      const double saddle = MiddleRoot(k, FindTurningPoints(k), a_base);
      side = !from_rest && a_before > saddle ? Branch::kUpper : Branch::kLower;
    } else {
      side = lower_exists ? Branch::kLower : Branch::kUpper;
    }
  } else if ((side == Branch::kLower && !lower_exists) ||
             (side == Branch::kUpper && !upper_exists)) {
    side = side == Branch::kLower ? Branch::kUpper : Branch::kLower;
    dwell.jumped = !from_rest;
  }
  dwell.side = side;
  dwell.amplitude = side == Branch::kLower ? lower.a : upper.a;
  dwell.branch = lower_exists && upper_exists ? side : Branch::kOnly;
  return dwell;
}

double ResponseLag(ModelForm form, const ParameterVector& truth, double omega_drive_rad_s,
                   double amplitude) {
  const auto k =
      ResponseCoefficients<double>::FromParameters(form, truth.data(), omega_drive_rad_s);
  return std::atan2(k.P(amplitude), k.Q(amplitude));
}

std::vector<Sweep> SimulateDwells(const DwellPlan& plan) {
  std::string error;
  if (!plan.IsValid(&error)) throw InputError("dwell plan: " + error);
  std::vector<Sweep> sweeps;
  for (const SweepPlan& sweep_plan : plan.sweeps) {
    Branch side = sweep_plan.start_branch;
    double a = 0.0;  // at rest before the first dwell
    for (SweepDirection direction : sweep_plan.directions) {
      Sweep sweep{sweep_plan.id, direction, sweep_plan.kind};
      const bool frequency = sweep_plan.kind == SweepKind::kFrequency;
      for (double control : ControlGrid(sweep_plan, direction)) {
        DwellPoint point;
        point.drive_frequency_rad_s =
            HzToRadPerSecond(frequency ? control : sweep_plan.held_frequency_hz);
        point.a_base = frequency ? sweep_plan.held_a_base : control;
        const SettledDwell dwell =
            SettleDwell(plan.form, plan.truth, point.drive_frequency_rad_s, point.a_base, side, a);
        if (dwell.jumped && !sweep.points.empty()) {
          JumpBracket jump;  // its controls and amplitudes once the noise is on
          jump.kind = side == Branch::kLower ? JumpKind::kJumpUp : JumpKind::kJumpDown;
          jump.index_before = static_cast<int>(sweep.points.size()) - 1;
          sweep.jumps.push_back(jump);
        }
        side = dwell.side;
        a = dwell.amplitude;
        point.amplitude = dwell.amplitude;
        point.branch = dwell.branch;
        point.phase_rad =
            ResponseLag(plan.form, plan.truth, point.drive_frequency_rad_s, dwell.amplitude);
        sweep.points.push_back(point);
      }
      sweeps.push_back(std::move(sweep));
    }
  }
  if (plan.noise.relative_sigma > 0.0) {
    // Boost.Random's normal distribution is one implementation everywhere
    // (std::normal_distribution differs between standard libraries), so a
    // seed gives the same data on every platform.
    std::mt19937_64 rng(plan.noise.seed);
    boost::random::normal_distribution<double> standard_normal(0.0, 1.0);
    for (Sweep& sweep : sweeps) {
      for (DwellPoint& point : sweep.points) {
        point.amplitude *= 1.0 + plan.noise.relative_sigma * standard_normal(rng);
      }
    }
  }
  for (Sweep& sweep : sweeps) {
    for (JumpBracket& jump : sweep.jumps) {
      const DwellPoint& before = sweep.points[jump.index_before];
      const DwellPoint& after = sweep.points[jump.index_before + 1];
      jump.control_before = sweep.Control(before);
      jump.control_after = sweep.Control(after);
      jump.amplitude_before = before.amplitude;
      jump.amplitude_after = after.amplitude;
    }
  }
  return sweeps;
}

void DescribeSimulation(const DwellPlan& plan, const std::vector<Sweep>& sweeps,
                        std::ostream* out) {
  const ParameterVector& p = plan.truth;
  const auto names = ParameterNames(plan.form);
  *out << "truth: eta_e " << G12(p[kEtaE]) << ", mu1 " << G12(p[kMu1]) << " 1/s, " << names[kMu2]
       << " " << G12(p[kMu2]) << ", " << names[kDelta] << " " << G12(p[kDelta]) << ", alpha "
       << G12(p[kAlpha]) << ", w " << G12(p[kNaturalFrequency]) << " rad/s ("
       << G12(RadPerSecondToHz(p[kNaturalFrequency])) << " Hz)\n";
  if (plan.noise.relative_sigma > 0.0) {
    *out << "noise: relative_sigma " << G12(plan.noise.relative_sigma) << ", seed "
         << plan.noise.seed << "\n";
  } else {
    *out << "noise: none\n";
  }
  for (const Sweep& sweep : sweeps) {
    const bool frequency = sweep.kind == SweepKind::kFrequency;
    auto control = [frequency](double value) {
      return frequency ? G12(RadPerSecondToHz(value)) + " Hz" : "a_base " + G12(value);
    };
    const auto [low, high] = std::minmax_element(
        sweep.points.begin(), sweep.points.end(),
        [](const DwellPoint& x, const DwellPoint& y) { return x.amplitude < y.amplitude; });
    const DwellPoint& first = sweep.points.front();
    *out << sweep.Name() << ": " << SweepKindName(sweep.kind) << " sweep at "
         << (frequency ? "a_base " + G12(first.a_base)
                       : G12(RadPerSecondToHz(first.drive_frequency_rad_s)) + " Hz")
         << ", " << control(sweep.Control(first)) << " -> "
         << control(sweep.Control(sweep.points.back())) << ", " << sweep.points.size()
         << " dwells, a " << StringPrintf("%.4g", low->amplitude) << " .. "
         << StringPrintf("%.4g", high->amplitude);
    if (sweep.jumps.empty()) *out << ", no jump";
    for (const JumpBracket& jump : sweep.jumps) {
      *out << ", " << JumpKindName(jump.kind) << " between " << control(jump.control_before)
           << " and " << control(jump.control_after) << " (a "
           << StringPrintf("%.4g", jump.amplitude_before) << " -> "
           << StringPrintf("%.4g", jump.amplitude_after) << ")";
    }
    *out << "\n";
  }
}

}  // namespace dwellfit
