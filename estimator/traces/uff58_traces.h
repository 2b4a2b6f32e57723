// Dwell traces (trace_file.h) from UFF data set 58 time histories
// (uff58.h): what a test system exports, channel by channel, mapped to dwells
// by a small index beside the UFF files.
//
// The index is a CSV file, one header row, then one row per dwell in
// measurement order:
//
//   sweep,direction,kind,freq_hz,file,base,response,base_unit
//     sweep, direction, kind, freq_hz  as in traces.csv (trace_file.h)
//     file       the UFF file holding the dwell's two channels, relative to
//                the index's folder (ASCII 58 or binary 58b; any number of
//                dwells per file, other data sets are skipped)
//     base       the data set 58 of the base channel (base acceleration)
//     response   the data set 58 of the response channel (strain-gauge volts)
//     base_unit  the unit of the data's a_base (e.g. g): the base channel's
//                ordinate units label (record 9) must be exactly this, the
//                response channel's must be V
//
// A data set is selected by one of
//   fid:N      its function identification number (record 6, field 2)
//   node:N:D   its response node N and direction D (record 6, fields 6-7)
//   id:TEXT    its ID line 1 (record 1), blanks around it ignored
// and the selector must match exactly one data set 58 of the file.
//
// Each selected data set must be a real, evenly sampled time history
// (function type 0 or 1) whose abscissa is time in seconds (units label "s",
// or no label and specific data type 17); the sample rate is 1/increment.
// The increment is written with 6 significant digits (E13.5), so a rate
// within 5e-6 (relative) of a whole number of Hz is taken as that whole
// number (1/4.88281E-04 s = 2048.0013 Hz reads as 2048 Hz, as the analyzer
// sampled). Both channels of a dwell must have the same rate.
#ifndef DWELLFIT_ESTIMATOR_TRACES_UFF58_TRACES_H_
#define DWELLFIT_ESTIMATOR_TRACES_UFF58_TRACES_H_

#include <string>
#include <vector>

#include "dwellfit/estimator/traces/trace_file.h"

namespace dwellfit {

// The sample rate [Hz] of an abscissa increment [s], as described above.
double SampleRateFromIncrement(double increment_s);

// Reads the dwells an index names. Throws InputError naming the index, its
// line and field (and the UFF file's line or byte offset, through
// ReadUff58File) for what it cannot read or what does not match.
std::vector<DwellTrace> ReadUffTraceSet(const std::string& index_path);

// Writes `dwells` as one UFF file `uff_path` (58b binary, single precision;
// or ASCII 58 in double precision E20.12, which keeps every float32 sample
// exact) and its index `index_path` (the file named relative to the index's
// folder), the base channels labelled in `base_unit`. Data sets 2k+1 and 2k+2
// (function ids) are dwell k's base and response. Throws InputError when it
// cannot write.
void WriteUffTraceSet(const std::vector<DwellTrace>& dwells, const std::string& uff_path,
                      const std::string& index_path, bool binary, const std::string& base_unit);

}  // namespace dwellfit

#endif  // DWELLFIT_ESTIMATOR_TRACES_UFF58_TRACES_H_
