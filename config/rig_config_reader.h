// Reading a rig description (simulate_rig, process_traces) from YAML.
//
//   sample_rate_hz: 2048        # samples per second of each channel
//   record_periods: 16          # drive periods recorded per dwell
//   settling:                   # optional (simulate_rig; estimator/rig/rig_simulator.h)
//     tolerance: 1.0e-4         # relative change of the first harmonic over a window
//     window_periods: 50
//     max_periods: 20000        # a dwell not settled by then is recorded as unsettled
//   channels:                   # optional
//     skew_samples: 0.5         # response sampled half a sample after the base
//     base_filter_hz: 0         # one-pole low-pass cutoff [Hz]; 0 or absent: none
//     response_filter_hz: 200
//   noise:                      # optional (simulate_rig); default none
//     relative_sigma: 0.005     # of each dwell's amplitudes (rig_simulator.h)
//     base_relative_sigma: 0    # optional: the base channel's own; default relative_sigma
//     seed: 1
//   beam:                       # the beam and its mode (estimator/traces/strain_gauge.h)
//     boundary: cantilever      # or clamped_clamped
//     mode: 1                   # 1, 2 or 3
//     length_m: 0.8382
//     thickness_m: 7.9375e-4
//     gauge_position_m: 0.0254  # from the clamp
//   gauge:                      # the bridge: eq. (3.4)
//     excitation_v: 5
//     gain: 1000
//     gauge_factor: 2.1
//   processing:                 # optional (process_traces; trace_processing.h)
//     correct_channels: true    # undo the skew and the filters
//     harmonics: 3
//     settle_tolerance: 5.0e-3
//     harmonic_warning_ratio: 0.05
//     level_tolerance: 0.01
//
// Keys are strict as in identify's config; errors name the file, line and key.
#ifndef DWELLFIT_CONFIG_RIG_CONFIG_READER_H_
#define DWELLFIT_CONFIG_RIG_CONFIG_READER_H_

#include <string>

#include "dwellfit/estimator/rig/rig_simulator.h"
#include "dwellfit/estimator/traces/trace_processing.h"

namespace dwellfit {

struct RigConfig {
  RigOptions rig;                     // what simulate_rig needs
  TraceProcessingOptions processing;  // what process_traces needs (same channels and gauge)
};

// Parses the YAML text; `source` names it in errors. Throws InputError.
RigConfig ParseRigConfig(const std::string& yaml_text, const std::string& source);
// Reads and parses the file `path`. Throws InputError.
RigConfig ReadRigConfig(const std::string& path);

}  // namespace dwellfit

#endif  // DWELLFIT_CONFIG_RIG_CONFIG_READER_H_
