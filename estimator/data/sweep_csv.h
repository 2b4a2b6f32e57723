// Loading sine-dwell sweeps from a CSV file.
//
// Format: one header row, then one row per dwell in measurement order.
//   sweep      sweep id (text); rows with one id and one direction form a Sweep
//   direction  `up` or `down`
//   freq_hz    drive frequency [Hz] > 0 (stored as rad/s)
//   a_base     base excitation level > 0 (data's unit, e.g. g)
//   a          response amplitude (data's unit); a <= 0 marks a missing
//              measurement (no measurement, not a zero response): the row is
//              no dwell; it is counted and kept in Sweep::missing, not an error
//   phase_deg | phase_rad   optional response lag gamma (one of them at most)
//   sigma      optional standard deviation of `a` (> 0, same unit as a)
// Columns may come in any order; any other column is an error.
#ifndef DWELLFIT_ESTIMATOR_DATA_SWEEP_CSV_H_
#define DWELLFIT_ESTIMATOR_DATA_SWEEP_CSV_H_

#include <string>
#include <vector>

#include "dwellfit/estimator/data/sweep.h"

namespace dwellfit {

struct LoadedSweeps {
  // One Sweep per (sweep id, direction) in order of first appearance; sweeps
  // whose every row had a <= 0 are left out (see `all_dropped`).
  std::vector<Sweep> sweeps;
  // Rows with a <= 0 over the whole file, including those of left-out sweeps.
  int dropped_nonpositive = 0;
  // Names ("id/up") of the sweeps left out because no row had a > 0.
  std::vector<std::string> all_dropped;
};

// Reads the sweeps in `path`. Frequencies are converted to rad/s and phases to
// radians here. Each sweep's kind follows from which control varies within it
// (freq_hz: frequency sweep; a_base: amplitude sweep; neither: a frequency
// sweep of repeated dwells). Dropped rows are reported with LOG(WARNING) and
// listed, with where they fell among the dwells, in Sweep::missing (jump
// detection reads a sweep ending in missing rows as a jump into missing data).
// Throws InputError naming file, line and column for any malformed content.
LoadedSweeps LoadSweepsCsv(const std::string& path);

}  // namespace dwellfit

#endif  // DWELLFIT_ESTIMATOR_DATA_SWEEP_CSV_H_
