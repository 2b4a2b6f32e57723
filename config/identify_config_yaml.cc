// ConfigToYaml: the config in effect, in the schema LoadIdentifyConfig reads.
#include <charconv>
#include <string>
#include <vector>

#include "dwellfit/config/identify_config.h"
#include "dwellfit/estimator/data/sweep_csv_writer.h"
#include "yaml-cpp/yaml.h"

namespace dwellfit {
namespace {

// 15 significant digits: recovers the decimal a person typed from a value
// that went through a unit conversion (Hz -> rad/s -> Hz).
std::string ConvertedNumber(double value) {
  char buffer[64];
  const auto result =
      std::to_chars(buffer, buffer + sizeof(buffer), value, std::chars_format::general, 15);
  return std::string(buffer, result.ptr);
}

// `key: value`; a double as its FormatRoundTrip.
template <typename T>
void Put(YAML::Emitter& out, const char* key, const T& value) {
  out << YAML::Key << key << YAML::Value << value;
}
void Put(YAML::Emitter& out, const char* key, double value) {
  Put(out, key, FormatRoundTrip(value));
}

// `key: [...]`, the flow list of `text(item)` for each of `items`.
template <typename Items, typename Text>
void PutList(YAML::Emitter& out, const char* key, const Items& items, const Text& text) {
  out << YAML::Key << key << YAML::Value << YAML::Flow << YAML::BeginSeq;
  for (const auto& item : items) out << text(item);
  out << YAML::EndSeq;
}

std::string SelectionName(const SweepSelection& selection) { return selection.Name(); }

void EmitPenalties(YAML::Emitter& out, const PenaltyOptions& penalties) {
  const BifurcationRangeOptions& range = penalties.bifurcation_range;
  out << YAML::Key << "penalties" << YAML::Value << YAML::BeginMap;
  out << YAML::Key << "bifurcation_range" << YAML::Value << YAML::BeginMap;
  Put(out, "enabled", range.enabled);
  Put(out, "exponent", range.exponent);
  Put(out, "weight", range.weight);
  PutList(out, "enforce", range.enforce, JumpTargetName);
  out << YAML::EndMap;
  const BranchStabilityOptions& stability = penalties.branch_stability;
  out << YAML::Key << "branch_stability" << YAML::Value << YAML::BeginMap;
  Put(out, "enabled", stability.enabled);
  Put(out, "lambda", stability.lambda);
  Put(out, "weight", stability.weight);
  out << YAML::EndMap;
  out << YAML::EndMap;
}

// Brackets in the config's units: Hz (with rad/s as a comment) or a_base.
void EmitJumpOverrides(YAML::Emitter& out, const std::vector<JumpOverride>& jumps) {
  out << YAML::Key << "jumps" << YAML::Value;
  if (jumps.empty()) {
    out << YAML::Flow << YAML::BeginSeq << YAML::EndSeq;
    return;
  }
  out << YAML::BeginSeq;
  for (const JumpOverride& jump : jumps) {
    out << YAML::BeginMap;
    Put(out, "sweep", jump.sweep);
    if (jump.none) {
      Put(out, "none", true);
    } else {
      Put(out, "kind", JumpKindName(jump.kind));
      const bool frequency = jump.control == SweepKind::kFrequency;
      out << YAML::Key << (frequency ? "between_hz" : "between_a_base") << YAML::Value << YAML::Flow
          << YAML::BeginSeq;
      if (frequency) {
        out << ConvertedNumber(RadPerSecondToHz(jump.control_before))
            << ConvertedNumber(RadPerSecondToHz(jump.control_after));
      } else {
        out << FormatRoundTrip(jump.control_before) << FormatRoundTrip(jump.control_after);
      }
      out << YAML::EndSeq;
      if (frequency) {
        out << YAML::Comment(FormatRoundTrip(jump.control_before) + ", " +
                             FormatRoundTrip(jump.control_after) + " rad/s");
      }
    }
    out << YAML::EndMap;
  }
  out << YAML::EndSeq;
}

void EmitInitialGuess(YAML::Emitter& out, const IdentifyConfig& config) {
  const ParameterVector& initial = config.identification.initial;
  const auto names = ParameterNames(config.identification.solve.residual.form);
  out << YAML::Key << "initial_guess" << YAML::Value << YAML::BeginMap;
  for (int i = 0; i < kNumParameters; ++i) {
    if (!config.initial_guess[i]) {
      out << YAML::Key << (i == kNaturalFrequency ? "omega_hz" : names[i]) << YAML::Value << "auto";
    } else if (i == kNaturalFrequency) {
      out << YAML::Key << "omega_hz" << YAML::Value << ConvertedNumber(RadPerSecondToHz(initial[i]))
          << YAML::Comment(FormatRoundTrip(initial[i]) + " rad/s");
    } else {
      Put(out, names[i], initial[i]);
    }
  }
  out << YAML::EndMap;
}

// fixed, stages, residual and solver: how the fit runs.
void EmitFitSettings(YAML::Emitter& out, const IdentificationOptions& identification,
                     ConfigKeys keys) {
  out << YAML::Key << "fixed" << YAML::Value << YAML::Flow << YAML::BeginSeq;
  for (int i = 0; i < kNumParameters; ++i) {
    if (identification.fixed[i]) out << ParameterName(identification.solve.residual.form, i);
  }
  out << YAML::EndSeq;
  PutList(out, "stages", identification.solve.stages, ResidualKindName);

  out << YAML::Key << "residual" << YAML::Value << YAML::BeginMap;
  Put(out, "error", ErrorMeasureName(identification.solve.residual.error));
  Put(out, "use_point_sigma", identification.solve.residual.use_point_sigma);
  // yaml-cpp's own text of a double, as this key has always been written.
  out << YAML::Key << "amplitude_floor" << YAML::Value
      << identification.solve.residual.amplitude_floor;
  out << YAML::EndMap;

  const SolverSettings& solver = identification.solve.solver;
  out << YAML::Key << "solver" << YAML::Value << YAML::BeginMap;
  Put(out, "max_iterations", solver.max_iterations);
  Put(out, "function_tolerance", solver.function_tolerance);
  Put(out, "start_function_tolerance", solver.start_function_tolerance);
  Put(out, "gradient_tolerance", solver.gradient_tolerance);
  Put(out, "parameter_tolerance", solver.parameter_tolerance);
  if (keys == ConfigKeys::kAll) {
    Put(out, "num_threads", solver.num_threads);
  }
  Put(out, "nonmonotonic_steps", solver.nonmonotonic_steps);
  Put(out, "valley_polish", solver.valley_polish);
  out << YAML::EndMap;
}

void EmitMultiStartAndJumpDetection(YAML::Emitter& out, const IdentifyConfig& config,
                                    ConfigKeys keys) {
  out << YAML::Key << "multi_start" << YAML::Value << YAML::BeginMap;
  Put(out, "starts", config.multi_start.starts);
  Put(out, "spread", config.multi_start.spread);
  Put(out, "seed", config.multi_start.seed);
  if (keys == ConfigKeys::kAll) {
    Put(out, "threads", config.multi_start.threads);
  }
  out << YAML::EndMap;

  const JumpDetectionOptions& jump_detection = config.jump_detection;
  out << YAML::Key << "jump_detection" << YAML::Value << YAML::BeginMap;
  Put(out, "min_ratio", jump_detection.min_ratio);
  Put(out, "min_relative_amplitude", jump_detection.min_relative_amplitude);
  Put(out, "noise_multiple", jump_detection.noise_multiple);
  Put(out, "min_candidate_steps", jump_detection.min_candidate_steps);
  out << YAML::EndMap;
}

void EmitChoices(YAML::Emitter& out, const char* key, const std::vector<ParameterChoice>& choices,
                 bool omega) {
  PutList(out, key, choices, [omega](const ParameterChoice& choice) {
    if (!choice.value) return std::string("free");
    return omega ? ConvertedNumber(RadPerSecondToHz(*choice.value))
                 : FormatRoundTrip(*choice.value);
  });
}

void EmitModelSelection(YAML::Emitter& out, const ModelSelectionConfig& selection) {
  out << YAML::Key << "model_selection" << YAML::Value << YAML::BeginMap;
  EmitChoices(out, "delta", selection.delta, false);
  EmitChoices(out, "mu2", selection.mu2, false);
  EmitChoices(out, "omega_hz", selection.omega, true);
  Put(out, "cross_validation", CrossValidationSchemeName(selection.scheme));
  Put(out, "training", CrossValidationTrainingName(selection.training));
  // No pool: the fitted and validation sweeps (an empty list is refused).
  if (!selection.pool.empty()) PutList(out, "pool", selection.pool, SelectionName);
  Put(out, "threads", selection.threads);
  out << YAML::EndMap;
}

// Only what differs from the model's own form (the defaults), so that a
// config without these keys keeps its text.
void EmitTestQuantities(YAML::Emitter& out, const TestQuantities& test) {
  if (test.excitation != Excitation::kBaseAcceleration) {
    Put(out, "excitation", ExcitationName(test.excitation));
  }
  if (test.response != Response::kDisplacement) Put(out, "response", ResponseName(test.response));
  if (test.estimate_phase_offset || test.phase_offset_rad != 0.0) {
    out << YAML::Key << "phase" << YAML::Value << YAML::BeginMap;
    if (test.estimate_phase_offset) {
      Put(out, "offset", "estimate");
    } else {
      out << YAML::Key << "offset_deg" << YAML::Value
          << ConvertedNumber(test.phase_offset_rad * 180.0 / kPi);
    }
    out << YAML::EndMap;
  }
}

}  // namespace

std::string ConfigToYaml(const IdentifyConfig& config, ConfigKeys keys) {
  YAML::Emitter out;
  if (keys == ConfigKeys::kAll) {
    std::string header = "Configuration in effect, loaded from " + config.config_path;
    for (const ConfigOverride& applied : config.overrides) {
      header += "\noverride: " + DescribeOverride(applied);
    }
    out << YAML::Comment(header) << YAML::Newline;
  }
  out << YAML::BeginMap;
  PutList(out, "data", config.data_files, [](const std::string& file) { return file; });
  PutList(out, "fit", config.fit_sweeps, SelectionName);
  PutList(out, "validate", config.validate_sweeps, SelectionName);
  EmitInitialGuess(out, config);
  EmitFitSettings(out, config.identification, keys);
  EmitPenalties(out, config.identification.solve.penalties);
  EmitMultiStartAndJumpDetection(out, config, keys);
  EmitJumpOverrides(out, config.jump_overrides);
  if (config.omega_ref_rad_s.has_value()) {
    out << YAML::Key << "effective_nonlinearity_reference_hz" << YAML::Value
        << ConvertedNumber(RadPerSecondToHz(*config.omega_ref_rad_s))
        << YAML::Comment(FormatRoundTrip(*config.omega_ref_rad_s) + " rad/s");
  }  // unset: the identified omega (the key's default)
  if (config.model_selection.has_value()) EmitModelSelection(out, *config.model_selection);
  if (config.forcing_calibration.has_value()) {
    out << YAML::Key << "forcing_calibration" << YAML::Value << YAML::BeginMap;
    Put(out, "prior_sigma", config.forcing_calibration->prior_sigma);
    Put(out, "held_out_dwells", HeldOutDwellsName(config.forcing_calibration->held_out_dwells));
    Put(out, "parameter", CalibratedParameterName(config.forcing_calibration->parameter));
    out << YAML::EndMap;
  }
  EmitTestQuantities(out, config.test);
  // Only what differs from the chapter's model, so that a config without the
  // key keeps its text.
  const ModelForm form = config.identification.solve.residual.form;
  if (form != ModelForm{}) {
    out << YAML::Key << "model" << YAML::Value << YAML::BeginMap;
    if (form.second_order()) Put(out, "averaging", AveragingName(form.averaging));
    if (form.cubic_damping()) Put(out, "damping", DampingTermName(form.damping));
    if (form.quintic_stiffness()) Put(out, "backbone", BackboneTermName(form.backbone));
    out << YAML::EndMap;
  }
  if (!config.units.a.empty() || !config.units.a_base.empty()) {
    out << YAML::Key << "units" << YAML::Value << YAML::BeginMap;
    if (!config.units.a.empty()) Put(out, "a", config.units.a);
    if (!config.units.a_base.empty()) Put(out, "a_base", config.units.a_base);
    out << YAML::EndMap;
  }
  if (config.log_amplitude) {
    out << YAML::Key << "plot" << YAML::Value << YAML::BeginMap;
    Put(out, "log_amplitude", true);
    out << YAML::EndMap;
  }
  if (keys == ConfigKeys::kAll && config.write_mat) {
    out << YAML::Key << "outputs" << YAML::Value << YAML::BeginMap;
    Put(out, "mat", true);
    out << YAML::EndMap;
  }
  if (keys == ConfigKeys::kAll) Put(out, "output_dir", config.output_dir);
  out << YAML::EndMap;
  return std::string(out.c_str()) + "\n";
}

}  // namespace dwellfit
