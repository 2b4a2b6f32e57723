// Loading sine-dwell sweeps from a MATLAB MAT file (v5, v7 and v7.3/HDF5)
// through libmatio; layout and examples in docs/matlab.md.
//
// One variable per column of the sweeps CSV (estimator/data/sweep_csv.h), of
// the same name, meaning and unit, each holding one value per row:
//   sweep, direction     cell arrays of char strings (ids; 'up' or 'down'), or
//                        char matrices of one row each (padding cut off)
//   freq_hz, a_base, a   double vectors (freq_hz in Hz)
//   phase_deg | phase_rad, sigma, a_base_sigma   optional double vectors
// Vectors may be columns or rows; all have the same length. Any other
// variable is an error, as any other CSV column is. Row i of the variables is
// the CSV's row i: the rows pass the same checks and give the same sweeps,
// the numbers as the same doubles (handed over as round-trip text).
#ifndef DWELLFIT_ESTIMATOR_MATFILE_MAT_SWEEPS_H_
#define DWELLFIT_ESTIMATOR_MATFILE_MAT_SWEEPS_H_

#include <string>

#include "dwellfit/estimator/data/sweep_csv.h"

namespace dwellfit {

// True when `path` ends in ".mat" (any case): a data file read by LoadSweepsMat.
bool IsMatFileName(const std::string& path);

// Reads the sweeps in the MAT file `path`, like LoadSweepsCsv. Throws
// InputError naming the file, the variable and the 1-based row, and saying
// what to do: not a MAT file, a variable missing, unknown or of the wrong
// class or shape, lengths that differ, and every check of a CSV row.
LoadedSweeps LoadSweepsMat(const std::string& path);

}  // namespace dwellfit

#endif  // DWELLFIT_ESTIMATOR_MATFILE_MAT_SWEEPS_H_
