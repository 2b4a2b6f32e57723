// Writing sine-dwell sweeps in the project's CSV format (read by
// LoadSweepsCsv, estimator/data/sweep_csv.h).
//
// Header `sweep,direction,freq_hz,a_base,a`, plus `phase_rad`, `sigma` and
// `a_base_sigma` when the points carry them (each all or nothing; a frequency
// sweep's dwells, which share one a_base, share one a_base_sigma too); then
// one row per dwell, sweeps in the given order and each sweep's points in
// measurement order. Every number is printed so that reading it back gives
// the same double:
//   freq_hz  the shortest decimal f with HzToRadPerSecond(f) equal to the
//            point's drive_frequency_rad_s (so 41.5, not 41.500000000000007);
//   others   the shortest round-trip representation (std::to_chars).
#ifndef DWELLFIT_ESTIMATOR_DATA_SWEEP_CSV_WRITER_H_
#define DWELLFIT_ESTIMATOR_DATA_SWEEP_CSV_WRITER_H_

#include <ostream>
#include <string>
#include <vector>

#include "dwellfit/estimator/data/sweep.h"

namespace dwellfit {

// The shortest decimal text that reads back as exactly `value`.
std::string FormatRoundTrip(double value);

// The shortest decimal frequency [Hz] f such that HzToRadPerSecond(f) ==
// omega_rad_s; the round-trip text of RadPerSecondToHz(omega_rad_s) when no
// decimal maps back exactly.
std::string FormatFrequencyHz(double omega_rad_s);

// Writes `sweeps` as CSV. Throws InputError when some points carry a phase,
// sigma or a_base_sigma and others do not (each column is all or nothing),
// when the dwells of a sweep with one a_base differ in a_base_sigma (the
// reader would refuse them), or when a sweep id cannot be written as a plain
// CSV field.
void WriteSweepsCsv(const std::vector<Sweep>& sweeps, std::ostream* out);

// WriteSweepsCsv into the file `path` (created or replaced, by WriteFileAtomically).
void WriteSweepsCsvFile(const std::vector<Sweep>& sweeps, const std::string& path);

// Writes `text` to `path` through a temporary file renamed into place, so a
// failed write leaves no half-written file. Throws InputError when it cannot.
void WriteFileAtomically(const std::string& text, const std::string& path);

}  // namespace dwellfit

#endif  // DWELLFIT_ESTIMATOR_DATA_SWEEP_CSV_WRITER_H_
