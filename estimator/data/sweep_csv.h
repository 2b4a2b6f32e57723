// Loading sine-dwell sweeps from a CSV file.
//
// Format: one header row, then one row per dwell in measurement order.
//   sweep      sweep id (text); rows with one id and one direction form a Sweep
//   direction  `up` or `down`
//   freq_hz    drive frequency [Hz], in [1e-6, 1e9] (stored as rad/s)
//   a_base     base excitation level (data's unit, e.g. g), in [1e-20, 1e20]
//   a          response amplitude (data's unit), in [1e-20, 1e20]; a <= 0
//              marks a missing measurement (no measurement, not a zero
//              response): the row is no dwell; it is counted and kept in
//              Sweep::missing, not an error
//   phase_deg | phase_rad   optional response lag gamma (one of them at most;
//              any finite number, not used by the fit)
//   sigma      optional standard deviation of `a` (same unit as a), in
//              [1e-20, 1e20]
//   a_base_sigma  optional standard deviation of `a_base` (same unit as
//              a_base), in [1e-20, 1e20]: the measured level's noise, which
//              the intervals then count (estimator/analysis/level_noise.h).
//              A frequency sweep's rows share one level and so one error:
//              they must all state the same a_base_sigma (an error names
//              the first row that differs); an amplitude sweep's rows each
//              state their own
// Columns may come in any order; any other column is an error. Fields are
// separated by commas; a field may be double-quoted ("A,1" is one field) and
// is trimmed of spaces and tabs; numbers take a '.' decimal point; blank lines
// are skipped; lines may end in LF or CRLF (not CR alone); a UTF-8 byte-order
// mark before the header is skipped.
//
// The bounds keep the model's powers (up to a^6 and Omega^4) and the squared
// residuals within about 1e+-240: normal doubles, far from overflow and
// subnormal underflow.
//
// Order: within a sweep, the control (freq_hz in a frequency sweep, a_base in
// an amplitude sweep) must rise from row to row in an up-sweep and fall in a
// down-sweep; repeats are allowed. Measurement order is what places the jumps,
// so a sweep out of order (shuffled, reversed, a file appended to itself) is
// an error naming the first row out of order, never sorted. A row that
// repeats its sweep's previous row value for value (a copied row) is an
// error. A sweep of one row is loaded (it has no step, so no jump).
#ifndef DWELLFIT_ESTIMATOR_DATA_SWEEP_CSV_H_
#define DWELLFIT_ESTIMATOR_DATA_SWEEP_CSV_H_

#include <functional>
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

// Why `path` cannot be read as a data file ("is a directory", "is a character
// device (such as /dev/null), not a file", ...); "" for a regular file or a
// path that does not exist.
std::string NotARegularFile(const std::string& path);

// Reads the sweeps in `path`. Frequencies are converted to rad/s and phases to
// radians here. Each sweep's kind follows from which control varies within it
// (freq_hz: frequency sweep; a_base: amplitude sweep; neither: a frequency
// sweep of repeated dwells). Dropped rows are reported with LOG(WARNING) and
// listed, with where they fell among the dwells, in Sweep::missing (jump
// detection reads a sweep ending in missing rows as a jump into missing data).
// Throws InputError naming file, line and column for any malformed content.
LoadedSweeps LoadSweepsCsv(const std::string& path);

// One row of a sweeps table as the text of its fields (the columns above); a
// column the table lacks stays nullptr. Readers of other file formats (the
// MAT file's, estimator/matfile) hand their rows over as text, so that every
// source passes the checks of the CSV's rows.
struct SweepRowFields {
  char* sweep = nullptr;
  char* direction = nullptr;
  char* freq_hz = nullptr;
  char* a_base = nullptr;
  char* a = nullptr;
  char* phase_deg = nullptr;
  char* phase_rad = nullptr;
  char* sigma = nullptr;
  char* a_base_sigma = nullptr;
};

// Fills the next row and its 1-based position `line` (named in errors);
// returns false after the last row.
using SweepRowSource = std::function<bool(SweepRowFields* row, int* line)>;

// What LoadSweepsCsv does after the header, for rows from any source: checks
// and assembles them into sweeps. Errors name `path` and the row's line
// (`header_line` when there is no row). The source checks the column set.
LoadedSweeps LoadSweepsFromRows(const std::string& path, int header_line,
                                const SweepRowSource& next_row);

}  // namespace dwellfit

#endif  // DWELLFIT_ESTIMATOR_DATA_SWEEP_CSV_H_
