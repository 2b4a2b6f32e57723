// A virtual sine-dwell rig (section 3.1, Figure 3.1): a shaker holds the base
// at a_base cos(Omega t), the beam's mode obeys the equation of motion
// (docs/model.md, eq. 3.12)
//   u'' + w^2 u + delta (u u'^2 + u^2 u'') + alpha u^3 + 2 mu1 u'
//       + (mu2/Omega) u'|u'| = 2 eta_e a_base cos(Omega t),
// and an analyzer records the base acceleration and the strain-gauge voltage.
//
// Every dwell of the plan (config/dwell_plan_reader.h; its `noise` must be
// zero, the rig has its own) is integrated with Boost.Odeint's controlled
// runge_kutta_dopri5 from the state the previous dwell ended in, with the
// drive's phase continuous across the step, as a real test does: jumps and
// hysteresis come from the dynamics. A dwell settles period by period: the
// first harmonic of u over each period, H_k = (2/T) int u exp(-i theta) dt
// (theta the drive's phase, integrated with the state), is compared with
// H_{k-W}, W = `settle_window_periods`; the dwell has settled when
// |H_k - H_{k-W}| <= settle_tolerance |H_k| at two checks in a row, W periods
// apart. A dwell that has not settled after `max_settle_periods` is recorded
// anyway and marked unsettled in the truth.
//
// Then `record_periods` periods are sampled at `sample_rate_hz`
// (round(record_periods fs / f) samples). The response channel is sampled
// `skew_samples` of a sample interval after the base channel; a channel with
// a filter records the output of y' = 2 pi f_c (x - y), integrated with the
// state. Noise: independent Gaussian samples of standard deviation
// relative_sigma A sqrt(N/2) (the base channel's own relative_sigma where
// given), A the channel's first-harmonic amplitude and N
// the record's samples, so that each channel's first harmonic carries a
// relative error of relative_sigma (its amplitude that much, its phase that
// many radians): "0.5 % noise" means 0.5 % on every dwell's amplitudes, as in
// simulate_dwell, whatever the record length. Drawn from
// std::mt19937_64(seed) through boost::random::normal_distribution, base then
// response, dwell after dwell: the same plan and seed give the same traces.
// The drive's level and frequency change in one step between dwells.
#ifndef DWELLFIT_ESTIMATOR_RIG_RIG_SIMULATOR_H_
#define DWELLFIT_ESTIMATOR_RIG_RIG_SIMULATOR_H_

#include <cstdint>
#include <functional>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include "dwellfit/estimator/data/sweep.h"
#include "dwellfit/estimator/simulation/dwell_simulator.h"
#include "dwellfit/estimator/traces/trace_file.h"
#include "dwellfit/estimator/traces/trace_processing.h"

namespace dwellfit {

struct RigOptions {
  double sample_rate_hz = 2048.0;
  int record_periods = 16;            // >= 1
  double settle_tolerance = 1e-4;     // > 0, relative change of H over W periods
  int settle_window_periods = 50;     // W >= 1
  int max_settle_periods = 20000;     // >= 2 W
  RigChannels channels;               // skew and filters (trace_processing.h)
  StrainGaugeOptions gauge;           // beam, mode and bridge (strain_gauge.h)
  double noise_relative_sigma = 0.0;  // [0, 1), per dwell amplitude (see above)
  // The base channel's, where it differs from the response's (an
  // accelerometer on the shaker head is often far cleaner than the gauge):
  // [0, 1), unset for noise_relative_sigma. Both channels draw from one
  // sequence as they do at one sigma, so a run with another base sigma has
  // the same response noise, sample for sample.
  std::optional<double> base_noise_relative_sigma;
  std::uint64_t noise_seed = 0;
  // Integrator tolerances of the controlled stepper (relative; the absolute
  // one is this times the state's scale).
  double integration_tolerance = 1e-9;

  bool IsValid(std::string* error) const;
};

// The truth of one dwell: the noise-free, unfiltered response.
struct RigDwellTruth {
  double amplitude = 0.0;  // |H| of u over the last settling period [m]
  double lag_rad = 0.0;    // gamma: u = a cos(Omega t - gamma)
  bool settled = false;
  int settle_periods = 0;  // periods integrated before the record
};

struct RigRun {
  std::vector<DwellTrace> traces;  // one per dwell, in measurement order
  // The truth as sweeps: amplitude, lag (phase_rad) of the noise-free
  // response, a_base as set; kind, id, direction as planned.
  std::vector<Sweep> truth;
  std::vector<RigDwellTruth> dwell_truth;  // one per dwell, as traces
};

// The beam and the channels between dwells: the state the next dwell starts
// from.
struct RigMotion {
  double u = 0.0, v = 0.0;                // displacement [m] and velocity [m/s]
  double y_base = 0.0, y_response = 0.0;  // the channel filters' outputs
  double phase = 0.0;                     // the drive's phase now [rad]
  double amplitude = 0.0;                 // the last dwell's first-harmonic amplitude [m]
};

// One dwell of a VirtualRig, with the test time it took.
struct RigDwell {
  DwellTrace trace;
  RigDwellTruth truth;
  double settle_seconds = 0.0;  // settle_periods / f
  double record_seconds = 0.0;  // record_periods / f
};

// The rig one dwell at a time, for a loop that chooses each dwell from the
// ones before (docs/next-dwell.md): every dwell starts from the motion the
// previous one ended in, with the drive's phase continuous, as the dwells of
// a sweep in SimulateRig do; Rest() stops the beam. The noise is one stream
// over all dwells, seeded by the options.
class VirtualRig {
 public:
  // `form` names the member whose terms entries kMu2 and kDelta of `truth`
  // hold (its averaging does not matter: the rig integrates the equation of
  // motion). Throws InputError when the options are not valid.
  VirtualRig(const ParameterVector& truth, const RigOptions& options, ModelForm form = ModelForm{});

  // Settles and records one dwell at f_hz and base level a_base; the trace
  // carries `sweep_id` and `direction`. Throws InputError when the sample
  // rate gives fewer than 8 samples per period at f_hz or the record is not
  // usable (a channel not finite or constant).
  RigDwell Dwell(double f_hz, double a_base, const std::string& sweep_id = "dwell",
                 SweepDirection direction = SweepDirection::kUp);
  void Rest() { motion_ = RigMotion(); }
  const RigMotion& motion() const { return motion_; }
  // Settling and recording time of every dwell so far [s].
  double elapsed_seconds() const { return elapsed_seconds_; }

 private:
  ParameterVector truth_;
  ModelForm form_;
  RigOptions options_;
  StrainGauge gauge_;
  std::mt19937_64 random_;
  RigMotion motion_;
  double elapsed_seconds_ = 0.0;
};

// Called after every dwell with (dwells done, dwells in all).
using RigProgress = std::function<void(int, int)>;

// Runs the plan on the rig. Throws InputError when the plan or the options
// are not valid or the plan has noise.
RigRun SimulateRig(const DwellPlan& plan, const RigOptions& options,
                   const RigProgress& progress = nullptr);

// Writes the truth as CSV: sweep,direction,freq_hz,a_base,a,phase_deg,settled,settle_periods.
void WriteRigTruthCsv(const RigRun& run, const std::string& path);

}  // namespace dwellfit

#endif  // DWELLFIT_ESTIMATOR_RIG_RIG_SIMULATOR_H_
