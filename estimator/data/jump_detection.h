// Jumps in measured sweeps and the stable branch of every dwell.
//
// A sweep of the single-mode model passes at most one saddle-node fold
// (docs/model.md, "Stability and folds"), so it shows at most one jump: a step
// between consecutive dwells that brackets the fold and splits the sweep into
// the branch before and after it. A JumpOverride (the config's `jumps:`)
// replaces what detection found for one sweep.
#ifndef DWELLFIT_ESTIMATOR_DATA_JUMP_DETECTION_H_
#define DWELLFIT_ESTIMATOR_DATA_JUMP_DETECTION_H_

#include <string>
#include <vector>

#include "dwellfit/estimator/data/sweep.h"

namespace dwellfit {

// Jump detection in measured sweeps (config/README.md, `jump_detection`, has
// the data sets behind these defaults).
struct JumpDetectionOptions {
  // A jump's step changes the amplitude by more than this ratio, either way
  // (in an amplitude sweep: beyond the power-law trend in a_base) ...
  double min_ratio = 1.07;
  // ... its larger side reaches this fraction of the sweep's largest
  // amplitude (ignores hops in the noise floor far from resonance) ...
  double min_relative_amplitude = 0.2;
  // ... and its log ratio exceeds this many robust standard deviations of
  // the sweep's steps (0: no noise test).
  double noise_multiple = 6.0;
  // Sweeps with fewer candidate steps get no detected jump (too few to tell
  // a jump from noise).
  int min_candidate_steps = 5;
  bool IsValid(std::string* error) const;
};

// What DetectJumps weighs in one sweep (for logs, reports and tests).
//
// Steps r_i = ln(a_{i+1} / a_i) between consecutive dwells; candidates: steps
// whose larger side reaches min_relative_amplitude of the sweep's largest
// amplitude and whose two controls differ (a fold cannot lie between equal
// controls). Excess e_i = r_i - p ln(c_{i+1} / c_i): an amplitude sweep's
// response grows like a_base^p by itself, p the median of r_i / ln(c_{i+1} /
// c_i) over the candidates; a frequency sweep has p = 0. Noise: 1.4826 MAD(e)
// over the candidates (not the noisier floor far from resonance); the MAD
// ignores the jump itself and a smeared transition of a few steps.
struct JumpEvidence {
  int candidate_steps = 0;
  int step = -1;             // the candidate with the largest |e_i| (-1: none)
  double log_ratio = 0.0;    // r of that step
  double log_excess = 0.0;   // e of that step
  double trend_slope = 0.0;  // p (0 for a frequency sweep)
  double noise_sigma = 0.0;  // 1.4826 MAD(e) over the candidates
  // max(ln(min_ratio), noise_multiple * noise_sigma): the step is a jump when
  // |log_excess| exceeds it and candidate_steps >= min_candidate_steps.
  double threshold = 0.0;
  bool accepted = false;
};

// The evidence for a jump between dwells of `sweep` (see JumpEvidence).
// `options` must be valid; every amplitude must be positive.
JumpEvidence WeighJumpEvidence(const JumpDetectionOptions& options, const Sweep& sweep);

// Finds at most one jump in `sweep` and labels every point's branch.
//
// The jump is the step WeighJumpEvidence accepts: amplitude rising across it
// is a jump up, falling a jump down.
// Limits: a smooth but nearly vertical flank just below the onset of
// hysteresis, or a sharp peak sampled by a handful of dwells, can pass for a
// jump or hide one; state such sweeps in the config (`jumps:`).
//
// Jump into missing data: when no step is accepted, every row after the last
// dwell is missing (Sweep::missing) and the last dwell reaches
// min_relative_amplitude of the largest, the response left its branch
// unrecorded: a jump down to the first missing row at another control.
//
// Labels: before a jump down Branch::kUpper and after it kLower; before a jump
// up kLower and after it kUpper; no jump: every point kOnly. Replaces any
// previous `sweep->jumps`. `options` must be valid (IsValid).
void DetectJumps(const JumpDetectionOptions& options, Sweep* sweep);

// DetectJumps on each sweep.
void DetectJumps(const JumpDetectionOptions& options, std::vector<Sweep>* sweeps);

// A jump (or its absence) stated for one sweep, replacing detection.
struct JumpOverride {
  std::string sweep;  // one direction, as Sweep::Name(): "L0.060g/down"
  bool none = false;  // the sweep has no jump: every dwell on the only branch
  JumpKind kind = JumpKind::kJumpUp;
  // Which control the bracket is given in: the drive frequency (rad/s here;
  // the config's between_hz) for a frequency sweep, a_base for an amplitude one.
  SweepKind control = SweepKind::kFrequency;
  // The bracket in measurement order (rad/s or a_base).
  double control_before = 0.0;
  double control_after = 0.0;
  // Where the config states it, for errors: its line (0: unknown, e.g. set on
  // the command line) and key path ("jumps[0]").
  int line = 0;
  std::string field = "jumps";
};

// Replaces the jumps of `sweep` with `jump_override` and relabels its branches
// as DetectJumps would. Throws InputError naming `config_path` and the sweep
// when the bracket's control does not match the sweep's kind, runs against
// the sweep's direction, or does not lie between two consecutive dwells.
void ApplyJumpOverride(const JumpOverride& jump_override, const std::string& config_path,
                       Sweep* sweep);

// ApplyJumpOverride on the sweep each override names; an override of a sweep
// not in `sweeps` throws InputError listing the available ones.
void ApplyJumpOverrides(const std::vector<JumpOverride>& overrides, const std::string& config_path,
                        std::vector<Sweep>* sweeps);

// One line per sweep for logs and reports, frequencies in Hz, e.g.
//   "F/up: jump_down between 42.20 and 42.30 Hz (a 4.7e-3 -> 2.8e-4)"
//   "F/down: no jump (41 dwells, largest a 1.0e-3)"
// A jump stated in the config ends in " [config]"; one whose direction fits
// a softening response, or no response of the model, gets a note.
std::string DescribeJumps(const Sweep& sweep);

}  // namespace dwellfit

#endif  // DWELLFIT_ESTIMATOR_DATA_JUMP_DETECTION_H_
