#include "dwellfit/estimator/rig/rig_simulator.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <complex>
#include <random>
#include <sstream>

#include "boost/numeric/odeint.hpp"
#include "boost/random/normal_distribution.hpp"
#include "dwellfit/estimator/common/input_error.h"
#include "dwellfit/estimator/common/string_printf.h"
#include "dwellfit/estimator/data/sweep_csv_writer.h"

namespace dwellfit {
namespace {

namespace odeint = boost::numeric::odeint;
using Complex = std::complex<double>;
// Scaled state: u/U, u'/(Omega U), base filter y_b/a_base, response filter
// y_r/(V_U), and the running integrals of u cos(theta), u sin(theta) in U/Omega;
// U the dwell's amplitude scale, V_U its small-signal voltage.
using State = std::array<double, 6>;

// The rig during one dwell: eq. (3.12) with the two channel filters and the
// first-harmonic integrals, on the scaled state.
struct RigEquation {
  ParameterVector p;
  double omega;  // drive [rad/s]
  double a_base;
  double phase0;      // the drive's phase at t = 0
  double scale;       // U [m]
  double volt_scale;  // V_U [V]
  double base_pole;   // 2 pi f_c [rad/s], 0: no filter
  double response_pole;
  const StrainGauge* gauge;
  ModelForm form;  // the member: entries kMu2 and kDelta may hold mu3 and alpha5

  void operator()(const State& x, State& dxdt, double t) const {
    const double theta = omega * t + phase0;
    const double u = scale * x[0];
    const double v = omega * scale * x[1];
    const double w = p[kNaturalFrequency];
    const double drive = a_base * std::cos(theta);
    // (1 + delta u^2) u'' + delta u u'^2 + w^2 u + alpha u^3 [+ alpha5 u^5]
    //   + 2 mu1 u' + (mu2 / Omega) u'|u'| [or 2 mu3 u^2 u'] = 2 eta_e a_base cos(theta)
    const double delta = form.has_inertia() ? p[kDelta] : 0.0;
    double restoring = w * w * u + delta * u * v * v + p[kAlpha] * u * u * u;
    if (form.quintic_stiffness()) restoring += p[kAlpha5] * u * u * u * u * u;
    double damping = 2.0 * p[kMu1] * v;
    damping +=
        form.cubic_damping() ? 2.0 * p[kMu3] * u * u * v : (p[kMu2] / omega) * v * std::abs(v);
    const double acc = (2.0 * p[kEtaE] * drive - restoring - damping) / (1.0 + delta * u * u);
    dxdt[0] = omega * x[1];
    dxdt[1] = acc / (omega * scale);
    dxdt[2] = base_pole > 0.0 ? base_pole * (drive / a_base - x[2]) : 0.0;
    dxdt[3] = response_pole > 0.0
                  ? response_pole * (gauge->VoltageFromDisplacement(u) / volt_scale - x[3])
                  : 0.0;
    dxdt[4] = x[0] * std::cos(theta) * omega;
    dxdt[5] = x[0] * std::sin(theta) * omega;
  }
};

using Stepper = odeint::controlled_runge_kutta<odeint::runge_kutta_dopri5<State>>;

// One dwell: settle, then record. Updates `state`.
class DwellRun {
 public:
  DwellRun(const ParameterVector& p, ModelForm form, const RigOptions& options,
           const StrainGauge& gauge, double omega, double a_base, RigMotion* state)
      : options_(options), state_(state), period_(kTwoPi / omega) {
    const double w = p[kNaturalFrequency];
    const double linear =
        2.0 * p[kEtaE] * a_base / std::hypot(w * w - omega * omega, 2.0 * p[kMu1] * omega);
    const double scale = std::max(state->amplitude, 0.1 * linear);
    const double volt_scale = std::abs(gauge.SmallSignalVoltsPerMetre()) * scale;
    const auto pole = [](double cutoff_hz) { return cutoff_hz > 0.0 ? kTwoPi * cutoff_hz : 0.0; };
    equation_ = RigEquation({p, omega, a_base, state->phase, scale, volt_scale,
                             pole(options.channels.base_filter_cutoff_hz),
                             pole(options.channels.response_filter_cutoff_hz), &gauge, form});
    x_ = State({state->u / scale, state->v / (omega * scale), state->y_base / a_base,
                state->y_response / volt_scale, 0.0, 0.0});
    stepper_ = odeint::make_controlled(options.integration_tolerance, options.integration_tolerance,
                                       odeint::runge_kutta_dopri5<State>());
  }

  RigDwellTruth Settle();
  void Record(DwellTrace* trace);  // then leaves `state` at the dwell's end

