// ConfigToYaml: the config in effect, in the schema LoadIdentifyConfig reads.
#include <charconv>
#include <string>
#include <vector>

#include "dwellfit/config/identify_config.h"
#include "yaml-cpp/yaml.h"

namespace dwellfit {
namespace {

// The shortest text that reads back as exactly `value`.
std::string ExactNumber(double value) {
  char buffer[64];
  const auto result = std::to_chars(buffer, buffer + sizeof(buffer), value);
  return std::string(buffer, result.ptr);
}

// 15 significant digits: recovers the decimal a person typed from a value
// that went through a unit conversion (Hz -> rad/s -> Hz).
std::string ConvertedNumber(double value) {
  char buffer[64];
  const auto result =
      std::to_chars(buffer, buffer + sizeof(buffer), value, std::chars_format::general, 15);
  return std::string(buffer, result.ptr);
}

void EmitSelections(YAML::Emitter& out, const char* key,
                    const std::vector<SweepSelection>& selections) {
  out << YAML::Key << key << YAML::Value << YAML::Flow << YAML::BeginSeq;
  for (const SweepSelection& selection : selections) out << selection.Name();
  out << YAML::EndSeq;
}

void EmitPenalties(YAML::Emitter& out, const PenaltyOptions& penalties) {
  const BifurcationRangeOptions& range = penalties.bifurcation_range;
  out << YAML::Key << "penalties" << YAML::Value << YAML::BeginMap;
  out << YAML::Key << "bifurcation_range" << YAML::Value << YAML::BeginMap;
  out << YAML::Key << "enabled" << YAML::Value << range.enabled;
  out << YAML::Key << "exponent" << YAML::Value << range.exponent;
  out << YAML::Key << "weight" << YAML::Value << ExactNumber(range.weight);
  out << YAML::Key << "enforce" << YAML::Value << YAML::Flow << YAML::BeginSeq;
  for (JumpTarget target : range.enforce) out << JumpTargetName(target);
  out << YAML::EndSeq;
  out << YAML::EndMap;
  const BranchStabilityOptions& stability = penalties.branch_stability;
  out << YAML::Key << "branch_stability" << YAML::Value << YAML::BeginMap;
  out << YAML::Key << "enabled" << YAML::Value << stability.enabled;
  out << YAML::Key << "lambda" << YAML::Value << ExactNumber(stability.lambda);
  out << YAML::Key << "weight" << YAML::Value << ExactNumber(stability.weight);
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
    out << YAML::Key << "sweep" << YAML::Value << jump.sweep;
    if (jump.none) {
      out << YAML::Key << "none" << YAML::Value << true;
    } else {
      out << YAML::Key << "kind" << YAML::Value << JumpKindName(jump.kind);
      const bool frequency = jump.control == SweepKind::kFrequency;
      out << YAML::Key << (frequency ? "between_hz" : "between_a_base") << YAML::Value << YAML::Flow
          << YAML::BeginSeq;
      if (frequency) {
        out << ConvertedNumber(RadPerSecondToHz(jump.control_before))
            << ConvertedNumber(RadPerSecondToHz(jump.control_after));
      } else {
        out << ExactNumber(jump.control_before) << ExactNumber(jump.control_after);
      }
      out << YAML::EndSeq;
      if (frequency) {
        out << YAML::Comment(ExactNumber(jump.control_before) + ", " +
                             ExactNumber(jump.control_after) + " rad/s");
      }
    }
    out << YAML::EndMap;
  }
  out << YAML::EndSeq;
}

void EmitInitialGuess(YAML::Emitter& out, const IdentifyConfig& config) {
  const ParameterVector& initial = config.identification.initial;
  out << YAML::Key << "initial_guess" << YAML::Value << YAML::BeginMap;
  for (int i = 0; i < kNumParameters; ++i) {
    if (!config.initial_guess[i]) {
      out << YAML::Key << (i == kNaturalFrequency ? "omega_hz" : ParameterName(i)) << YAML::Value
          << "auto";
    } else if (i == kNaturalFrequency) {
      out << YAML::Key << "omega_hz" << YAML::Value << ConvertedNumber(RadPerSecondToHz(initial[i]))
          << YAML::Comment(ExactNumber(initial[i]) + " rad/s");
    } else {
      out << YAML::Key << ParameterName(i) << YAML::Value << ExactNumber(initial[i]);
    }
  }
  out << YAML::EndMap;
}

// fixed, stages, residual and solver: how the fit runs.
void EmitFitSettings(YAML::Emitter& out, const IdentificationOptions& identification,
                     ConfigKeys keys) {
  out << YAML::Key << "fixed" << YAML::Value << YAML::Flow << YAML::BeginSeq;
  for (int i = 0; i < kNumParameters; ++i) {
    if (identification.fixed[i]) out << ParameterName(i);
  }
  out << YAML::EndSeq;
  out << YAML::Key << "stages" << YAML::Value << YAML::Flow << YAML::BeginSeq;
  for (ResidualKind stage : identification.solve.stages) out << ResidualKindName(stage);
  out << YAML::EndSeq;

  out << YAML::Key << "residual" << YAML::Value << YAML::BeginMap;
  out << YAML::Key << "error" << YAML::Value
      << ErrorMeasureName(identification.solve.residual.error);
  out << YAML::Key << "use_point_sigma" << YAML::Value
      << identification.solve.residual.use_point_sigma;
  out << YAML::Key << "amplitude_floor" << YAML::Value
      << identification.solve.residual.amplitude_floor;
  out << YAML::EndMap;

  const SolverSettings& solver = identification.solve.solver;
  out << YAML::Key << "solver" << YAML::Value << YAML::BeginMap;
  out << YAML::Key << "max_iterations" << YAML::Value << solver.max_iterations;
  out << YAML::Key << "function_tolerance" << YAML::Value << ExactNumber(solver.function_tolerance);
  out << YAML::Key << "start_function_tolerance" << YAML::Value
      << ExactNumber(solver.start_function_tolerance);
  out << YAML::Key << "gradient_tolerance" << YAML::Value << ExactNumber(solver.gradient_tolerance);
  out << YAML::Key << "parameter_tolerance" << YAML::Value
      << ExactNumber(solver.parameter_tolerance);
  if (keys == ConfigKeys::kAll) {
    out << YAML::Key << "num_threads" << YAML::Value << solver.num_threads;
  }
  out << YAML::Key << "nonmonotonic_steps" << YAML::Value << solver.nonmonotonic_steps;
  out << YAML::Key << "valley_polish" << YAML::Value << solver.valley_polish;
  out << YAML::EndMap;
}

void EmitMultiStartAndJumpDetection(YAML::Emitter& out, const IdentifyConfig& config,
                                    ConfigKeys keys) {
  out << YAML::Key << "multi_start" << YAML::Value << YAML::BeginMap;
  out << YAML::Key << "starts" << YAML::Value << config.multi_start.starts;
  out << YAML::Key << "spread" << YAML::Value << ExactNumber(config.multi_start.spread);
  out << YAML::Key << "seed" << YAML::Value << config.multi_start.seed;
  if (keys == ConfigKeys::kAll) {
    out << YAML::Key << "threads" << YAML::Value << config.multi_start.threads;
  }
  out << YAML::EndMap;

  const JumpDetectionOptions& jump_detection = config.jump_detection;
  out << YAML::Key << "jump_detection" << YAML::Value << YAML::BeginMap;
  out << YAML::Key << "min_ratio" << YAML::Value << ExactNumber(jump_detection.min_ratio);
  out << YAML::Key << "min_relative_amplitude" << YAML::Value
      << ExactNumber(jump_detection.min_relative_amplitude);
  out << YAML::Key << "noise_multiple" << YAML::Value << ExactNumber(jump_detection.noise_multiple);
  out << YAML::Key << "min_candidate_steps" << YAML::Value << jump_detection.min_candidate_steps;
  out << YAML::EndMap;
}

void EmitChoices(YAML::Emitter& out, const char* key, const std::vector<ParameterChoice>& choices,
                 bool omega) {
  out << YAML::Key << key << YAML::Value << YAML::Flow << YAML::BeginSeq;
  for (const ParameterChoice& choice : choices) {
    if (!choice.value) {
      out << "free";
    } else {
      out << (omega ? ConvertedNumber(RadPerSecondToHz(*choice.value))
                    : ExactNumber(*choice.value));
    }
  }
  out << YAML::EndSeq;
}

void EmitModelSelection(YAML::Emitter& out, const ModelSelectionConfig& selection) {
  out << YAML::Key << "model_selection" << YAML::Value << YAML::BeginMap;
  EmitChoices(out, "delta", selection.delta, false);
  EmitChoices(out, "mu2", selection.mu2, false);
  EmitChoices(out, "omega_hz", selection.omega, true);
  out << YAML::Key << "cross_validation" << YAML::Value
      << CrossValidationSchemeName(selection.scheme);
  out << YAML::Key << "training" << YAML::Value << CrossValidationTrainingName(selection.training);
  EmitSelections(out, "pool", selection.pool);
  out << YAML::Key << "threads" << YAML::Value << selection.threads;
  out << YAML::EndMap;
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
  out << YAML::Key << "data" << YAML::Value << YAML::Flow << YAML::BeginSeq;
  for (const std::string& file : config.data_files) out << file;
  out << YAML::EndSeq;
  EmitSelections(out, "fit", config.fit_sweeps);
  EmitSelections(out, "validate", config.validate_sweeps);
  EmitInitialGuess(out, config);
  EmitFitSettings(out, config.identification, keys);
  EmitPenalties(out, config.identification.solve.penalties);
  EmitMultiStartAndJumpDetection(out, config, keys);
  EmitJumpOverrides(out, config.jump_overrides);
  if (config.omega_ref_rad_s.has_value()) {
    out << YAML::Key << "effective_nonlinearity_reference_hz" << YAML::Value
        << ConvertedNumber(RadPerSecondToHz(*config.omega_ref_rad_s))
        << YAML::Comment(ExactNumber(*config.omega_ref_rad_s) + " rad/s");
  }  // unset: the identified omega (the key's default)
  if (config.model_selection.has_value()) EmitModelSelection(out, *config.model_selection);
  if (keys == ConfigKeys::kAll)
    out << YAML::Key << "output_dir" << YAML::Value << config.output_dir;
  out << YAML::EndMap;
  return std::string(out.c_str()) + "\n";
}

}  // namespace dwellfit
