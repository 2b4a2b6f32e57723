// Jumps in measured sweeps and the stable branch of every dwell.
//
// In a stepped dwell test of the single-mode model (model.md, "Stability and
// folds") a sweep passes at most one saddle-node fold, so it shows at most one
// jump: a step between consecutive dwells where the response leaves one stable
// branch for the other. The detected jump brackets the fold between its two
// control values and splits the sweep into the branch before and after it.
#ifndef DWELLFIT_ESTIMATOR_JUMP_DETECTION_H_
#define DWELLFIT_ESTIMATOR_JUMP_DETECTION_H_

#include <string>
#include <vector>

#include "estimator/identification_options.h"
#include "estimator/sweep.h"

namespace dwellfit {

// Finds at most one jump in `sweep` and labels every point's branch.
//
// Candidates are steps i -> i+1 between consecutive dwells whose larger side
// reaches options.min_relative_amplitude * (largest amplitude of the sweep);
// this keeps hops in the noise floor far from resonance out. The candidate
// with the largest |ln(a_{i+1} / a_i)| is the jump if a_{i+1} / a_i (or its
// inverse) exceeds options.min_ratio. Amplitude rising across it is a jump up,
// falling a jump down.
//
// Labels: before a jump down Branch::kUpper and after it kLower; before a jump
// up kLower and after it kUpper; no jump: every point kOnly. Replaces any
// previous `sweep->jumps`. `options` must be valid (IsValid).
void DetectJumps(const JumpDetectionOptions& options, Sweep* sweep);

// DetectJumps on each sweep.
void DetectJumps(const JumpDetectionOptions& options, std::vector<Sweep>* sweeps);

// One line per sweep for logs and reports, frequencies in Hz, e.g.
//   "F/up: jump_down between 42.20 and 42.30 Hz (a 4.7e-3 -> 2.8e-4)"
//   "A/up: jump_up between a_base 0.0350 and 0.0360 (a 1.2e-3 -> 4.1e-3)"
//   "F/down: no jump (41 dwells, largest a 1.0e-3)"
std::string DescribeJumps(const Sweep& sweep);

}  // namespace dwellfit

#endif  // DWELLFIT_ESTIMATOR_JUMP_DETECTION_H_
