#include "dwellfit/estimator/traces/trace_processing.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <numeric>
#include <utility>

#include "dwellfit/estimator/common/input_error.h"
#include "dwellfit/estimator/common/string_printf.h"
#include "dwellfit/residuals/model/model_parameters.h"
#include "unsupported/Eigen/FFT"

namespace dwellfit {
namespace {

using Complex = std::complex<double>;
using Spectrum = std::vector<Complex>;

// A change counts only beyond this many standard deviations of the noise.
constexpr double kNoiseSigmas = 5.0;
// The smallest relative level sigma stated (exactly periodic noise-free
// samples would give 0, which the sweeps CSV refuses).
constexpr double kLevelSigmaFloor = 1e-12;

// The frequency [Hz] of FFT bin k of n samples at rate fs (negative above n/2).
double BinFrequencyHz(int k, int n, double fs) { return (2 * k <= n ? k : k - n) * fs / n; }

Spectrum Fft(const std::vector<double>& samples) {
  Eigen::FFT<double> fft;
  Spectrum spectrum;
  fft.fwd(spectrum, samples);
  return spectrum;
}

std::vector<double> InverseFft(const Spectrum& spectrum) {
  Eigen::FFT<double> fft;
  std::vector<double> samples;
  fft.inv(samples, spectrum);
  return samples;
}

// The spectrum of `samples` with the channel's filter divided out and a
// sampling delay `delay_s` undone (see the header, step 3).
Spectrum ChannelSpectrum(const std::vector<double>& samples, double fs, double cutoff_hz,
                         double delay_s) {
  Spectrum spectrum = Fft(samples);
  const int n = static_cast<int>(samples.size());
  for (int k = 0; k < n; ++k) {
    const double f = BinFrequencyHz(k, n, fs);
    if (cutoff_hz > 0.0) spectrum[k] *= Complex(1.0, f / cutoff_hz);
    if (delay_s != 0.0) spectrum[k] *= std::polar(1.0, -kTwoPi * f * delay_s);
  }
  // An even length's Nyquist bin stands for +fs/2 and -fs/2 at once: keep it real.
  if (n % 2 == 0) spectrum[n / 2] = spectrum[n / 2].real();
  return spectrum;
}

// Harmonics 0..count of a spectrum of n samples holding `periods` periods.
std::vector<Complex> Harmonics(const Spectrum& spectrum, int periods, int count) {
  const double n = static_cast<double>(spectrum.size());
  std::vector<Complex> harmonics(count + 1);
  harmonics[0] = spectrum[0] / n;
  for (int h = 1; h <= count; ++h) harmonics[h] = 2.0 / n * spectrum[h * periods];
  return harmonics;
}

// Step 1 of the header: the checks that make a dwell analysable.
void CheckTraces(const DwellTrace& dwell, int harmonics) {
  const std::string where = "dwell " + dwell.Describe() + ": ";
  if (dwell.base.empty() || dwell.response.empty()) {
    throw InputError(where + "a channel has no samples; record both channels");
  }
  if (dwell.base.size() != dwell.response.size()) {
    throw InputError(where + StringPrintf("the channels have different lengths (base %zu, "
                                          "response %zu samples); record both channels together",
                                          dwell.base.size(), dwell.response.size()));
  }
  for (const auto* channel : {&dwell.base, &dwell.response}) {
    const char* name = channel == &dwell.base ? "base" : "response";
    for (std::size_t i = 0; i < channel->size(); ++i) {
      if (std::isfinite((*channel)[i])) continue;
      throw InputError(where + StringPrintf("%s sample %zu is not a finite number (NaN or "
                                            "infinite); re-record the dwell",
                                            name, i));
    }
    // A constant channel (all zero: a cable off, a gain of 0) has no first
    // harmonic: it would give a = 0 or a_base = 0, not a measurement.
    const auto [low, high] = std::minmax_element(channel->begin(), channel->end());
    if (*low == *high) {
      throw InputError(where + StringPrintf("the %s channel is constant (every sample %g); "
                                            "check the channel's cabling and gain",
                                            name, *low));
    }
  }
  const double per_period = dwell.sample_rate_hz / RadPerSecondToHz(dwell.drive_frequency_rad_s);
  if (static_cast<double>(dwell.base.size()) < per_period) {
    throw InputError(where + StringPrintf("the record holds %zu samples, shorter than one drive "
                                          "period (%.1f samples); record whole periods",
                                          dwell.base.size(), per_period));
  }
  if (per_period < 2.0 * (harmonics + 1)) {
    throw InputError(where + StringPrintf("%.1f samples per period cannot resolve %d harmonics; "
                                          "sample faster or ask for fewer harmonics",
                                          per_period, harmonics));
  }
}

struct DwellResult {
  DwellHarmonics harmonics;
  double settle_change = 0.0;  // |Z_2 - Z_1| / |Z|, Z = U_1 / A_1 per half
  double settle_noise = 0.0;   // its standard deviation from the noise alone
  double base_noise = 0.0;     // relative standard deviation of |A_1|
  double harmonic_ratio = 0.0;
};

// The per-sample noise of a channel: the spectrum's energy outside harmonics
// 0..count (and their mirrors), per remaining bin (Parseval).
double SampleNoise(const Spectrum& spectrum, int periods, int count) {
  const int n = static_cast<int>(spectrum.size());
  double energy = 0.0;
  int bins = 0;
  for (int k = 0; k < n; ++k) {
    const int folded = std::min(k, n - k);
    if (folded % periods == 0 && folded / periods <= count) continue;
    energy += std::norm(spectrum[k]);
    ++bins;
  }
  return bins > 0 ? std::sqrt(energy / bins / n) : 0.0;
}

// The last `periods` whole periods of `channel` as doubles.
std::vector<double> LastPeriods(const std::vector<float>& channel, double per_period, int periods) {
  const std::size_t n =
      std::min(channel.size(), static_cast<std::size_t>(std::lround(periods * per_period)));
  return std::vector<double>(channel.end() - n, channel.end());
}

// Z = U_1 / A_1 over `periods` periods of u and base starting at sample `first`.
Complex ResponseRatio(const std::vector<double>& u, const std::vector<double>& base,
                      std::size_t first, std::size_t n, int periods) {
  const std::vector<double> u_part(u.begin() + first, u.begin() + first + n);
  const std::vector<double> b_part(base.begin() + first, base.begin() + first + n);
  return Fft(u_part)[periods] / Fft(b_part)[periods];
}

std::vector<double> Displacement(const DwellTrace& dwell, const Spectrum& voltage_spectrum,
                                 const StrainGauge& gauge) {
  const std::vector<double> volts = InverseFft(voltage_spectrum);
  std::vector<double> u(volts.size());
  for (std::size_t i = 0; i < volts.size(); ++i) {
    if (!gauge.DisplacementFromVoltage(volts[i], &u[i])) {
      throw InputError("dwell " + dwell.Describe() +
                       StringPrintf(": response %.6g V is beyond what the gauge relation (3.7) "
                                    "can give; check the gauge's gain, excitation and position",
                                    volts[i]));
    }
  }
  return u;
}

// Throws InputError when a channel holds (next to) nothing at the drive
// frequency: a first harmonic below 1e-6 of the channel's RMS (a recording
// at another frequency than freq_hz says, or no response), which would give
// an amplitude of 0 rather than a measurement.
void CheckDriveComponent(const DwellTrace& dwell, const char* channel,
                         const std::vector<double>& samples, Complex first_harmonic) {
  const double rms =
      std::sqrt(std::inner_product(samples.begin(), samples.end(), samples.begin(), 0.0) /
                static_cast<double>(samples.size()));
  // A sine of amplitude A has an RMS of A / sqrt(2).
  if (!(std::abs(first_harmonic) > 1e-6 * std::sqrt(2.0) * rms)) {
    throw InputError("dwell " + dwell.Describe() + ": the " + channel +
                     " channel has no component at the drive frequency; check freq_hz "
                     "against the recording");
  }
}

DwellResult AnalyzeDwell(const DwellTrace& dwell, const TraceProcessingOptions& options,
                         const StrainGauge& gauge) {
  CheckTraces(dwell, options.harmonics);
  const double fs = dwell.sample_rate_hz;
  const double per_period = fs / RadPerSecondToHz(dwell.drive_frequency_rad_s);
  // Whole periods to within half a sample: a record of round(P fs / f) samples holds P.
  const int periods = static_cast<int>(std::floor((dwell.base.size() + 0.5) / per_period));
  const std::vector<double> base = LastPeriods(dwell.base, per_period, periods);
  const std::vector<double> volts = LastPeriods(dwell.response, per_period, periods);
  const RigChannels none;
  const RigChannels& channels = options.correct_channels ? options.channels : none;
  const Spectrum base_spectrum = ChannelSpectrum(base, fs, channels.base_filter_cutoff_hz, 0.0);
  const Spectrum volt_spectrum =
      ChannelSpectrum(volts, fs, channels.response_filter_cutoff_hz, channels.skew_samples / fs);
  const std::vector<double> u = Displacement(dwell, volt_spectrum, gauge);
  DwellResult result;
  result.harmonics.drive_frequency_rad_s = dwell.drive_frequency_rad_s;
  const Spectrum u_spectrum = Fft(u);
  result.harmonics.u = Harmonics(u_spectrum, periods, options.harmonics);
  result.harmonics.base = Harmonics(base_spectrum, periods, options.harmonics);
  CheckDriveComponent(dwell, "response", u, result.harmonics.u[1]);
  CheckDriveComponent(dwell, "base", base, result.harmonics.base[1]);
  const double first = std::abs(result.harmonics.u[1]);
  for (int h = 2; h <= options.harmonics; ++h) {
    result.harmonic_ratio =
        std::max(result.harmonic_ratio, std::abs(result.harmonics.u[h]) / first);
  }
  const double n_all = static_cast<double>(u.size());
  const double u_noise = SampleNoise(u_spectrum, periods, options.harmonics) / first;
  const double b_noise =
      SampleNoise(base_spectrum, periods, options.harmonics) / std::abs(result.harmonics.base[1]);
  result.base_noise = b_noise * std::sqrt(2.0 / n_all);
  if (periods >= 2) {
    const int half = periods / 2;
    const std::size_t n = static_cast<std::size_t>(std::lround(half * per_period));
    // Each half's ratio carries relative noise sqrt(2/n) (u_noise^2 + b_noise^2)^(1/2).
    result.settle_noise = std::sqrt(2.0 * 2.0 / n * (u_noise * u_noise + b_noise * b_noise));
    const std::vector<double> base_corrected = InverseFft(base_spectrum);
    const Complex z1 = ResponseRatio(u, base_corrected, 0, n, half);
    const Complex z2 = ResponseRatio(u, base_corrected, u.size() - n, n, half);
    result.settle_change = std::abs(z2 - z1) / std::abs(z2);
  }
  return result;
}

// The lag of the response behind the base, in (-pi, pi].
double Lag(const DwellHarmonics& h) {
  double gamma = std::arg(h.base[1]) - std::arg(h.u[1]);
  while (gamma <= -kTwoPi / 2) gamma += kTwoPi;
  while (gamma > kTwoPi / 2) gamma -= kTwoPi;
  return gamma;
}

// Groups dwells into sweeps and sets each frequency sweep's base level.
void BuildSweeps(const std::vector<DwellTrace>& dwells, const TraceProcessingOptions& options,
                 const std::vector<double>& base_noise, ProcessedTraces* out) {
  std::map<std::pair<std::string, SweepDirection>, std::size_t> index;
  std::vector<std::vector<std::size_t>> members;
  for (std::size_t i = 0; i < dwells.size(); ++i) {
    const auto key = std::make_pair(dwells[i].sweep, dwells[i].direction);
    auto [it, added] = index.emplace(key, out->sweeps.size());
    if (added) {
      Sweep sweep;
      sweep.id = dwells[i].sweep;
      sweep.direction = dwells[i].direction;
      sweep.kind = dwells[i].kind;
      out->sweeps.push_back(sweep);
      members.emplace_back();
    }
    const DwellHarmonics& h = out->harmonics[i];
    // Omega, a_base = |A_1|, a = |U_1| and the lag.
    out->sweeps[it->second].points.push_back(
        DwellPoint{dwells[i].drive_frequency_rad_s, std::abs(h.base[1]), std::abs(h.u[1]), Lag(h)});
    // Every dwell states one (the sweeps CSV takes the column whole): at least
    // kLevelSigmaFloor of the level, far below any recorded noise.
    out->sweeps[it->second].points.back().a_base_sigma =
        std::abs(h.base[1]) * std::max(base_noise[i], kLevelSigmaFloor);
    members[it->second].push_back(i);
  }
  for (std::size_t s = 0; s < out->sweeps.size(); ++s) {
    Sweep& sweep = out->sweeps[s];
    if (sweep.kind != SweepKind::kFrequency) continue;
    double mean = 0.0, mean_variance = 0.0;  // the mean level and its error's variance
    const double n = static_cast<double>(sweep.points.size());
    for (const DwellPoint& point : sweep.points) {
      mean += point.a_base / n;
      mean_variance += std::pow(*point.a_base_sigma / n, 2);
    }
    for (std::size_t j = 0; j < sweep.points.size(); ++j) {
      const double change = sweep.points[j].a_base / mean - 1.0;
      const double limit =
          std::max(options.level_tolerance, kNoiseSigmas * base_noise[members[s][j]]);
      if (std::abs(change) > limit) {
        out->warnings.push_back(
            StringPrintf("level: dwell %s: base level differs from the "
                         "sweep's mean by %.2f %%",
                         dwells[members[s][j]].Describe().c_str(), 100 * change));
      }
      sweep.points[j].a_base = mean;
      sweep.points[j].a_base_sigma = std::sqrt(mean_variance);
    }
  }
}

}  // namespace

bool RigChannels::IsValid(std::string* error) const {
  if (!(std::abs(skew_samples) < 1.0)) {
    *error = StringPrintf("skew_samples must lie in (-1, 1), got %g", skew_samples);
    return false;
  }
  if (!(base_filter_cutoff_hz >= 0.0 && response_filter_cutoff_hz >= 0.0 &&
        std::isfinite(base_filter_cutoff_hz) && std::isfinite(response_filter_cutoff_hz))) {
    *error = "filter cutoffs must be positive numbers [Hz] (0: no filter)";
    return false;
  }
  return true;
}

bool TraceProcessingOptions::IsValid(std::string* error) const {
  if (!channels.IsValid(error) || !gauge.IsValid(error)) return false;
  if (harmonics < 1 || harmonics > 20) {
    *error = StringPrintf("harmonics must be 1 to 20, got %d", harmonics);
    return false;
  }
  if (!(settle_tolerance > 0.0 && harmonic_warning_ratio > 0.0 && level_tolerance > 0.0)) {
    *error = "settle_tolerance, harmonic_warning_ratio and level_tolerance must be positive";
    return false;
  }
  return true;
}

ProcessedTraces ProcessTraces(const std::vector<DwellTrace>& dwells,
                              const TraceProcessingOptions& options) {
  std::string error;
  if (!options.IsValid(&error)) throw InputError("trace processing options: " + error);
  if (dwells.empty()) throw InputError("no dwell to process");
  const StrainGauge gauge(options.gauge);
  ProcessedTraces out;
  std::vector<double> base_noise;
  for (const DwellTrace& dwell : dwells) {
    const DwellResult result = AnalyzeDwell(dwell, options, gauge);
    const double settle_limit =
        std::max(options.settle_tolerance, kNoiseSigmas * result.settle_noise);
    if (result.settle_change > settle_limit) {
      ++out.unsettled_dwells;
      out.warnings.push_back(StringPrintf(
          "unsettled: dwell %s: the response changed by %.3g (relative) between the record's "
          "halves (limit %.3g: the tolerance or %g times the noise); wait longer before recording",
          dwell.Describe().c_str(), result.settle_change, settle_limit, kNoiseSigmas));
    }
    if (result.harmonic_ratio > options.harmonic_warning_ratio) {
      out.warnings.push_back(StringPrintf(
          "harmonics: dwell %s: a higher harmonic reaches %.3g of the first (warning above "
          "%.3g); the single-harmonic model may not hold",
          dwell.Describe().c_str(), result.harmonic_ratio, options.harmonic_warning_ratio));
    }
    out.harmonics.push_back(result.harmonics);
    base_noise.push_back(result.base_noise);
  }
  BuildSweeps(dwells, options, base_noise, &out);
  return out;
}

}  // namespace dwellfit
