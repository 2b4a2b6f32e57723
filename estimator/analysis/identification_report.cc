#include "dwellfit/estimator/analysis/identification_report.h"

#include <cstdio>
#include <sstream>

#include "dwellfit/estimator/data/sweep_csv_writer.h"
#include "yaml-cpp/yaml.h"

namespace dwellfit {

IdentificationReport MakeIdentificationReport(const std::string& config_path,
                                              const IdentificationOptions& options,
                                              const IdentificationResult& result,
                                              double omega_ref_rad_s,
                                              const std::vector<const Sweep*>& fitted,
                                              const std::vector<const Sweep*>& validation) {
  IdentificationReport report;
  report.config_path = config_path;
  report.options = options;
  report.result = result;
  report.omega_ref_rad_s = omega_ref_rad_s > 0.0 ? omega_ref_rad_s : result.parameters[kOmega];
  for (const Sweep* sweep : fitted) {
    report.predictions.push_back(PredictSweep(result.parameters, *sweep, /*fitted=*/true));
  }
  for (const Sweep* sweep : validation) {
    report.predictions.push_back(PredictSweep(result.parameters, *sweep, /*fitted=*/false));
  }
  return report;
}

namespace {

const char* Role(const SweepPrediction& prediction) {
  return prediction.fitted ? "fitted" : "validation";
}

// The control in the file's unit: Hz for frequencies, a_base as given.
double ControlInFileUnit(const Sweep& sweep, double control) {
  return sweep.kind == SweepKind::kFrequency ? RadPerSecondToHz(control) : control;
}

}  // namespace

std::string ReportToYaml(const IdentificationReport& report) {
  const IdentificationResult& result = report.result;
  YAML::Emitter out;
  out.SetDoublePrecision(17);
  out << YAML::BeginMap;
  out << YAML::Key << "config" << YAML::Value << report.config_path;
  out << YAML::Key << "parameters" << YAML::Value << YAML::BeginMap;
  for (int i = 0; i < kNumParameters; ++i) {
    out << YAML::Key << ParameterName(i) << YAML::Value << YAML::BeginMap;
    out << YAML::Key << "value" << YAML::Value << result.parameters[i];
    out << YAML::Key << "initial" << YAML::Value << report.options.initial[i];
    out << YAML::Key << "fixed" << YAML::Value << report.options.fixed[i];
    if (report.uncertainty.available && !report.options.fixed[i]) {
      out << YAML::Key << "standard_error" << YAML::Value << report.uncertainty.standard_error[i];
      out << YAML::Key << "ci95" << YAML::Value << YAML::Flow << YAML::BeginSeq
          << report.uncertainty.ci95_low[i] << report.uncertainty.ci95_high[i] << YAML::EndSeq;
    }
    if (i == kOmega) out << YAML::Key << "unit" << YAML::Value << "rad/s";
    out << YAML::EndMap;
  }
  out << YAML::EndMap;
  out << YAML::Key << "natural_frequency_hz" << YAML::Value
      << RadPerSecondToHz(result.parameters[kOmega]);
  out << YAML::Key << "effective_nonlinearity" << YAML::Value << YAML::BeginMap;
  out << YAML::Key << "definition" << YAML::Value << "-(1/3)(2 delta Omega_ref^2 - 3 alpha)";
  out << YAML::Key << "value" << YAML::Value
      << EffectiveNonlinearity(result.parameters, report.omega_ref_rad_s);
  out << YAML::Key << "omega_ref_rad_s" << YAML::Value << report.omega_ref_rad_s;
  if (report.uncertainty.available) {
    out << YAML::Key << "standard_error" << YAML::Value
        << report.uncertainty.effective_nonlinearity_standard_error;
    out << YAML::Key << "ci95" << YAML::Value << YAML::Flow << YAML::BeginSeq
        << report.uncertainty.effective_nonlinearity_ci95_low
        << report.uncertainty.effective_nonlinearity_ci95_high << YAML::EndSeq;
  }
  out << YAML::EndMap;
  const ParameterUncertainty& u = report.uncertainty;
  out << YAML::Key << "uncertainty" << YAML::Value << YAML::BeginMap;
  out << YAML::Key << "available" << YAML::Value << u.available;
  out << YAML::Key << "message" << YAML::Value << u.message;
  out << YAML::Key << "noise_sigma" << YAML::Value << u.noise_sigma;
  out << YAML::Key << "degrees_of_freedom" << YAML::Value << u.degrees_of_freedom;
  if (u.available) {
    out << YAML::Key << "correlation" << YAML::Value << YAML::BeginMap;
    for (int i = 0; i < kNumParameters; ++i) {
      if (report.options.fixed[i]) continue;
      out << YAML::Key << ParameterName(i) << YAML::Value << YAML::Flow << YAML::BeginSeq;
      for (int j = 0; j < kNumParameters; ++j) {
        if (!report.options.fixed[j]) out << u.correlation(i, j);
      }
      out << YAML::EndSeq;
    }
    out << YAML::EndMap;
  }
  out << YAML::Key << "warnings" << YAML::Value << YAML::BeginSeq;
  for (const std::string& warning : u.warnings) out << warning;
  out << YAML::EndSeq;
  out << YAML::EndMap;
  out << YAML::Key << "multi_start" << YAML::Value << YAML::BeginMap;
  out << YAML::Key << "starts" << YAML::Value << report.multi_start.starts.size();
  out << YAML::Key << "reached_best" << YAML::Value << report.multi_start.reached_best;
  out << YAML::Key << "best_start" << YAML::Value << report.multi_start.best_start;
  out << YAML::Key << "final_costs" << YAML::Value << YAML::Flow << YAML::BeginSeq;
  for (double cost : report.multi_start.final_costs) out << cost;
  out << YAML::EndSeq;
  out << YAML::EndMap;
  if (!report.initial_guess_steps.empty()) {
    out << YAML::Key << "automatic_initial_guess" << YAML::Value << YAML::BeginSeq;
    for (const std::string& step : report.initial_guess_steps) out << step;
    out << YAML::EndSeq;
  }
  out << YAML::Key << "final_cost" << YAML::Value << result.final_cost;
  out << YAML::Key << "iterations" << YAML::Value << result.iterations;
  out << YAML::Key << "converged" << YAML::Value << result.converged;
  out << YAML::Key << "fitted_points" << YAML::Value << result.residual_blocks;
  out << YAML::Key << "stages" << YAML::Value << YAML::BeginSeq;
  for (const StageSummary& stage : result.stages) {
    out << YAML::BeginMap;
    out << YAML::Key << "residual" << YAML::Value << ResidualKindName(stage.residual);
    out << YAML::Key << "dwells" << YAML::Value << stage.residual_blocks;
    out << YAML::Key << "initial_cost" << YAML::Value << stage.initial_cost;
    out << YAML::Key << "final_cost" << YAML::Value << stage.final_cost;
    out << YAML::Key << "final_data_cost" << YAML::Value << stage.final_data_cost;
    if (stage.penalty_unit > 0.0) {
      out << YAML::Key << "penalty_unit" << YAML::Value << stage.penalty_unit;
      out << YAML::Key << "penalty_exponent" << YAML::Value << stage.penalty_exponent;
    }
    out << YAML::Key << "iterations" << YAML::Value << stage.iterations;
    out << YAML::Key << "solves" << YAML::Value << stage.solves;
    out << YAML::Key << "held_at_bound" << YAML::Value << YAML::Flow << YAML::BeginSeq;
    for (int index : stage.held_at_bound) out << ParameterName(index);
    out << YAML::EndSeq;
    out << YAML::Key << "converged" << YAML::Value << stage.converged;
    out << YAML::Key << "solver" << YAML::Value << stage.brief_report;
    out << YAML::EndMap;
  }
  out << YAML::EndSeq;
  out << YAML::Key << "sweeps" << YAML::Value << YAML::BeginSeq;
  for (const SweepPrediction& prediction : report.predictions) {
    const Sweep& sweep = *prediction.sweep;
    out << YAML::BeginMap;
    out << YAML::Key << "name" << YAML::Value << sweep.Name();
    out << YAML::Key << "role" << YAML::Value << Role(prediction);
    out << YAML::Key << "kind" << YAML::Value << SweepKindName(sweep.kind);
    out << YAML::Key << "points" << YAML::Value << sweep.points.size();
    out << YAML::Key << "rms_error" << YAML::Value << prediction.rms_error;
    out << YAML::Key << "relative_rms_error" << YAML::Value << prediction.relative_rms_error;
    out << YAML::Key << "points_off_branch" << YAML::Value << prediction.points_off_branch;
    // Measured jump brackets beside the model's jumps (Hz or a_base).
    out << YAML::Key << "jumps" << YAML::Value << YAML::BeginSeq;
    const bool frequency = sweep.kind == SweepKind::kFrequency;
    for (const PredictedJump& jump : prediction.jumps) {
      out << YAML::Flow << YAML::BeginMap;
      out << YAML::Key << "kind" << YAML::Value << JumpKindName(jump.kind);
      if (jump.measured) {
        out << YAML::Key << (frequency ? "measured_between_hz" : "measured_between_a_base")
            << YAML::Value << YAML::Flow << YAML::BeginSeq
            << ControlInFileUnit(sweep, jump.bracket.control_before)
            << ControlInFileUnit(sweep, jump.bracket.control_after) << YAML::EndSeq;
      }
      out << YAML::Key << (frequency ? "model_hz" : "model_a_base") << YAML::Value;
      if (jump.exists) {
        out << ControlInFileUnit(sweep, jump.control);
      } else {
        out << YAML::Null;
      }
      if (jump.measured) out << YAML::Key << "inside" << YAML::Value << jump.inside;
      if (jump.measured && jump.bracket.into_missing_data) {
        out << YAML::Key << "into_missing_data" << YAML::Value << true;
      }
      out << YAML::EndMap;
    }
    out << YAML::EndSeq;
    out << YAML::EndMap;
  }
  out << YAML::EndSeq;
  out << YAML::EndMap;
  return std::string(out.c_str()) + "\n";
}

std::string ReportToPredictionsCsv(const IdentificationReport& report) {
  std::ostringstream csv;
  csv << "sweep,direction,role,freq_hz,a_base,a,a_model,branch,model_status\n";
  for (const SweepPrediction& prediction : report.predictions) {
    const Sweep& sweep = *prediction.sweep;
    for (size_t i = 0; i < sweep.points.size(); ++i) {
      const DwellPoint& point = sweep.points[i];
      const StableRoot& model = prediction.model[i];
      const char* status = model.status == RootStatus::kOnBranch    ? "on_branch"
                           : model.status == RootStatus::kBranchEnd ? "branch_end"
                                                                    : "failed";
      csv << sweep.id << ',' << SweepDirectionName(sweep.direction) << ',' << Role(prediction)
          << ',' << FormatRoundTrip(RadPerSecondToHz(point.drive_frequency_rad_s)) << ','
          << FormatRoundTrip(point.a_base) << ',' << FormatRoundTrip(point.amplitude) << ','
          << FormatRoundTrip(model.a) << ',' << BranchName(point.branch) << ',' << status << '\n';
    }
  }
  return csv.str();
}

void PrintReport(const IdentificationReport& report, std::ostream& out) {
  const IdentificationResult& result = report.result;
  for (const StageSummary& stage : result.stages) {
    out << ResidualKindName(stage.residual);
    if (stage.penalty_unit > 0.0) out << " + penalties (exponent " << stage.penalty_exponent << ")";
    char costs[64];
    std::snprintf(costs, sizeof(costs), "%.7g -> %.7g", stage.initial_cost, stage.final_cost);
    out << " stage: cost " << costs << ", " << stage.iterations << " iterations";
    if (stage.solves > 1) out << " in " << stage.solves << " solves";
    for (size_t i = 0; i < stage.held_at_bound.size(); ++i) {
      out << (i == 0 ? ", held at bound: " : ", ") << ParameterName(stage.held_at_bound[i]);
    }
    out << "\n  last solve: " << stage.brief_report << "\n";
  }
  char line[256];
  out << "\n";
  const ParameterUncertainty& u = report.uncertainty;
  std::snprintf(line, sizeof(line), "%-8s %-18s %-12s %-34s %-14s %s\n", "param", "estimate",
                "std.error", "95% interval", "initial", "fixed");
  out << line;
  for (int i = 0; i < kNumParameters; ++i) {
    const bool interval = u.available && !report.options.fixed[i];
    char se[32] = "-", ci[64] = "-";
    if (interval) {
      std::snprintf(se, sizeof(se), "%.3g", u.standard_error[i]);
      std::snprintf(ci, sizeof(ci), "[%.6g, %.6g]", u.ci95_low[i], u.ci95_high[i]);
    }
    std::snprintf(line, sizeof(line), "%-8s %-18.10g %-12s %-34s %-14.6g %s\n", ParameterName(i),
                  result.parameters[i], se, ci, report.options.initial[i],
                  report.options.fixed[i] ? "yes" : "no");
    out << line;
  }
  std::snprintf(line, sizeof(line),
                "natural frequency %.8g Hz; effective nonlinearity %.8g at "
                "Omega_ref %.6g rad/s\n",
                RadPerSecondToHz(result.parameters[kOmega]),
                EffectiveNonlinearity(result.parameters, report.omega_ref_rad_s),
                report.omega_ref_rad_s);
  out << line;
  if (u.available) {
    std::snprintf(line, sizeof(line),
                  "  effective nonlinearity std.error %.3g, 95%% interval [%.6g, %.6g]\n",
                  u.effective_nonlinearity_standard_error, u.effective_nonlinearity_ci95_low,
                  u.effective_nonlinearity_ci95_high);
    out << line;
  }
  std::snprintf(line, sizeof(line), "final cost %.6g after %d iterations, %s\n", result.final_cost,
                result.iterations, result.converged ? "converged" : "NOT converged");
  out << line;
  std::snprintf(line, sizeof(line), "starts: %zu, %d reached the best (start %d)\n",
                report.multi_start.starts.size(), report.multi_start.reached_best,
                report.multi_start.best_start);
  out << line;
  out << "uncertainty: " << u.message << "\n";
  for (const std::string& warning : u.warnings) out << "warning: " << warning << "\n";
  out << "\n";
  std::snprintf(line, sizeof(line), "%-20s %-10s %6s %14s %14s %s\n", "sweep", "role", "points",
                "rms_error", "relative_rms", "off_branch");
  out << line;
  for (const SweepPrediction& prediction : report.predictions) {
    std::snprintf(line, sizeof(line), "%-20s %-10s %6zu %14.6g %14.6g %d\n",
                  prediction.sweep->Name().c_str(), Role(prediction),
                  prediction.sweep->points.size(), prediction.rms_error,
                  prediction.relative_rms_error, prediction.points_off_branch);
    out << line;
  }
  out << "\njumps (measured bracket -> model)\n";
  for (const SweepPrediction& prediction : report.predictions) {
    const Sweep& sweep = *prediction.sweep;
    const char* unit = sweep.kind == SweepKind::kFrequency ? " Hz" : "";
    for (const PredictedJump& jump : prediction.jumps) {
      std::string measured = "not measured";
      if (jump.measured) {
        std::snprintf(line, sizeof(line), "%.6g..%.6g%s",
                      ControlInFileUnit(sweep, jump.bracket.control_before),
                      ControlInFileUnit(sweep, jump.bracket.control_after), unit);
        measured = line;
      }
      std::string model = "no fold";
      if (jump.exists) {
        std::snprintf(line, sizeof(line), "%.6g%s%s", ControlInFileUnit(sweep, jump.control), unit,
                      jump.measured ? (jump.inside ? " (inside)" : " (outside)") : "");
        model = line;
      }
      std::snprintf(line, sizeof(line), "%-20s %-10s %-30s %s\n", sweep.Name().c_str(),
                    JumpKindName(jump.kind), measured.c_str(), model.c_str());
      out << line;
    }
  }
}

}  // namespace dwellfit
