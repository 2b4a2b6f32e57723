// Sine-dwell data: points, sweeps and the jumps measured in them.
//
// A sweep is the ordered list of dwells with one `sweep` id and one direction.
// Its kind follows from which control varies: the drive frequency (frequency
// sweep, a_base fixed) or the base level (amplitude sweep, frequency fixed).
// Frequencies are rad/s here; files carry Hz and are converted once, at load.
#ifndef DWELLFIT_ESTIMATOR_DATA_SWEEP_H_
#define DWELLFIT_ESTIMATOR_DATA_SWEEP_H_

#include <cmath>
#include <optional>
#include <string>
#include <vector>

#include "dwellfit/residuals/model/stable_root.h"
#include "dwellfit/residuals/model/sweep_vocabulary.h"

namespace dwellfit {

enum class SweepDirection { kUp, kDown };

const char* SweepDirectionName(SweepDirection direction);
bool SweepDirectionFromName(const std::string& name, SweepDirection* direction);

// One steady-state dwell.
struct DwellPoint {
  double drive_frequency_rad_s = 0.0;  // Omega
  double a_base = 0.0;                 // base excitation level (data's unit, e.g. g)
  double amplitude = 0.0;              // measured response amplitude a (data's unit)
  std::optional<double> phase_rad;     // response lag gamma, when measured
  std::optional<double> sigma;         // standard deviation of `amplitude`, when given
  Branch branch = Branch::kOnly;       // stable branch it was measured on
  int source_line = 0;                 // 1-based line in the source file (0: generated)
  // Standard deviation of `a_base` (data's unit), when known: the measured
  // level's own noise (estimator/analysis/level_noise.h). A frequency sweep's
  // dwells share one level and so one error.
  std::optional<double> a_base_sigma;
};

// A jump between two consecutive dwells: the model's fold lies between the two
// control values (eq. 3.17 uses the bracket's centre and half-width).
struct JumpBracket {
  JumpKind kind = JumpKind::kJumpDown;
  int index_before = 0;         // index of the last dwell before the jump
  double control_before = 0.0;  // rad/s (frequency sweep) or a_base (amplitude sweep)
  double control_after = 0.0;
  double amplitude_before = 0.0;  // measured a on either side
  double amplitude_after = 0.0;   // 0 when into_missing_data
  // The jump leads into rows recorded as missing (a <= 0) up to the sweep's
  // end: `index_before` is the last dwell, control_after the control of the
  // first missing row after it, and no dwell follows on the new branch.
  bool into_missing_data = false;

  double centre() const { return 0.5 * (control_before + control_after); }
  double half_width() const { return 0.5 * std::abs(control_after - control_before); }
};

// A row of the sweep whose amplitude was recorded as a <= 0: no measurement
// (not a zero response), so it is no dwell; kept for where it was.
struct MissingDwell {
  double drive_frequency_rad_s = 0.0;
  double a_base = 0.0;
  int points_before = 0;  // dwells of the sweep measured before it
  int source_line = 0;    // 1-based line in the source file
};

struct Sweep {
  std::string id;  // the `sweep` column
  SweepDirection direction = SweepDirection::kUp;
  SweepKind kind = SweepKind::kFrequency;
  std::vector<DwellPoint> points;  // in measurement order
  std::vector<JumpBracket> jumps;  // filled by jump detection
  // True when `jumps` (and the branch labels) were stated in the config
  // (ApplyJumpOverride) instead of detected.
  bool jumps_from_config = false;
  std::string source_file;
  int dropped_nonpositive = 0;        // rows with a <= 0, treated as missing
  std::vector<MissingDwell> missing;  // those rows, in measurement order

  // "id/up" or "id/down": the name a config uses to select one direction.
  std::string Name() const;
  // The control that varies: Omega [rad/s] or a_base.
  double Control(const DwellPoint& point) const {
    return kind == SweepKind::kFrequency ? point.drive_frequency_rad_s : point.a_base;
  }
  double Control(const MissingDwell& row) const {
    return kind == SweepKind::kFrequency ? row.drive_frequency_rad_s : row.a_base;
  }
};

}  // namespace dwellfit

#endif  // DWELLFIT_ESTIMATOR_DATA_SWEEP_H_