 private:
  // Integrates one period from t_; returns the first harmonic H of u over it.
  Complex OnePeriod() {
    x_[4] = x_[5] = 0.0;
    odeint::integrate_adaptive(stepper_, equation_, x_, t_, t_ + period_, period_ / 32);
    t_ += period_;
    return 2.0 / period_ * equation_.scale / equation_.omega * Complex(x_[4], -x_[5]);
  }

  const RigOptions& options_;
  RigMotion* state_;
  double period_;
  double t_ = 0.0;
  RigEquation equation_;
  State x_;
  Stepper stepper_;
};

RigDwellTruth DwellRun::Settle() {
  const int window = options_.settle_window_periods;
  std::vector<Complex> history;
  int good_checks = 0;
  RigDwellTruth truth;
  while (static_cast<int>(history.size()) < options_.max_settle_periods) {
    history.push_back(OnePeriod());
    const int k = static_cast<int>(history.size());
    if (k % window != 0 || k < 2 * window) continue;
    const Complex now = history.back();
    const bool steady =
        std::abs(now - history[k - 1 - window]) <= options_.settle_tolerance * std::abs(now);
    good_checks = steady ? good_checks + 1 : 0;
    if (good_checks >= 2) {
      truth.settled = true;
      break;
    }
  }
  truth.settle_periods = static_cast<int>(history.size());
  truth.amplitude = std::abs(history.back());
  truth.lag_rad = -std::arg(history.back());
  state_->amplitude = truth.amplitude;
  return truth;
}

void DwellRun::Record(DwellTrace* trace) {
  const RigEquation& e = equation_;
  const double fs = options_.sample_rate_hz;
  const double tau = options_.channels.skew_samples / fs;
  const int n = static_cast<int>(std::lround(options_.record_periods * period_ * fs));
  const double start = t_ + std::max(0.0, -tau);
  // Sample times of both channels, in time order: (time, channel 0 base / 1 response).
  std::vector<std::pair<double, int>> events;
  for (int j = 0; j < n; ++j) {
    events.emplace_back(start + j / fs, 0);
    events.emplace_back(start + j / fs + tau, 1);
  }
  std::stable_sort(events.begin(), events.end());
  std::vector<double> times;
  for (const auto& event : events) {
    if (times.empty() || event.first > times.back()) times.push_back(event.first);
  }
  trace->base.reserve(n);
  trace->response.reserve(n);
  std::size_t next = 0;
  auto observe = [&](const State& x, double t) {
    for (; next < events.size() && events[next].first <= t; ++next) {
      if (events[next].second == 0) {
        const double y =
            e.base_pole > 0.0 ? e.a_base * x[2] : e.a_base * std::cos(e.omega * t + e.phase0);
        trace->base.push_back(static_cast<float>(y));
      } else {
        const double y = e.response_pole > 0.0 ? e.volt_scale * x[3]
                                               : e.gauge->VoltageFromDisplacement(e.scale * x[0]);
        trace->response.push_back(static_cast<float>(y));
      }
    }
  };
  odeint::integrate_times(stepper_, equation_, x_, times.begin(), times.end(), period_ / 32,
                          observe);
  t_ = times.back();
  state_->u = e.scale * x_[0];
  state_->v = e.omega * e.scale * x_[1];
  state_->y_base = e.a_base * x_[2];
  state_->y_response = e.volt_scale * x_[3];
  state_->phase = std::fmod(e.phase0 + e.omega * t_, kTwoPi);
}

// |H(f)| of a one-pole filter (1 without one).
double FilterGain(double cutoff_hz, double f_hz) {
  return cutoff_hz > 0.0 ? 1.0 / std::hypot(1.0, f_hz / cutoff_hz) : 1.0;
}

// The channels' noise (header).
void AddNoise(const RigOptions& options, const StrainGauge& gauge, double a_base,
              const RigDwellTruth& truth, double f_hz, std::mt19937_64* random, DwellTrace* trace) {
  const double response_sigma = options.noise_relative_sigma;
  const double base_sigma = options.base_noise_relative_sigma.value_or(response_sigma);
  if (response_sigma == 0.0 && base_sigma == 0.0) return;
  // One sequence for both channels, at the response's sigma (the base's when
  // the response has none); a channel of another sigma scales its draws.
  const double drawn_sigma = response_sigma > 0.0 ? response_sigma : base_sigma;
  boost::random::normal_distribution<double> normal(
      0.0, drawn_sigma * std::sqrt(0.5 * trace->base.size()));
  const double base_amplitude = a_base * FilterGain(options.channels.base_filter_cutoff_hz, f_hz) *
                                (base_sigma / drawn_sigma);
  const double volt_amplitude = std::abs(gauge.VoltageFromDisplacement(truth.amplitude)) *
                                FilterGain(options.channels.response_filter_cutoff_hz, f_hz) *
                                (response_sigma / drawn_sigma);
  for (float& y : trace->base) y += static_cast<float>(base_amplitude * normal(*random));
  for (float& y : trace->response) y += static_cast<float>(volt_amplitude * normal(*random));
}

constexpr double kMinSamplesPerPeriod = 8.0;  // 3 harmonics and their mirrors

// Throws InputError when the sample rate gives fewer than kMinSamplesPerPeriod
// samples per period at max_hz, `which` drive frequency that is.
void CheckSampleRate(const RigOptions& options, double max_hz, const char* which) {
  if (options.sample_rate_hz < kMinSamplesPerPeriod * max_hz) {
    throw InputError(StringPrintf(
        "rig: sample_rate_hz %g gives %.3g samples per period at %s, %g Hz; give at least %g "
        "(sample_rate_hz >= %g)",
        options.sample_rate_hz, options.sample_rate_hz / max_hz, which, max_hz,
        kMinSamplesPerPeriod, kMinSamplesPerPeriod * max_hz));
  }
}

// Throws InputError unless every dwell's record has enough samples per drive
// period for the processing's harmonics (kMinSamplesPerPeriod) and all the
// records fit in kMaxTraceBytes.
void CheckSampling(const DwellPlan& plan, const RigOptions& options) {
  constexpr double kMaxTraceBytes = 4.0 * (1u << 30);
  double max_hz = 0.0;
  double samples = 0.0;  // both channels, every dwell
  for (const SweepPlan& sweep : plan.sweeps) {
    for (SweepDirection direction : sweep.directions) {
      for (double control : ControlGrid(sweep, direction)) {
        const double f_hz = sweep.kind == SweepKind::kFrequency ? control : sweep.held_frequency_hz;
        max_hz = std::max(max_hz, f_hz);
        samples += 2.0 * options.record_periods * options.sample_rate_hz / f_hz;
      }
    }
  }
  CheckSampleRate(options, max_hz, "the plan's highest drive frequency");
  if (4.0 * samples > kMaxTraceBytes) {
    throw InputError(StringPrintf(
        "rig: the records would hold %.3g samples (%.3g GiB as float32), more than 4 GiB; give "
        "fewer record_periods, a lower sample_rate_hz or fewer dwells",
        samples, 4.0 * samples / (1u << 30)));
  }
}

// Throws InputError when a simulated channel is not finite or is constant:
// channel settings (gain, filters) that put the signal outside float32's range.
void CheckRecorded(const DwellTrace& trace) {
  for (const auto* channel : {&trace.base, &trace.response}) {
    const auto [low, high] = std::minmax_element(channel->begin(), channel->end());
    if (!std::isfinite(*low) || !std::isfinite(*high) || *low == *high) {
      throw InputError(StringPrintf(
          "rig: dwell %s: the simulated %s channel is %s; check the channel and gauge settings "
          "(gain, filters) for values that put the signal outside float32's range",
          trace.Describe().c_str(), channel == &trace.base ? "base" : "response",
          *low == *high ? "constant" : "not finite"));
    }
  }
}

void CheckPlan(const DwellPlan& plan, const RigOptions& options) {
  std::string error;
  if (!plan.IsValid(&error)) throw InputError("plan: " + error);
  if (!options.IsValid(&error)) throw InputError("rig: " + error);
  if (plan.noise.relative_sigma != 0.0) {
    throw InputError(
        "plan: the plan's noise applies to dwell amplitudes; set it to 0 (or leave "
        "it out) and give the rig's noise instead");
  }
  for (const SweepPlan& sweep : plan.sweeps) {
    if (sweep.start_branch == Branch::kUpper) {
      throw InputError("plan: sweep '" + sweep.id +
                       "' asks to start on the upper branch; the "
                       "rig starts every sweep from rest (leave `start` out)");
    }
  }
  CheckSampling(plan, options);
}

}  // namespace

bool RigOptions::IsValid(std::string* error) const {
  auto fail = [error](const std::string& what) {
    *error = what;
    return false;
  };
  if (!channels.IsValid(error) || !gauge.IsValid(error)) return false;
  if (!(sample_rate_hz > 0.0 && std::isfinite(sample_rate_hz)) || record_periods < 1) {
    return fail("sample_rate_hz must be positive and record_periods at least 1");
  }
  if (!(settle_tolerance > 0.0) || settle_window_periods < 1 ||
      max_settle_periods / 2 < settle_window_periods) {  // 2 W could overflow
    return fail(
        "settle_tolerance must be positive, window_periods >= 1 and max_periods at least "
        "twice window_periods");
  }
  if (!(noise_relative_sigma >= 0.0 && noise_relative_sigma < 1.0)) {
    return fail(
        StringPrintf("noise relative_sigma must lie in [0, 1), got %g", noise_relative_sigma));
  }
  if (base_noise_relative_sigma &&
      !(*base_noise_relative_sigma >= 0.0 && *base_noise_relative_sigma < 1.0)) {
    return fail(StringPrintf("noise base_relative_sigma must lie in [0, 1), got %g",
                             *base_noise_relative_sigma));
  }
  if (!(integration_tolerance > 0.0 && integration_tolerance < 1e-3)) {
    return fail("integration_tolerance must lie in (0, 1e-3)");
  }
  return true;
}

VirtualRig::VirtualRig(const ParameterVector& truth, const RigOptions& options, ModelForm form)
    : truth_(truth),
      form_(form),
      options_(options),
      gauge_(options.gauge),
      random_(options.noise_seed) {
  std::string error;
  if (!options.IsValid(&error)) throw InputError("rig: " + error);
}

RigDwell VirtualRig::Dwell(double f_hz, double a_base, const std::string& sweep_id,
                           SweepDirection direction) {
  CheckSampleRate(options_, f_hz, "the dwell's drive frequency");
  const double omega = HzToRadPerSecond(f_hz);
  RigDwell out;
  DwellRun dwell(truth_, form_, options_, gauge_, omega, a_base, &motion_);
  out.truth = dwell.Settle();
  out.trace =
      DwellTrace{sweep_id, direction, SweepKind::kFrequency, omega, options_.sample_rate_hz};
  dwell.Record(&out.trace);
  AddNoise(options_, gauge_, a_base, out.truth, f_hz, &random_, &out.trace);
  CheckRecorded(out.trace);
  out.settle_seconds = out.truth.settle_periods / f_hz;
  out.record_seconds = options_.record_periods / f_hz;
  elapsed_seconds_ += out.settle_seconds + out.record_seconds;
  return out;
}

RigRun SimulateRig(const DwellPlan& plan, const RigOptions& options, const RigProgress& progress) {
  CheckPlan(plan, options);
  VirtualRig rig(plan.truth, options, plan.form);
  int total = 0;
  for (const SweepPlan& sweep : plan.sweeps) {
    total += (sweep.NumSteps() + 1) * static_cast<int>(sweep.directions.size());
  }
  RigRun run;
  for (const SweepPlan& sweep : plan.sweeps) {
    rig.Rest();  // every sweep starts from rest
    for (SweepDirection direction : sweep.directions) {
      Sweep truth{sweep.id, direction, sweep.kind};
      for (double control : ControlGrid(sweep, direction)) {
        const bool frequency = sweep.kind == SweepKind::kFrequency;
        const double f_hz = frequency ? control : sweep.held_frequency_hz;
        const double a_base = frequency ? sweep.held_a_base : control;
        RigDwell dwell = rig.Dwell(f_hz, a_base, sweep.id, direction);
        dwell.trace.kind = sweep.kind;
        truth.points.push_back(
            {HzToRadPerSecond(f_hz), a_base, dwell.truth.amplitude, dwell.truth.lag_rad});
        run.traces.push_back(std::move(dwell.trace));
        run.dwell_truth.push_back(dwell.truth);
        if (progress) progress(static_cast<int>(run.traces.size()), total);
      }
      run.truth.push_back(std::move(truth));
    }
  }
  return run;
}

void WriteRigTruthCsv(const RigRun& run, const std::string& path) {
  std::ostringstream text;
  text << "sweep,direction,freq_hz,a_base,a,phase_deg,settled,settle_periods\n";
  std::size_t i = 0;
  for (const Sweep& sweep : run.truth) {
    for (const DwellPoint& point : sweep.points) {
      const RigDwellTruth& truth = run.dwell_truth[i++];
      text << sweep.id << ',' << SweepDirectionName(sweep.direction) << ','
           << FormatFrequencyHz(point.drive_frequency_rad_s) << ',' << FormatRoundTrip(point.a_base)
           << ',' << FormatRoundTrip(point.amplitude) << ','
           << StringPrintf("%.6f", *point.phase_rad * 360.0 / kTwoPi) << ','
           << (truth.settled ? "true" : "false") << ',' << truth.settle_periods << '\n';
    }
  }
  WriteFileAtomically(text.str(), path);
}

}  // namespace dwellfit
