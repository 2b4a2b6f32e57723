#include "dwellfit/estimator/analysis/identification_report.h"

#include <cmath>
#include <utility>

#include "dwellfit/estimator/common/string_printf.h"
#include "dwellfit/estimator/common/version.h"
#include "dwellfit/estimator/data/csv_text.h"
#include "yaml-cpp/yaml.h"

namespace dwellfit {

void AddModelError(const std::vector<const Sweep*>& fitted,
                   const std::vector<const Sweep*>& validation, int threads,
                   IdentificationReport* report) {
  const IdentificationResult& result = report->result;
  report->validation_intervals = PredictValidationIntervals(
      fitted, validation, report->options, result.parameters, result.IsSolutionUsable());
  report->level_refits = RefitLeavingOneLevelOut(fitted, report->options, result.parameters,
                                                 report->omega_ref_rad_s, threads);
}

namespace {

// About the length of one predictions.csv row, to reserve the text at once.
constexpr size_t kPredictionRowBytes = 96;

const char* Role(const SweepPrediction& prediction) {
  return prediction.fitted ? "fitted" : "validation";
}

// The control in the file's unit: Hz for frequencies, a_base as given.
double ControlInFileUnit(const Sweep& sweep, double control) {
  return sweep.kind == SweepKind::kFrequency ? RadPerSecondToHz(control) : control;
}

// `key`: the items of `list` as a sequence (flow style with `flow`).
template <typename List>
void EmitList(const char* key, const List& list, YAML::Emitter* out, bool flow = false) {
  *out << YAML::Key << key << YAML::Value;
  if (flow) *out << YAML::Flow;
  *out << YAML::BeginSeq;
  for (const auto& item : list) *out << item;
  *out << YAML::EndSeq;
}

// `key`: [first, second].
template <typename T>
void EmitPair(const char* key, const T& first, const T& second, YAML::Emitter* out) {
  *out << YAML::Key << key << YAML::Value << YAML::Flow << YAML::BeginSeq << first << second
       << YAML::EndSeq;
}

// Of parameter i (kNumParameters: alpha_e): ci95, the reported interval; with
// the profile's, ci95_ends (crossed, bound, open) and linearised_ci95.
void EmitInterval(const ParameterUncertainty& u, int i, YAML::Emitter* out) {
  const bool p = i < kNumParameters;
  EmitPair("ci95", p ? u.ci95_low[i] : u.effective_nonlinearity_ci95_low,
           p ? u.ci95_high[i] : u.effective_nonlinearity_ci95_high, out);
  const ProfileInterval& profile = p ? u.profile.parameters[i] : u.profile.effective_nonlinearity;
  if (u.interval_kind != "profile_likelihood" || !profile.computed) return;
  EmitPair("ci95_ends", ProfileEndName(profile.low_end), ProfileEndName(profile.high_end), out);
  EmitPair("linearised_ci95",
           p ? u.linearised_ci95_low[i] : u.effective_nonlinearity_linearised_ci95_low,
           p ? u.linearised_ci95_high[i] : u.effective_nonlinearity_linearised_ci95_high, out);
}

// parameters, the natural frequency in Hz and alpha_e with its interval.
void EmitParameters(const IdentificationReport& report, YAML::Emitter* out) {
  const ModelForm form = report.options.solve.residual.form;
  const ParameterVector& p = report.result.parameters;
  const ParameterUncertainty& u = report.uncertainty;
  *out << YAML::Key << "parameters" << YAML::Value << YAML::BeginMap;
  for (int i = 0; i < kNumParameters; ++i) {
    *out << YAML::Key << ParameterName(form, i) << YAML::Value << YAML::BeginMap;
    *out << YAML::Key << "value" << YAML::Value << p[i];
    *out << YAML::Key << "initial" << YAML::Value << report.options.initial[i];
    *out << YAML::Key << "fixed" << YAML::Value << report.options.fixed[i];
    if (u.available && !report.options.fixed[i]) {
      *out << YAML::Key << "standard_error" << YAML::Value << u.standard_error[i];
      EmitInterval(u, i, out);
    }
    if (i == kNaturalFrequency) *out << YAML::Key << "unit" << YAML::Value << "rad/s";
    *out << YAML::EndMap;
  }
  *out << YAML::EndMap;
  *out << YAML::Key << "natural_frequency_hz" << YAML::Value
       << RadPerSecondToHz(p[kNaturalFrequency]);
  *out << YAML::Key << "effective_nonlinearity" << YAML::Value << YAML::BeginMap;
  *out << YAML::Key << "definition" << YAML::Value
       << (form.has_inertia() ? "-(1/3)(2 delta Omega_ref^2 - 3 alpha)" : "alpha");
  *out << YAML::Key << "value" << YAML::Value
       << EffectiveNonlinearity(form, p, report.omega_ref_rad_s);
  *out << YAML::Key << "omega_ref_rad_s" << YAML::Value << report.omega_ref_rad_s;
  if (u.available) {
    *out << YAML::Key << "standard_error" << YAML::Value << u.effective_nonlinearity_standard_error;
    EmitInterval(u, kNumParameters, out);
  }
  *out << YAML::EndMap;
}

void EmitUncertainty(const IdentificationReport& report, YAML::Emitter* out) {
  const ModelForm form = report.options.solve.residual.form;
  const ParameterUncertainty& u = report.uncertainty;
  *out << YAML::Key << "uncertainty" << YAML::Value << YAML::BeginMap;
  *out << YAML::Key << "available" << YAML::Value << u.available;
  *out << YAML::Key << "interval_kind" << YAML::Value << u.interval_kind;
  *out << YAML::Key << "penalty_terms" << YAML::Value << u.penalty_terms;
  if (u.interval_kind == "profile_likelihood") {
    *out << YAML::Key << "profile_threshold" << YAML::Value << u.profile.threshold;
    *out << YAML::Key << "profile_fits" << YAML::Value << u.profile.fits;
  }
  *out << YAML::Key << "message" << YAML::Value << u.message;
  *out << YAML::Key << "noise_sigma" << YAML::Value << u.noise_sigma;
  *out << YAML::Key << "degrees_of_freedom" << YAML::Value << u.degrees_of_freedom;
  if (u.available) {
    *out << YAML::Key << "correlation" << YAML::Value << YAML::BeginMap;
    for (int i = 0; i < kNumParameters; ++i) {
      if (report.options.fixed[i]) continue;
      *out << YAML::Key << ParameterName(form, i) << YAML::Value << YAML::Flow << YAML::BeginSeq;
      for (int j = 0; j < kNumParameters; ++j) {
        if (!report.options.fixed[j]) *out << u.correlation(i, j);
      }
      *out << YAML::EndSeq;
    }
    *out << YAML::EndMap;
  }
  EmitList("warnings", u.warnings, out);
  *out << YAML::EndMap;
}

void EmitStarts(const IdentificationReport& report, YAML::Emitter* out) {
  *out << YAML::Key << "multi_start" << YAML::Value << YAML::BeginMap;
  *out << YAML::Key << "starts" << YAML::Value << report.multi_start.starts.size();
  *out << YAML::Key << "reached_best" << YAML::Value << report.multi_start.reached_best;
  *out << YAML::Key << "best_start" << YAML::Value << report.multi_start.best_start;
  EmitList("final_costs", report.multi_start.final_costs, out, /*flow=*/true);
  *out << YAML::EndMap;
  if (!report.initial_guess_steps.empty()) {
    EmitList("automatic_initial_guess", report.initial_guess_steps, out);
  }
}

void EmitStage(ModelForm form, const StageSummary& stage, YAML::Emitter* out) {
  *out << YAML::BeginMap;
  *out << YAML::Key << "residual" << YAML::Value << ResidualKindName(stage.residual);
  if (stage.fold_stage) *out << YAML::Key << "fold_conditions" << YAML::Value << true;
  if (stage.start_stage) *out << YAML::Key << "start_stage" << YAML::Value << true;
  *out << YAML::Key << "dwells" << YAML::Value << stage.residual_blocks;
  *out << YAML::Key << "initial_cost" << YAML::Value << stage.initial_cost;
  *out << YAML::Key << "final_cost" << YAML::Value << stage.final_cost;
  *out << YAML::Key << "final_data_cost" << YAML::Value << stage.final_data_cost;
  if (stage.penalty_unit > 0.0) {
    *out << YAML::Key << "penalty_unit" << YAML::Value << stage.penalty_unit;
    *out << YAML::Key << "penalty_exponent" << YAML::Value << stage.penalty_exponent;
  }
  *out << YAML::Key << "iterations" << YAML::Value << stage.iterations;
  *out << YAML::Key << "solves" << YAML::Value << stage.solves;
  *out << YAML::Key << "held_at_bound" << YAML::Value << YAML::Flow << YAML::BeginSeq;
  for (int index : stage.held_at_bound) *out << ParameterName(form, index);
  *out << YAML::EndSeq;
  *out << YAML::Key << "converged" << YAML::Value << stage.converged;
  if (stage.penalty_unit > 0.0) {
    *out << YAML::Key << "final_penalty_cost" << YAML::Value << stage.final_penalty_cost;
    EmitList("missing_folds", stage.missing_folds, out);
  }
  if (!stage.note.empty()) *out << YAML::Key << "note" << YAML::Value << stage.note;
  *out << YAML::Key << "solver" << YAML::Value << stage.brief_report;
  *out << YAML::EndMap;
}

// `key`: a number, or null when it is not finite (a missing prediction).
void EmitNumber(const char* key, double value, YAML::Emitter* out) {
  *out << YAML::Key << key << YAML::Value;
  if (std::isfinite(value)) {
    *out << value;
  } else {
    *out << YAML::Null;
  }
}

// One measured or predicted jump: the measured bracket beside the model's
// fold, in the file's unit (Hz or a_base).
void EmitJump(const Sweep& sweep, const PredictedJump& jump, YAML::Emitter* out) {
  const bool frequency = sweep.kind == SweepKind::kFrequency;
  *out << YAML::Flow << YAML::BeginMap;
  *out << YAML::Key << "kind" << YAML::Value << JumpKindName(jump.kind);
  if (jump.measured) {
    EmitPair(frequency ? "measured_between_hz" : "measured_between_a_base",
             ControlInFileUnit(sweep, jump.bracket.control_before),
             ControlInFileUnit(sweep, jump.bracket.control_after), out);
  }
  EmitNumber(frequency ? "model_hz" : "model_a_base",
             jump.exists ? ControlInFileUnit(sweep, jump.control) : NAN, out);
  if (jump.measured) *out << YAML::Key << "inside" << YAML::Value << jump.inside;
  if (jump.measured && jump.bracket.into_missing_data) {
    *out << YAML::Key << "into_missing_data" << YAML::Value << true;
  }
  *out << YAML::EndMap;
}

void EmitSweep(const SweepPrediction& prediction, YAML::Emitter* out) {
  const Sweep& sweep = *prediction.sweep;
  *out << YAML::BeginMap;
  *out << YAML::Key << "name" << YAML::Value << sweep.Name();
  *out << YAML::Key << "role" << YAML::Value << Role(prediction);
  *out << YAML::Key << "kind" << YAML::Value << SweepKindName(sweep.kind);
  *out << YAML::Key << "points" << YAML::Value << sweep.points.size();
  *out << YAML::Key << "rms_error" << YAML::Value << prediction.rms_error;
  *out << YAML::Key << "relative_rms_error" << YAML::Value << prediction.relative_rms_error;
  *out << YAML::Key << "points_off_branch" << YAML::Value << prediction.points_off_branch;
  *out << YAML::Key << "jumps" << YAML::Value << YAML::BeginSeq;
  for (const PredictedJump& jump : prediction.jumps) EmitJump(sweep, jump, out);
  *out << YAML::EndSeq;
  *out << YAML::EndMap;
}

bool IsAmplitude(const HeldOutPrediction& p) {
  return p.quantity == HeldOutQuantity::kUpperBranchAmplitude;
}

void EmitCoverage(const char* key, const IntervalCoverage& c, YAML::Emitter* out) {
  *out << YAML::Key << key << YAML::Value << YAML::Flow << YAML::BeginMap;
  *out << YAML::Key << "inside" << YAML::Value << c.inside;
  *out << YAML::Key << "total" << YAML::Value << c.total;
  EmitNumber("median_half_width", c.median_half_width, out);
  EmitNumber("median_half_width_percent", c.median_half_width_percent, out);
  *out << YAML::EndMap;
}

// validation_intervals: the rule, each quantity's coverage, every prediction.
void EmitValidationIntervals(const ValidationIntervals& v, YAML::Emitter* out) {
  *out << YAML::Key << "validation_intervals" << YAML::Value << YAML::BeginMap;
  *out << YAML::Key << "rule" << YAML::Value << kPredictionIntervalRule;
  *out << YAML::Key << "parameter_covariance" << YAML::Value << v.parameter_covariance;
  if (!v.note.empty()) *out << YAML::Key << "note" << YAML::Value << v.note;
  *out << YAML::Key << "coverage" << YAML::Value << YAML::BeginMap;
  EmitCoverage("jump_down", v.coverage.jump_down, out);
  EmitCoverage("jump_up", v.coverage.jump_up, out);
  EmitCoverage("upper_branch_amplitude", v.coverage.upper_branch, out);
  *out << YAML::EndMap;
  *out << YAML::Key << "predictions" << YAML::Value << YAML::BeginSeq;
  for (const ValidationLevel& level : v.levels) {
    for (const HeldOutPrediction& p : level.predictions) {
      *out << YAML::Flow << YAML::BeginMap;
      *out << YAML::Key << "sweep" << YAML::Value << p.sweep;
      *out << YAML::Key << "quantity" << YAML::Value << HeldOutQuantityKey(p.quantity);
      *out << YAML::Key << "unit" << YAML::Value << (IsAmplitude(p) ? "data" : "Hz");
      *out << YAML::Key << "measured" << YAML::Value << p.measured;
      EmitNumber("predicted", p.predicted, out);
      EmitNumber("half_width", p.half_width, out);
      EmitNumber("parameter_sd", p.parameter_sd, out);
      EmitNumber("model_sd", p.model_sd, out);
      *out << YAML::Key << "inside" << YAML::Value << p.inside;
      *out << YAML::EndMap;
    }
  }
  *out << YAML::EndSeq;
  *out << YAML::EndMap;
}

// leave_one_level_out: the refits and their spread (omega in rad/s).
void EmitLevelRefits(ModelForm form, const LevelRefits& r, YAML::Emitter* out) {
  *out << YAML::Key << "leave_one_level_out" << YAML::Value << YAML::BeginMap;
  *out << YAML::Key << "computed" << YAML::Value << r.computed;
  *out << YAML::Key << "message" << YAML::Value << r.message;
  *out << YAML::Key << "levels" << YAML::Value << YAML::Flow << r.levels;
  if (r.computed) {
    *out << YAML::Key << "usable" << YAML::Value << r.usable;
    *out << YAML::Key << "refits" << YAML::Value << YAML::BeginSeq;
    for (const LevelRefit& refit : r.refits) {
      *out << YAML::Flow << YAML::BeginMap;
      *out << YAML::Key << "left_out" << YAML::Value << refit.left_out;
      *out << YAML::Key << "status" << YAML::Value << FitStatusName(refit.status);
      *out << YAML::Key << "usable" << YAML::Value << refit.usable;
      *out << YAML::Key << "final_cost" << YAML::Value << refit.final_cost;
      for (int i = 0; i < kNumParameters; ++i) {
        *out << YAML::Key << ParameterName(form, i) << YAML::Value << refit.parameters[i];
      }
      *out << YAML::Key << "alpha_e" << YAML::Value << refit.effective_nonlinearity;
      *out << YAML::EndMap;
    }
    *out << YAML::EndSeq;
    *out << YAML::Key << "spread" << YAML::Value << YAML::BeginMap;
    for (const RefitSpread& s : r.spread) {
      *out << YAML::Key << s.name << YAML::Value << YAML::Flow << YAML::BeginMap;
      *out << YAML::Key << "estimate" << YAML::Value << s.estimate;
      *out << YAML::Key << "min" << YAML::Value << s.min;
      *out << YAML::Key << "max" << YAML::Value << s.max;
      *out << YAML::Key << "jackknife_standard_error" << YAML::Value << s.jackknife_standard_error;
      *out << YAML::EndMap;
    }
    *out << YAML::EndMap;
    EmitList("warnings", r.warnings, out);
  }
  *out << YAML::EndMap;
}

// Appends `mapping` (YAML text of a block mapping) to the top-level block
// mapping `yaml` as the value of `key`, every line indented two spaces, as
// text: the configuration is already YAML, and parsing it again to emit it
// cost as much as writing the rest of result.yaml.
void AppendBlockMapping(const char* key, const std::string& mapping, std::string* yaml) {
  yaml->append(key).append(":\n");
  std::size_t begin = 0;
  while (begin < mapping.size()) {
    std::size_t end = mapping.find('\n', begin);
    if (end == std::string::npos) end = mapping.size();
    if (end > begin) yaml->append("  ").append(mapping, begin, end - begin);
    yaml->push_back('\n');
    begin = end + 1;
  }
}

void PrintStages(ModelForm form, const IdentificationResult& result, std::ostream& out) {
  for (const StageSummary& stage : result.stages) {
    out << ResidualKindName(stage.residual) << (stage.fold_stage ? " + fold conditions" : "")
        << (stage.start_stage ? " (start stage)" : "");
    if (stage.penalty_unit > 0.0) out << " + penalties (exponent " << stage.penalty_exponent << ")";
    out << " stage: cost " << StringPrintf("%.7g -> %.7g", stage.initial_cost, stage.final_cost)
        << ", " << stage.iterations << " iterations";
    if (stage.solves > 1) out << " in " << stage.solves << " solves";
    for (size_t i = 0; i < stage.held_at_bound.size(); ++i) {
      out << (i == 0 ? ", held at bound: " : ", ") << ParameterName(form, stage.held_at_bound[i]);
    }
    out << "\n";
    if (!stage.note.empty()) out << "  " << stage.note << "\n";
    out << "  last solve: " << stage.brief_report << "\n";
  }
}

void PrintParameters(const IdentificationReport& report, std::ostream& out) {
  const ModelForm form = report.options.solve.residual.form;
  const IdentificationResult& result = report.result;
  const ParameterUncertainty& u = report.uncertainty;
  const bool profile = u.interval_kind == "profile_likelihood";
  out << StringPrintf("%-8s %-18s %-12s %-34s %-14s %s\n", "param", "estimate",
                      profile ? "lin.std.err" : "std.error",
                      profile ? "95% interval (profile)" : "95% interval (linearised)", "initial",
                      "fixed");
  for (int i = 0; i < kNumParameters; ++i) {
    const bool interval = u.available && !report.options.fixed[i];
    const std::string se = interval ? StringPrintf("%.3g", u.standard_error[i]) : "-";
    const std::string ci =
        interval ? StringPrintf("[%.6g, %.6g]", u.ci95_low[i], u.ci95_high[i]) : "-";
    out << StringPrintf("%-8s %-18.10g %-12s %-34s %-14.6g %s\n", ParameterName(form, i),
                        result.parameters[i], se.c_str(), ci.c_str(), report.options.initial[i],
                        report.options.fixed[i] ? "yes" : "no");
  }
  out << StringPrintf(
      "natural frequency %.8g Hz; effective nonlinearity %.8g at Omega_ref %.6g rad/s\n",
      RadPerSecondToHz(result.parameters[kNaturalFrequency]),
      EffectiveNonlinearity(form, result.parameters, report.omega_ref_rad_s),
      report.omega_ref_rad_s);
  if (u.available) {
    out << StringPrintf("  effective nonlinearity std.error %.3g, 95%% interval [%.6g, %.6g]\n",
                        u.effective_nonlinearity_standard_error, u.effective_nonlinearity_ci95_low,
                        u.effective_nonlinearity_ci95_high);
  }
  out << StringPrintf("final cost %.6g after %d iterations\n", result.final_cost,
                      result.iterations);
  out << StringPrintf("starts: %zu, %d reached the best (start %d)\n",
                      report.multi_start.starts.size(), report.multi_start.reached_best,
                      report.multi_start.best_start);
  out << "uncertainty (" << u.interval_kind << "): " << u.message << "\n";
  for (const std::string& warning : u.warnings) out << "warning: " << warning << "\n";
}

void PrintSweeps(const IdentificationReport& report, std::ostream& out) {
  out << StringPrintf("%-20s %-10s %6s %14s %14s %s\n", "sweep", "role", "points", "rms_error",
                      "relative_rms", "off_branch");
  for (const SweepPrediction& prediction : report.predictions) {
    out << StringPrintf("%-20s %-10s %6zu %14.6g %14.6g %d\n", prediction.sweep->Name().c_str(),
                        Role(prediction), prediction.sweep->points.size(), prediction.rms_error,
                        prediction.relative_rms_error, prediction.points_off_branch);
  }
}

void PrintJumps(const IdentificationReport& report, std::ostream& out) {
  out << "jumps (measured bracket -> model)\n";
  for (const SweepPrediction& prediction : report.predictions) {
    const Sweep& sweep = *prediction.sweep;
    const char* unit = sweep.kind == SweepKind::kFrequency ? " Hz" : "";
    for (const PredictedJump& jump : prediction.jumps) {
      const std::string measured =
          jump.measured
              ? StringPrintf("%.6g..%.6g%s", ControlInFileUnit(sweep, jump.bracket.control_before),
                             ControlInFileUnit(sweep, jump.bracket.control_after), unit)
              : "not measured";
      const std::string model =
          jump.exists
              ? StringPrintf("%.6g%s%s", ControlInFileUnit(sweep, jump.control), unit,
                             jump.measured ? StringPrintf(" (%s, %+.3g %% from the bracket centre)",
                                                          jump.inside ? "inside" : "outside",
                                                          jump.ErrorPercent())
                                                 .c_str()
                                           : "")
              : "no fold";
      out << StringPrintf("%-20s %-10s %-30s %s\n", sweep.Name().c_str(), JumpKindName(jump.kind),
                          measured.c_str(), model.c_str());
    }
  }
}

// The validation sweeps' prediction intervals and each quantity's coverage.
void PrintValidationIntervals(const ValidationIntervals& v, std::ostream& out) {
  if (v.levels.empty()) return;
  out << "validation prediction intervals (95 %)\n  rule: " << kPredictionIntervalRule << "\n";
  if (!v.note.empty()) out << "  " << v.note << "\n";
  out << StringPrintf("%-20s %-24s %-14s %-30s %-9s %s\n", "sweep", "quantity", "measured",
                      "predicted +/- half-width", "error %", "inside");
  for (const ValidationLevel& level : v.levels) {
    for (const HeldOutPrediction& p : level.predictions) {
      const char* unit = IsAmplitude(p) ? "" : " Hz";
      const std::string predicted =
          std::isfinite(p.predicted)
              ? StringPrintf("%.6g +/- %.3g%s", p.predicted, p.half_width, unit)
              : std::string("no fold");
      out << StringPrintf("%-20s %-24s %-14s %-30s %-9s %s\n", p.sweep.c_str(),
                          HeldOutQuantityName(p.quantity),
                          StringPrintf("%.6g%s", p.measured, unit).c_str(), predicted.c_str(),
                          StringPrintf("%+.2f", p.ErrorPercent()).c_str(), p.inside ? "yes" : "no");
    }
  }
  const struct {
    const char* name;
    const IntervalCoverage& c;
    const char* unit;
  } rows[] = {{"jump-down", v.coverage.jump_down, " Hz"},
              {"jump-up", v.coverage.jump_up, " Hz"},
              {"upper-branch amplitude", v.coverage.upper_branch, ""}};
  for (const auto& row : rows) {
    if (row.c.total == 0) continue;
    std::vector<double> errors;
    for (const ValidationLevel& level : v.levels) {
      for (const HeldOutPrediction& p : level.predictions) {
        if (HeldOutQuantityName(p.quantity) == std::string(row.name)) {
          errors.push_back(std::abs(p.ErrorPercent()));
        }
      }
    }
    out << StringPrintf("%s: median |error| %.3g %%, %d of %d measured inside, ", row.name,
                        MedianOf(errors), row.c.inside, row.c.total)
        << (std::isfinite(row.c.median_half_width)
                ? StringPrintf("median half-width %.3g%s (%.3g %%)\n", row.c.median_half_width,
                               row.unit, row.c.median_half_width_percent)
                : std::string("no interval (the model predicts none of them)\n"));
  }
}

// The leave-one-level-out spread beside the reported interval.
void PrintLevelRefits(const IdentificationReport& report, std::ostream& out) {
  const LevelRefits& r = report.level_refits;
  if (r.message.empty()) return;  // not run (AddModelError)
  out << "leave-one-level-out refits: " << r.message << "\n";
  if (!r.computed) return;
  const ParameterUncertainty& u = report.uncertainty;
  if (!r.spread.empty()) {
    out << StringPrintf("%-8s %-14s %-30s %-12s %s\n", "param", "estimate", "refits min..max",
                        "jackknife se", "95% interval");
  }
  for (const RefitSpread& s : r.spread) {
    const bool alpha_e = s.index == kNumParameters;
    const std::string interval =
        !u.available ? "-"
        : alpha_e    ? StringPrintf("[%.6g, %.6g]", u.effective_nonlinearity_ci95_low,
                                    u.effective_nonlinearity_ci95_high)
                     : StringPrintf("[%.6g, %.6g]", u.ci95_low[s.index], u.ci95_high[s.index]);
    out << StringPrintf("%-8s %-14.6g %-30s %-12.3g %s\n", s.name.c_str(), s.estimate,
                        StringPrintf("%.6g..%.6g", s.min, s.max).c_str(),
                        s.jackknife_standard_error, interval.c_str());
  }
  for (const std::string& warning : r.warnings) out << "warning: " << warning << "\n";
}

// omega(a) [Hz] and zeta(a) with their 95 % bands (linearised), one flow
// map per amplitude.
void EmitModalProperties(const ModalProperties& modal, YAML::Emitter* out) {
  *out << YAML::Key << "modal_properties" << YAML::Value << YAML::BeginMap;
  *out << YAML::Key << "band" << YAML::Value << (modal.bands ? "linearised_95" : "none");
  *out << YAML::Key << "points" << YAML::Value << YAML::BeginSeq;
  for (const ModalPoint& p : modal.points) {
    *out << YAML::Flow << YAML::BeginMap;
    EmitNumber("a", p.a, out);
    EmitNumber("omega_hz", p.omega_hz, out);
    *out << YAML::Key << "omega_hz_ci95" << YAML::Value << YAML::Flow << YAML::BeginSeq
         << p.omega_hz_low << p.omega_hz_high << YAML::EndSeq;
    EmitNumber("zeta", p.zeta, out);
    *out << YAML::Key << "zeta_ci95" << YAML::Value << YAML::Flow << YAML::BeginSeq << p.zeta_low
         << p.zeta_high << YAML::EndSeq << YAML::EndMap;
  }
  *out << YAML::EndSeq << YAML::EndMap;
}

}  // namespace

std::string ReportToYaml(const IdentificationReport& report) {
  const IdentificationResult& result = report.result;
  YAML::Emitter out;
  out.SetDoublePrecision(17);
  out << YAML::BeginMap;
  out << YAML::Key << "status" << YAML::Value << FitStatusName(result.status);
  out << YAML::Key << "status_message" << YAML::Value << result.message;
  out << YAML::Key << "dwellfit_version" << YAML::Value << DwellfitVersion();
  out << YAML::Key << "config" << YAML::Value << report.config_path;
  out << YAML::Key << "model" << YAML::Value << YAML::BeginMap;
  out << YAML::Key << "averaging" << YAML::Value
      << AveragingName(report.options.solve.residual.form.averaging);
  out << YAML::EndMap;
  EmitParameters(report, &out);
  EmitUncertainty(report, &out);
  EmitStarts(report, &out);
  out << YAML::Key << "final_cost" << YAML::Value << result.final_cost;
  out << YAML::Key << "iterations" << YAML::Value << result.iterations;
  out << YAML::Key << "converged" << YAML::Value << result.converged;
  out << YAML::Key << "fitted_points" << YAML::Value << result.residual_blocks;
  out << YAML::Key << "stages" << YAML::Value << YAML::BeginSeq;
  for (const StageSummary& stage : result.stages)
    EmitStage(report.options.solve.residual.form, stage, &out);
  out << YAML::EndSeq;
  out << YAML::Key << "sweeps" << YAML::Value << YAML::BeginSeq;
  for (const SweepPrediction& prediction : report.predictions) EmitSweep(prediction, &out);
  out << YAML::EndSeq;
  if (!report.validation_intervals.levels.empty()) {
    EmitValidationIntervals(report.validation_intervals, &out);
  }
  if (!report.level_refits.message.empty()) {
    EmitLevelRefits(report.options.solve.residual.form, report.level_refits, &out);
  }
  if (!report.modal.points.empty()) EmitModalProperties(report.modal, &out);
  out << YAML::EndMap;
  std::string yaml = std::string(out.c_str()) + "\n";
  if (!report.config_in_effect.empty()) {
    AppendBlockMapping("config_in_effect", report.config_in_effect, &yaml);
  }
  return yaml;
}

std::string ReportToPredictionsCsv(const IdentificationReport& report) {
  size_t rows = 0;
  for (const SweepPrediction& prediction : report.predictions) {
    rows += prediction.sweep->points.size();
  }
  CsvText csv("sweep,direction,role,freq_hz,a_base,a,a_model,branch,model_status",
              (rows + 1) * kPredictionRowBytes);
  for (const SweepPrediction& prediction : report.predictions) {
    const Sweep& sweep = *prediction.sweep;
    const char* direction = SweepDirectionName(sweep.direction);
    for (size_t i = 0; i < sweep.points.size(); ++i) {
      const DwellPoint& point = sweep.points[i];
      const StableRoot& model = prediction.model[i];
      csv.Text(sweep.id);
      csv.Text(direction);
      csv.Text(Role(prediction));
      for (double value : {RadPerSecondToHz(point.drive_frequency_rad_s), point.a_base,
                           point.amplitude, model.a}) {
        csv.Number(value);
      }
      csv.Text(BranchName(point.branch));
      csv.Text(model.status == RootStatus::kOnBranch    ? "on_branch"
               : model.status == RootStatus::kBranchEnd ? "branch_end"
                                                        : "failed");
      csv.EndRow();
    }
  }
  return std::move(csv).Release();
}

void PrintReport(const IdentificationReport& report, std::ostream& out) {
  // The chapter's model goes unsaid, so that its reports keep their text.
  if (report.options.solve.residual.form.second_order()) {
    out << "model: second-order averaging (harmonic balance on harmonics 1 and 3; "
           "docs/model.md)\n";
  }
  PrintStages(report.options.solve.residual.form, report.result, out);
  out << "\n";
  PrintParameters(report, out);
  out << "\n";
  PrintSweeps(report, out);
  out << "\n";
  PrintJumps(report, out);
  out << "\n";
  PrintValidationIntervals(report.validation_intervals, out);
  PrintLevelRefits(report, out);
  out << "\nstatus: " << FitStatusName(report.result.status) << ": " << report.result.message
      << "\n";
}

}  // namespace dwellfit
