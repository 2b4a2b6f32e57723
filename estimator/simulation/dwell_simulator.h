// A stepped sine-dwell test, simulated on the model (docs/model.md).
//
// A dwell test steps one control, the drive frequency Omega (frequency sweep,
// a_base held) or the base level a_base (amplitude sweep, Omega held), and at
// every step waits for the steady state before measuring the amplitude. The
// response stays on the stable branch it is on for as long as that branch
// exists, and jumps to the other stable branch where it ends (a saddle-node
// fold). The simulator reproduces exactly that on the fixed points
// G(a; Omega) = a_base^2 of (3.11):
//
//   side    the stable branch the response is on: Branch::kLower (smallest
//           positive root), kUpper (largest), or kOnly where G is monotone;
//   dwell   SolveStableRoot on `side`; RootStatus::kBranchEnd means the branch
//           no longer reaches a_base, so the response jumps to the other one.
//
// Where G has turning points but the response was on a monotone G before
// (side kOnly), the response goes to the stable root on the same side of the
// unstable middle root as the previous amplitude (or the only stable root).
// A sweep's directions run back to back from one state, as a real test does:
// "up" then "down" continues from where "up" ended.
#ifndef DWELLFIT_ESTIMATOR_SIMULATION_DWELL_SIMULATOR_H_
#define DWELLFIT_ESTIMATOR_SIMULATION_DWELL_SIMULATOR_H_

#include <cstdint>
#include <ostream>
#include <string>
#include <vector>

#include "dwellfit/estimator/data/sweep.h"
#include "dwellfit/residuals/model/model_parameters.h"
#include "dwellfit/residuals/model/stable_root.h"

namespace dwellfit {

// Significant digits of a control value on a sweep grid: from + i step is
// rounded to this many digits, so that 41.5 is 41.5 and not 41.500000000000007.
inline constexpr int kGridSignificantDigits = 12;

// One sweep of the plan.
struct SweepPlan {
  std::string id;  // the `sweep` column, e.g. "F0.01" or "A41.5"
  SweepKind kind = SweepKind::kFrequency;
  double held_a_base = 0.0;        // frequency sweep: the base level held
  double held_frequency_hz = 0.0;  // amplitude sweep: the drive frequency held [Hz]
  // The stepped control: drive frequency [Hz] for a frequency sweep, a_base for
  // an amplitude sweep. Grid: from + i step, i = 0..n, with from + n step = to.
  double from = 0.0;
  double to = 0.0;
  double step = 0.0;
  // Run back to back from one state; "up" goes from -> to, "down" to -> from.
  std::vector<SweepDirection> directions = {SweepDirection::kUp, SweepDirection::kDown};
  // Branch of the first dwell: kLower is the rest-like start (smallest stable
  // root); kUpper starts on the largest. Used only where both exist.
  Branch start_branch = Branch::kLower;

  // Number of grid intervals n, or -1 when the plan is not valid.
  int NumSteps() const;
  // False, with a reason in `error`, when the values cannot make a sweep.
  bool IsValid(std::string* error) const;
};

// Multiplicative measurement noise: a *= 1 + relative_sigma N(0, 1), N drawn
// from std::mt19937_64(seed) through boost::random::normal_distribution, one
// draw per dwell in output order.
struct DwellNoise {
  double relative_sigma = 0.0;  // 0: noise-free
  std::uint64_t seed = 0;
};

struct DwellPlan {
  ParameterVector truth{};  // ParameterIndex layout; omega in rad/s
  ModelForm form;           // the response model the dwells follow (model_form.h)
  std::vector<SweepPlan> sweeps;
  DwellNoise noise;

  bool IsValid(std::string* error) const;
};

// The grid values of the stepped control of one direction, in measurement
// order, each from + i step (never an accumulated sum) rounded to
// kGridSignificantDigits. `sweep` must be valid.
std::vector<double> ControlGrid(const SweepPlan& sweep, SweepDirection direction);

// `value` rounded to `digits` significant decimal digits (as printed by %.*g).
double RoundToSignificantDigits(double value, int digits);

// The response settled at one dwell.
struct SettledDwell {
  double amplitude = 0.0;       // the stable root, noise-free
  Branch side = Branch::kOnly;  // branch the response is on (kOnly: G monotone)
  // Branch as recorded in DwellPoint::branch: `side` where two stable roots
  // exist at this control, kOnly where the response is single-valued.
  Branch branch = Branch::kOnly;
  bool jumped = false;  // `side_before` ended here (never on a first dwell)
};

// Settles one dwell at (omega_drive_rad_s, a_base) from the state of the
// previous dwell: the branch it was on and its amplitude (a_before <= 0: no
// previous dwell, start from rest). Throws InputError when the model has no
// root there (parameters not finite or eta_e = 0).
SettledDwell SettleDwell(ModelForm form, const ParameterVector& truth, double omega_drive_rad_s,
                         double a_base, Branch side_before, double a_before);

// The lag gamma [rad] of the response behind the base excitation at a fixed
// point of amplitude `amplitude` (docs/model.md, "Phase convention"):
// gamma = atan2(P(a), Q(a)) of eqs. (3.1)-(3.2), in (0, pi) for positive damping.
double ResponseLag(ModelForm form, const ParameterVector& truth, double omega_drive_rad_s,
                   double amplitude);

// Simulates every sweep of `plan`: one Sweep per (sweep, direction), in plan
// order, with kind, direction, id, points (drive_frequency_rad_s, a_base,
// amplitude with noise, the noise-free phase lag ResponseLag, true branch;
// source_line 0) and the true jumps (controls in rad/s or a_base, amplitudes
// as output). Deterministic. Throws InputError when the plan is not valid.
std::vector<Sweep> SimulateDwells(const DwellPlan& plan);

// A short human-readable account of the plan in effect and of each simulated
// sweep (dwells, amplitude range, jumps with their brackets in Hz or a_base).
void DescribeSimulation(const DwellPlan& plan, const std::vector<Sweep>& sweeps, std::ostream* out);

}  // namespace dwellfit

#endif  // DWELLFIT_ESTIMATOR_SIMULATION_DWELL_SIMULATOR_H_
