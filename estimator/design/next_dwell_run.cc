#include "dwellfit/estimator/design/next_dwell_run.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <map>
#include <sstream>

#include "dwellfit/estimator/analysis/level_noise.h"
#include "dwellfit/estimator/analysis/parameter_uncertainty.h"
#include "dwellfit/estimator/analysis/prediction_intervals.h"
#include "dwellfit/estimator/common/input_error.h"
#include "dwellfit/estimator/common/string_printf.h"
#include "dwellfit/estimator/run/resolved_run.h"

namespace dwellfit {
namespace {

// "key=value,key=value" as a map; throws InputError naming `flag`.
std::map<std::string, std::string> KeyValues(const std::string& text, const std::string& flag) {
  std::map<std::string, std::string> pairs;
  std::stringstream list(text);
  for (std::string item; std::getline(list, item, ',');) {
    const std::string::size_type eq = item.find('=');
    if (eq == std::string::npos || eq == 0) {
      throw InputError(flag, 0, item, "is not key=value (e.g. f_hz=41.5)");
    }
    if (!pairs.emplace(item.substr(0, eq), item.substr(eq + 1)).second) {
      throw InputError(flag, 0, item.substr(0, eq), "is given twice; give it once");
    }
  }
  return pairs;
}

double Number(const std::string& text, const std::string& flag, const std::string& key) {
  char* end = nullptr;
  const double value = std::strtod(text.c_str(), &end);
  if (text.empty() || *end != '\0' || !std::isfinite(value)) {
    throw InputError(flag, 0, key, "'" + text + "' is not a number");
  }
  return value;
}

// The smallest step of the stepped control between consecutive dwells of
// the sweeps of `kind` (frequency [Hz] or level); 0 when there is none.
double SmallestStep(const std::vector<const Sweep*>& sweeps, SweepKind kind) {
  double step = std::numeric_limits<double>::infinity();
  for (const Sweep* sweep : sweeps) {
    if (sweep->kind != kind) continue;
    for (std::size_t i = 1; i < sweep->points.size(); ++i) {
      double d = std::abs(sweep->Control(sweep->points[i]) - sweep->Control(sweep->points[i - 1]));
      if (kind == SweepKind::kFrequency) d = RadPerSecondToHz(d);
      if (d > 0.0) step = std::min(step, d);
    }
  }
  return std::isfinite(step) ? step : 0.0;
}

// "value +/- half-width%", or the half-width itself for a value of 0.
std::string Interval(double value, double half) {
  if (value == 0.0) return StringPrintf("%.5g +/- %.3g", value, half);
  return StringPrintf("%.5g +/- %.3g%%", value, 100.0 * half / std::abs(value));
}

// The half-width after a dwell, as Interval gives it.
std::string HalfWidth(double value, double half) {
  if (value == 0.0) return StringPrintf("%.3g", half);
  return StringPrintf("%.3g%%", 100.0 * half / std::abs(value));
}

}  // namespace

RigState ParseRigState(const std::string& text, const std::string& flag) {
  RigState state;
  bool f = false, level = false;
  for (const auto& [key, value] : KeyValues(text, flag)) {
    if (key == "f_hz") {
      state.frequency_hz = Number(value, flag, key), f = true;
    } else if (key == "level") {
      state.level = Number(value, flag, key), level = true;
    } else if (key == "branch") {
      if (value == "upper")
        state.branch = Branch::kUpper;
      else if (value == "lower")
        state.branch = Branch::kLower;
      else if (value == "only")
        state.branch = Branch::kOnly;
      else
        throw InputError(flag, 0, key, "'" + value + "' is not upper, lower or only");
    } else {
      throw InputError(flag, 0, key, "is not a key of the state; give f_hz, level and branch");
    }
  }
  std::string error;
  if (!f || !level) throw InputError(flag, 0, "", "give f_hz=...,level=...[,branch=upper|lower]");
  if (!state.IsValid(&error)) throw InputError(flag, 0, "", error);
  return state;
}

NextDwellRequest MakeNextDwellRequest(const std::string& state, const std::string& limits,
                                      const std::string& target, DesignOptions options,
                                      const std::string& prefix) {
  NextDwellRequest request;
  request.state = ParseRigState(state, prefix + "state");
  request.limits_text = limits;
  std::string error;
  if (!ParseDesignTarget(target, &options.target, &error)) {
    throw InputError(prefix + "target", 0, "", error);
  }
  if (!options.IsValid(&error)) throw InputError("next_dwell options", 0, "", error);
  request.options = options;
  return request;
}

RigLimits LimitsFromSweeps(const std::vector<const Sweep*>& sweeps) {
  std::vector<double> fs, ls;
  for (const Sweep* sweep : sweeps) {
    for (const DwellPoint& p : sweep->points) {
      fs.push_back(RadPerSecondToHz(p.drive_frequency_rad_s));
      ls.push_back(p.a_base);
    }
  }
  RigLimits limits;
  if (fs.empty()) return limits;
  limits.frequency_min_hz = *std::min_element(fs.begin(), fs.end());
  limits.frequency_max_hz = *std::max_element(fs.begin(), fs.end());
  limits.level_min = *std::min_element(ls.begin(), ls.end());
  limits.level_max = *std::max_element(ls.begin(), ls.end());
  limits.frequency_step_min_hz = SmallestStep(sweeps, SweepKind::kFrequency);
  limits.level_step_min = SmallestStep(sweeps, SweepKind::kAmplitude);
  limits.frequency_step_max_hz = limits.frequency_max_hz - limits.frequency_min_hz;
  limits.level_step_max = limits.level_max - limits.level_min;
  // No sweep of that kind: a tenth of the smallest level, a hundredth of the
  // lowest frequency.
  if (limits.level_step_min == 0.0) limits.level_step_min = 0.1 * limits.level_min;
  if (limits.frequency_step_min_hz == 0.0)
    limits.frequency_step_min_hz = 0.01 * limits.frequency_min_hz;
  return limits;
}

RigLimits OverrideLimits(RigLimits limits, const std::string& text, const std::string& flag) {
  const std::map<std::string, double*> fields = {{"f_min_hz", &limits.frequency_min_hz},
                                                 {"f_max_hz", &limits.frequency_max_hz},
                                                 {"f_step_min_hz", &limits.frequency_step_min_hz},
                                                 {"f_step_max_hz", &limits.frequency_step_max_hz},
                                                 {"level_min", &limits.level_min},
                                                 {"level_max", &limits.level_max},
                                                 {"level_step_min", &limits.level_step_min},
                                                 {"level_step_max", &limits.level_step_max}};
  if (!text.empty()) {
    for (const auto& [key, value] : KeyValues(text, flag)) {
      const auto field = fields.find(key);
      if (field == fields.end()) {
        throw InputError(flag, 0, key,
                         "is not a limit; give f_min_hz, f_max_hz, f_step_min_hz, f_step_max_hz, "
                         "level_min, level_max, level_step_min or level_step_max");
      }
      *field->second = Number(value, flag, key);
    }
  }
  std::string error;
  if (!limits.IsValid(&error)) throw InputError(flag, 0, "", error);
  return limits;
}

namespace {

// kappa of one new dwell's level from the fitted dwells' stated sigmas
// (level_noise.h): the median over the level draws of kappa_g sqrt(n_g), a
// draw of n dwells being the mean of n measured levels; 0 when none states one.
double SingleDwellLevelSigma(const std::vector<const Sweep*>& fitted) {
  std::vector<double> kappas;
  for (const std::vector<const DwellPoint*>& draw : LevelDraws(fitted)) {
    const DwellPoint& first = *draw.front();
    kappas.push_back(*first.a_base_sigma / first.a_base *
                     std::sqrt(static_cast<double>(draw.size())));
  }
  return kappas.empty() ? 0.0 : MedianOf(kappas);
}

}  // namespace

bool DesignBasisFromFit(const std::vector<const Sweep*>& fitted,
                        const IdentificationOptions& options, const ParameterVector& estimate,
                        double omega_ref_rad_s, DesignBasis* basis, std::string* why) {
  const ParameterUncertainty u = EstimateUncertainty(fitted, options, estimate, omega_ref_rad_s,
                                                     nullptr, IntervalMethod::kDataOnly);
  if (!u.available) {
    *why = "the fit gives no covariance to design from: " + u.message;
    return false;
  }
  basis->estimate = estimate;
  basis->fixed = options.fixed;
  basis->covariance = u.covariance;
  basis->noise_sigma = u.noise_sigma;
  basis->interval_quantile = u.interval_quantile;
  basis->degrees_of_freedom = u.degrees_of_freedom;
  basis->noise_known = u.noise_known;
  basis->residual = options.solve.residual;
  basis->omega_ref_rad_s = u.omega_ref_rad_s;
  basis->level_relative_sigma = SingleDwellLevelSigma(fitted);
  return true;
}

namespace {

// The rows of the interval table: each free parameter, alpha_e, and the
// target's quantity when it is neither: name, value and gradient.
struct IntervalRow {
  std::string name;
  double value;
  ParameterGradient gradient;
};

std::vector<IntervalRow> IntervalRows(const Recommendation& rec) {
  const DesignBasis& basis = rec.basis;
  std::vector<IntervalRow> rows;
  for (int j = 0; j < kNumParameters; ++j) {
    if (!basis.fixed[j]) {
      rows.push_back({ParameterName(j), basis.estimate[j], ParameterGradient::Unit(j)});
    }
  }
  IntervalRow row;
  if (!basis.fixed[kAlpha] &&
      QuantityGradient(basis, {TargetKind::kEffectiveNonlinearity}, &row.value, &row.gradient)) {
    row.name = "alpha_e";
    rows.push_back(row);
  }
  const TargetKind kind = rec.target.kind;
  if (kind == TargetKind::kModalFrequency || kind == TargetKind::kJumpFrequency) {
    QuantityGradient(basis, rec.target, &row.value, &row.gradient);
    row.name = rec.target.Name() + " [Hz]";
    rows.push_back(row);
  }
  return rows;
}

}  // namespace

// "-" for a single dwell, else "4 x +0.1 Hz" or "4 x -0.001".
std::string SegmentText(const Candidate& c) {
  if (c.dwells == 1) return "-";
  if (c.frequency_step_hz != 0.0)
    return StringPrintf("%d x %+.4g Hz", c.dwells, c.frequency_step_hz);
  return StringPrintf("%d x %+.4g", c.dwells, c.level_step);
}

void PrintRecommendation(const Recommendation& rec, int top, std::ostream& out) {
  const DesignBasis& basis = rec.basis;
  const int n = std::min<int>(top, rec.ranked.size());
  out << StringPrintf("%-4s %9s %10s %6s %4s %11s %14s %9s %8s %11s %11s\n", "rank", "f_hz",
                      "level", "branch", "jump", "a", "segment", "settle_s", "record_s", "gain",
                      "gain_per_s");
  std::vector<ParameterMatrix> after;
  for (int i = 0; i < n; ++i) {
    Candidate c = rec.ranked[i];
    out << StringPrintf("%-4d %9.4f %10.5g %6s %4s %11.5g %14s %9.3g %8.3g %11.4g %11.4g\n", i + 1,
                        c.frequency_hz, c.level, BranchName(c.branch), c.jumps ? "yes" : "no",
                        c.amplitude, SegmentText(c).c_str(), c.settle_seconds, c.record_seconds,
                        c.gain, c.gain_per_second);
    CandidateRows rows;
    Eigen::MatrixXd noise;
    WalkCandidate(basis, rec.state.branch, rec.present_amplitude, DesignOptions(), &c, &rows,
                  &noise);
    after.push_back(CovarianceAfter(basis.covariance, rows, noise));
  }
  out << "\nexpected 95 % intervals: estimate +/- half-width in % now, then the half-width\n"
         "after the candidate of each rank alone:\n";
  const double q = basis.interval_quantile;
  for (const IntervalRow& row : IntervalRows(rec)) {
    const ParameterGradient& c = row.gradient;
    out << StringPrintf("  %-22s %-26s", row.name.c_str(),
                        Interval(row.value, q * std::sqrt(c.dot(basis.covariance * c))).c_str());
    for (int i = 0; i < n; ++i) {
      out << " #" << i + 1 << " "
          << HalfWidth(row.value, q * std::sqrt(std::max(c.dot(after[i] * c), 0.0)));
    }
    out << "\n";
  }
}

std::string NextDwellCsv(const Recommendation& rec) {
  std::string csv =
      "rank,f_hz,level,branch,jumps,amplitude,settle_s,record_s,gain,gain_per_s,dwells,"
      "f_step_hz,level_step\n";
  for (std::size_t i = 0; i < rec.ranked.size(); ++i) {
    const Candidate& c = rec.ranked[i];
    csv += StringPrintf("%zu,%.10g,%.10g,%s,%d,%.10g,%.6g,%.6g,%.10g,%.10g,%d,%.10g,%.10g\n", i + 1,
                        c.frequency_hz, c.level, BranchName(c.branch), c.jumps ? 1 : 0, c.amplitude,
                        c.settle_seconds, c.record_seconds, c.gain, c.gain_per_second, c.dwells,
                        c.frequency_step_hz, c.level_step);
  }
  return csv;
}

std::string NextDwellGnuplot(const RigState& state, const Recommendation& rec) {
  std::string gp =
      "# Expected gain per second of test time of every candidate next dwell, from\n"
      "# next_dwell.csv. PNG: gnuplot next_dwell.gp; SVG: gnuplot -e \"fmt='svg'\" next_dwell.gp\n"
      "if (!exists(\"fmt\")) fmt = \"png\"\n"
      "if (fmt eq \"svg\") {\n"
      "  set terminal svg size 900,640 dynamic noenhanced font \"sans,12\" background \"white\"\n"
      "} else {\n"
      "  set terminal pngcairo size 900,640 noenhanced font \"sans,10\"\n"
      "}\n"
      "set datafile separator \",\"\n";
  gp += StringPrintf("set output \"%s.\".fmt\n", kNextDwellFigureStem);
  gp += StringPrintf(
      "set title \"next dwell: gain per second (%s), present state and best marked\"\n",
      rec.target.Name().c_str());
  gp +=
      "set xlabel \"drive frequency [Hz]\"\nset ylabel \"base level\"\n"
      "set cblabel \"gain per second of test time\"\nset grid\nset key outside bottom\n"
      "set palette rgb 33,13,10\n";
  gp +=
      "plot \"next_dwell.csv\" skip 1 using 2:3:($11 == 1 ? $10 : 1/0) with points pointtype 5 "
      "pointsize 0.8 palette title \"single dwells\"";
  gp += StringPrintf(
      ", \\\n  \"+\" using (%.10g):(%.10g) every ::0::0 with points pointtype 6 "
      "pointsize 3 lc rgb \"black\" title \"present\"",
      state.frequency_hz, state.level);
  if (!rec.ranked.empty()) {
    gp += StringPrintf(
        ", \\\n  \"+\" using (%.10g):(%.10g) every ::0::0 with points pointtype 3 "
        "pointsize 3 lc rgb \"red\" title \"best\"",
        rec.ranked[0].frequency_hz, rec.ranked[0].level);
  }
  return gp + "\nunset output\n";
}

NextDwellOutcome ComputeNextDwell(const IdentifyConfig& config, const NextDwellRequest& request,
                                  std::ostream& out) {
  NextDwellOutcome outcome;
  std::string error;
  if (!request.options.IsValid(&error)) throw InputError("next_dwell options: " + error);
  // The ranking's decay rate and intervals are the chapter's terms'
  // (next_dwell.cc).
  if (config.identification.solve.residual.form.family_terms()) {
    throw InputError(config.config_path, 0, "model",
                     "next_dwell ranks dwells for the chapter's terms (mu2, delta) only; remove "
                     "damping: and backbone: from model:");
  }
  const ResolvedRun run = ResolveRun(config);
  outcome.limits = OverrideLimits(LimitsFromSweeps(run.fitted), request.limits_text, "--limits");
  outcome.fit = FitRun(run).best;
  out << "fit of " << run.fitted.size() << " sweeps: " << FitStatusName(outcome.fit.status) << " ("
      << outcome.fit.message << ")\n";
  if (outcome.fit.status != FitStatus::kConverged &&
      outcome.fit.status != FitStatus::kNoConvergence) {
    return outcome;
  }
  const double omega_ref =
      config.omega_ref_rad_s.value_or(outcome.fit.parameters[kNaturalFrequency]);
  if (!DesignBasisFromFit(run.fitted, run.options, outcome.fit.parameters, omega_ref,
                          &outcome.basis, &outcome.fit.message)) {
    outcome.fit.status = FitStatus::kUnidentifiable;
    return outcome;
  }
  outcome.recommendation =
      RecommendNextDwell(outcome.basis, request.state, outcome.limits, request.options);
  const Recommendation& rec = outcome.recommendation;
  out << StringPrintf(
      "present: %.6g Hz, level %.6g, %s branch, model a = %.6g; target %s; "
      "s = %.4g; %zu candidates\n\n",
      request.state.frequency_hz, request.state.level, BranchName(request.state.branch),
      rec.present_amplitude, rec.target.Name().c_str(), rec.basis.noise_sigma, rec.ranked.size());
  PrintRecommendation(rec, request.options.top, out);
  const std::string script = NextDwellGnuplot(request.state, rec);
  outcome.files = {{kNextDwellCsvName, NextDwellCsv(rec)}, {"next_dwell.gp", script}};
  if (request.render_figures) {
    const RenderedFigures figures =
        RenderFigures({{kFigureScriptName, script}, outcome.files.front()});
    if (!figures.rendered) out << "figures: " << figures.warning << "\n";
    for (const NamedFile& image : figures.images) outcome.files.push_back(image);
  }
  return outcome;
}

}  // namespace dwellfit
