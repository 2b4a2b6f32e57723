#include "dwellfit/config/rig_config_reader.h"

#include "dwellfit/config/config_source.h"
#include "dwellfit/config/strict_yaml.h"

namespace dwellfit {
namespace {

void ReadSettling(const ConfigValue& value, const ConfigSource& source, RigOptions* rig) {
  const StrictMap block(value, source, {"tolerance", "window_periods", "max_periods"});
  if (auto v = block.Optional("tolerance")) rig->settle_tolerance = ReadPositive(*v, source);
  block.Read("window_periods", &rig->settle_window_periods);
  block.Read("max_periods", &rig->max_settle_periods);
}

RigChannels ReadChannels(const ConfigValue& value, const ConfigSource& source) {
  const StrictMap block(value, source, {"skew_samples", "base_filter_hz", "response_filter_hz"});
  RigChannels channels;
  block.Read("skew_samples", &channels.skew_samples);
  if (auto v = block.Optional("base_filter_hz"))
    channels.base_filter_cutoff_hz = ReadNonNegative(*v, source);
  if (auto v = block.Optional("response_filter_hz")) {
    channels.response_filter_cutoff_hz = ReadNonNegative(*v, source);
  }
  std::string error;
  if (!channels.IsValid(&error)) throw source.Error(value.path, value.mark, error);
  return channels;
}

void ReadBeam(const ConfigValue& value, const ConfigSource& source, StrainGaugeOptions* gauge) {
  const StrictMap block(value, source,
                        {"boundary", "mode", "length_m", "thickness_m", "gauge_position_m"});
  const std::string boundary =
      ReadOneOf(block.Required("boundary", "add boundary: cantilever or clamped_clamped"), source,
                "boundary", {"cantilever", "clamped_clamped"});
  gauge->boundary =
      boundary == "cantilever" ? BeamBoundary::kCantilever : BeamBoundary::kClampedClamped;
  block.Read("mode", &gauge->mode);
  gauge->length_m = ReadPositive(block.Required("length_m", "add the span [m]"), source);
  gauge->thickness_m = ReadPositive(block.Required("thickness_m", "add the thickness [m]"), source);
  gauge->gauge_position_m = ReadNonNegative(
      block.Required("gauge_position_m", "add the gauge's distance from the clamp [m]"), source);
}

void ReadGauge(const ConfigValue& value, const ConfigSource& source, StrainGaugeOptions* gauge) {
  const StrictMap block(value, source, {"excitation_v", "gain", "gauge_factor"});
  gauge->excitation_v = ReadPositive(block.Required("excitation_v", "add V_excite [V]"), source);
  gauge->gain = ReadPositive(block.Required("gain", "add the conditioner's gain G"), source);
  gauge->gauge_factor = ReadPositive(block.Required("gauge_factor", "add K_g"), source);
}

void ReadProcessing(const ConfigValue& value, const ConfigSource& source,
                    TraceProcessingOptions* processing) {
  const StrictMap block(value, source,
                        {"correct_channels", "harmonics", "settle_tolerance",
                         "harmonic_warning_ratio", "level_tolerance"});
  block.Read("correct_channels", &processing->correct_channels);
  block.Read("harmonics", &processing->harmonics);
  if (auto v = block.Optional("settle_tolerance"))
    processing->settle_tolerance = ReadPositive(*v, source);
  if (auto v = block.Optional("harmonic_warning_ratio")) {
    processing->harmonic_warning_ratio = ReadPositive(*v, source);
  }
  if (auto v = block.Optional("level_tolerance"))
    processing->level_tolerance = ReadPositive(*v, source);
}

RigConfig ReadConfig(const ConfigSource& source) {
  const ConfigValue document = DocumentValue(source);
  const StrictMap block(document, source,
                        {"sample_rate_hz", "record_periods", "settling", "channels", "noise",
                         "beam", "gauge", "processing"});
  RigConfig config;
  RigOptions& rig = config.rig;
  rig.sample_rate_hz =
      ReadPositive(block.Required("sample_rate_hz", "add the sample rate [Hz]"), source);
  rig.record_periods =
      ReadInt(block.Required("record_periods", "add the drive periods recorded per dwell"), source);
  if (auto v = block.Optional("settling")) ReadSettling(*v, source, &rig);
  if (auto v = block.Optional("channels")) rig.channels = ReadChannels(*v, source);
  if (auto v = block.Optional("noise")) {
    const StrictMap noise(*v, source, {"relative_sigma", "base_relative_sigma", "seed"});
    rig.noise_relative_sigma =
        ReadNonNegative(noise.Required("relative_sigma", "add relative_sigma (0: none)"), source);
    if (auto base = noise.Optional("base_relative_sigma")) {
      rig.base_noise_relative_sigma = ReadNonNegative(*base, source);
    }
    rig.noise_seed = ReadUint64(noise.Required("seed", "add seed (a whole number >= 0)"), source);
  }
  ReadBeam(block.Required("beam",
                          "add beam: with boundary, length_m, thickness_m, "
                          "gauge_position_m"),
           source, &rig.gauge);
  ReadGauge(block.Required("gauge", "add gauge: with excitation_v, gain, gauge_factor"), source,
            &rig.gauge);
  config.processing.channels = rig.channels;
  config.processing.gauge = rig.gauge;
  if (auto v = block.Optional("processing")) ReadProcessing(*v, source, &config.processing);
  std::string error;
  if (!rig.IsValid(&error) || !config.processing.IsValid(&error)) {
    throw source.Error(document.path, document.mark, error);
  }
  return config;
}

}  // namespace

RigConfig ParseRigConfig(const std::string& yaml_text, const std::string& source) {
  return ReadConfig(ConfigSource::Parse(source, yaml_text));
}

RigConfig ReadRigConfig(const std::string& path) {
  return ReadConfig(ConfigSource::Load(path, "rig file"));
}

}  // namespace dwellfit
