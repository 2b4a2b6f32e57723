// Time traces of a sine-dwell test: what a signal analyzer records at every
// dwell, two channels sampled at one rate.
//
//   base      base acceleration from the accelerometer, in the data's a_base
//             unit [B] (e.g. g): the channel's first harmonic is a_base
//   response  strain-gauge output voltage V_out [V] (eq. 3.4)
//
// On disk a trace set is a folder holding two files:
//
//   traces.csv  one header row, then one row per dwell in measurement order:
//     sweep,direction,kind,freq_hz,sample_rate_hz,base_samples,response_samples
//       sweep, direction  as in the sweeps CSV (estimator/data/sweep_csv.h)
//       kind              `frequency` or `amplitude`: which control the sweep steps
//       freq_hz           drive frequency [Hz] (the analyzer's source setting)
//       sample_rate_hz    samples per second of each channel
//       base_samples, response_samples  the number of samples of each channel
//       samples_crc32     CRC-32 of the dwell's samples in traces.f32, 8 hex
//                         digits (optional: sets written before it lack it)
//   traces.f32  the samples as little-endian IEEE-754 float32, dwell after
//               dwell in the order of traces.csv, each dwell's base channel
//               then its response channel (no header, no padding).
//
// float32 keeps 7 significant digits, far below any rig's noise. Before it
// allocates, the reader checks that the binary file holds exactly the samples
// the index announces; then each dwell's CRC (refusing files of two runs).
#ifndef DWELLFIT_ESTIMATOR_TRACES_TRACE_FILE_H_
#define DWELLFIT_ESTIMATOR_TRACES_TRACE_FILE_H_

#include <string>
#include <vector>

#include "dwellfit/estimator/data/sweep.h"

namespace dwellfit {

// The records of one dwell.
struct DwellTrace {
  std::string sweep;  // the sweep id
  SweepDirection direction = SweepDirection::kUp;
  SweepKind kind = SweepKind::kFrequency;
  double drive_frequency_rad_s = 0.0;  // Omega (Hz on disk)
  double sample_rate_hz = 0.0;         // samples per second of each channel
  std::vector<float> base;             // base acceleration [B]
  std::vector<float> response;         // strain-gauge voltage [V]
  int source_line = 0;                 // line of traces.csv (0: not read from disk)
  std::string source_file;             // the index read ("": traces.csv)

  // "F0.01/up @ 41.3 Hz (traces.csv:12)": names the dwell in messages.
  std::string Describe() const;
};

// The file names inside a trace folder.
inline constexpr char kTraceIndexFile[] = "traces.csv";
inline constexpr char kTraceSamplesFile[] = "traces.f32";

// The columns every trace index (traces.csv, the UFF index of uff58_traces.h)
// begins with: sweep, direction, kind and freq_hz, as `fields` [0, 4) of line
// `line` of `file`, into `trace`. Throws InputError naming the file, the line
// and the field.
void ReadDwellColumns(const std::string& file, int line, const char* const* fields,
                      DwellTrace* trace);

// Writes `dwells` into `folder` (created when missing) as the two files
// above, each written under a temporary name and renamed, so a failed write
// leaves no half-written trace set. Throws InputError when it cannot write.
void WriteTraceSet(const std::vector<DwellTrace>& dwells, const std::string& folder);

// Reads a trace folder. Throws InputError naming the file, the line and the
// field for a bad index row, and naming the binary file when its size does
// not match the index.
std::vector<DwellTrace> ReadTraceSet(const std::string& folder);

}  // namespace dwellfit

#endif  // DWELLFIT_ESTIMATOR_TRACES_TRACE_FILE_H_
