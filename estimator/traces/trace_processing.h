// From time traces to dwell points: the amplitudes of both channels and the
// phase between them at the drive frequency, and the strain-gauge voltage as
// modal displacement (section 3.1; eqs. 3.4-3.7 in strain_gauge.h).
//
// Per dwell, with f the drive frequency and fs the sample rate:
//   1. checks: both channels present, of one length, finite, and at least one
//      drive period long (else InputError naming the dwell);
//   2. the last N = round(P fs / f) samples, P the most whole periods the
//      record holds to within half a sample (the start, nearest the previous
//      dwell, is dropped; a window whole only to within a sample leaks a few
//      1e-4 of the amplitude at 50 samples per period);
//   3. each channel's spectrum (Eigen's FFT); when `correct_channels`, bin f_k
//      is divided by its channel's one-pole filter H(f_k) = 1 / (1 + i f_k / f_c)
//      and the response moved back by the multiplexing skew tau (times
//      exp(-i 2 pi f_k tau));
//   4. the corrected voltage back in time, turned into u sample by sample
//      through (3.7), and u's spectrum;
//   5. harmonic n of a channel x: X_n = (2/N) FFT[n P] (n >= 1), X_0 = FFT[0]/N,
//      x(t) ~ Re sum_n X_n exp(i n Omega t); a = |U_1|, a_base = |A_1|, and the
//      lag gamma = arg A_1 - arg U_1 in (-pi, pi] (docs/model.md: u = a cos(Omega t - gamma)).
// Warnings (ProcessedTraces::warnings, one line each, naming the dwell):
//   unsettled   U_1/A_1 over the record's two halves differs by more than
//               `settle_tolerance` (relative) and 5 standard deviations of the
//               noise (from the spectrum outside the harmonics);
//   harmonics   some |U_n| / |U_1| (n = 2..harmonics) exceeds
//               `harmonic_warning_ratio`;
//   level       in a frequency sweep, a dwell's base level differs from the
//               sweep's mean by more than `level_tolerance` (relative) and
//               more than 5 standard deviations of its noise.
// The sweeps CSV needs one base level per frequency sweep: its dwells get the
// mean of their measured levels; amplitude sweeps keep each dwell's own.
// Each level's standard deviation (DwellPoint::a_base_sigma) comes from the
// base channel's noise outside the harmonics: |A_1| s_b sqrt(2 / N) for one
// dwell (s_b the noise per sample relative to |A_1|, N samples), and
// sqrt(sum_j sigma_j^2) / n for the mean of a frequency sweep's n dwells.
#ifndef DWELLFIT_ESTIMATOR_TRACES_TRACE_PROCESSING_H_
#define DWELLFIT_ESTIMATOR_TRACES_TRACE_PROCESSING_H_

#include <complex>
#include <string>
#include <vector>

#include "dwellfit/estimator/data/sweep.h"
#include "dwellfit/estimator/traces/strain_gauge.h"
#include "dwellfit/estimator/traces/trace_file.h"

namespace dwellfit {

// What the experimenter knows about the two channels.
struct RigChannels {
  // The response channel is sampled this fraction of a sample interval after
  // the base channel (multiplexed sampling: 0.5 for two channels); in (-1, 1).
  double skew_samples = 0.0;
  // One-pole low-pass cutoff [Hz] on each channel; 0: no filter.
  double base_filter_cutoff_hz = 0.0;
  double response_filter_cutoff_hz = 0.0;

  bool IsValid(std::string* error) const;
};

struct TraceProcessingOptions {
  RigChannels channels;
  StrainGaugeOptions gauge;
  bool correct_channels = true;          // undo the skew and the filters
  int harmonics = 3;                     // harmonics kept per channel (1..20)
  double settle_tolerance = 5e-3;        // > 0
  double harmonic_warning_ratio = 0.05;  // > 0
  double level_tolerance = 0.01;         // > 0

  bool IsValid(std::string* error) const;
};

// The Fourier coefficients of one dwell, index n = 0..harmonics.
struct DwellHarmonics {
  double drive_frequency_rad_s = 0.0;
  std::vector<std::complex<double>> u;     // modal displacement [m]
  std::vector<std::complex<double>> base;  // base acceleration [B]
};

struct ProcessedTraces {
  std::vector<Sweep> sweeps;              // one per (sweep, direction), first appearance order
  std::vector<DwellHarmonics> harmonics;  // one per dwell, input order
  std::vector<std::string> warnings;
  int unsettled_dwells = 0;
};

// Throws InputError when `options` are not valid or a dwell's traces cannot
// be analysed (the message names the dwell and what to do).
ProcessedTraces ProcessTraces(const std::vector<DwellTrace>& dwells,
                              const TraceProcessingOptions& options);

}  // namespace dwellfit

#endif  // DWELLFIT_ESTIMATOR_TRACES_TRACE_PROCESSING_H_
