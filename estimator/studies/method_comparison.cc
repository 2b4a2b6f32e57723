#include "dwellfit/estimator/studies/method_comparison.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <optional>
#include <sstream>
#include <vector>

#include "dwellfit/config/dwell_plan_reader.h"
#include "dwellfit/config/rig_config_reader.h"
#include "dwellfit/estimator/analysis/prediction_intervals.h"
#include "dwellfit/estimator/analysis/sweep_prediction.h"
#include "dwellfit/estimator/common/input_error.h"
#include "dwellfit/estimator/common/string_printf.h"
#include "dwellfit/estimator/fit/identification.h"
#include "dwellfit/estimator/run/resolved_run.h"
#include "dwellfit/estimator/traces/harmonic_balance.h"
#include "dwellfit/estimator/traces/trace_file.h"

namespace dwellfit {
namespace {

// One method of the chapter: the stages it fits with and what it enforces.
struct Method {
  std::string name;
  std::vector<ResidualKind> stages;
  bool range_penalty = false;  // the bifurcation range (through the roots for all_roots)
  bool phase_bias = false;     // the measured phase is off by the study's bias
  double range_weight = 1.0;   // times the config's bifurcation_range.weight
};

// The all-roots method's multiple of the config's range weight: the
// chapter's "large penalty" (3.2.3).
constexpr double kAllRootsRangeWeight = 1e4;

std::vector<Method> Methods(bool with_phase) {
  using R = ResidualKind;
  std::vector<Method> methods;
  if (with_phase) {
    methods.push_back({"phase lag", {R::kPhaseLag}, false, false});
    methods.push_back({"phase lag, biased phase", {R::kPhaseLag}, false, true});
  }
  methods.push_back({"least squares (3.11)", {R::kAlgebraic}, false, false});
  methods.push_back(
      {"all roots + ranges", {R::kAlgebraic, R::kAllRoots}, true, false, kAllRootsRangeWeight});
  methods.push_back({"Newton, no penalty", {R::kAlgebraic, R::kVertical}, false, false});
  methods.push_back({"Newton + ranges", {R::kAlgebraic, R::kVertical}, true, false});
  return methods;
}

struct MethodFit {
  IdentificationResult result;
  // Set for harmonic balance (one linear solve: result.converged, no
  // iterations): its standard errors.
  std::optional<HarmonicBalanceResult> harmonic_balance;
  double seconds = 0.0;
  // |model fold - reference| / reference [%] of every measured jump-down;
  // a missing fold counts 100 %.
  std::vector<double> fitted_jump_down_errors;
  std::vector<double> held_out_jump_down_errors;
};

// The jump-down errors of `sweeps` at `parameters`, against the folds of
// `truth` when given, else against the measured brackets' centres.
std::vector<double> JumpDownErrors(ModelForm form, const std::vector<const Sweep*>& sweeps,
                                   const ParameterVector& parameters,
                                   const std::optional<ParameterVector>& truth) {
  std::vector<double> errors;
  for (const Sweep* sweep : sweeps) {
    const std::vector<PredictedJump> model = PredictJumps(form, parameters, *sweep);
    std::vector<PredictedJump> reference;
    if (truth) reference = PredictJumps(form, *truth, *sweep);
    for (size_t j = 0; j < model.size(); ++j) {
      if (!model[j].measured || model[j].kind != JumpKind::kJumpDown) continue;
      const double target = truth && j < reference.size() && reference[j].exists
                                ? reference[j].control
                                : model[j].bracket.centre();
      errors.push_back(model[j].exists ? 100.0 * std::abs(model[j].control - target) / target
                                       : 100.0);
    }
  }
  return errors;
}

MethodFit FitMethod(const IdentifyConfig& config, const std::optional<std::vector<Sweep>>& sweeps,
                    const Method& method, double phase_bias_rad,
                    const std::optional<ParameterVector>& truth) {
  ResolvedRun run = sweeps ? ResolveRun(config, *sweeps) : ResolveRun(config);
  if (method.phase_bias) {
    for (Sweep& sweep : run.sweeps) {
      for (DwellPoint& point : sweep.points) {
        if (point.phase_rad) *point.phase_rad += phase_bias_rad;
      }
    }
  }
  run.options.solve.stages = method.stages;
  run.options.solve.penalties.branch_stability.enabled = false;
  run.options.solve.penalties.bifurcation_range.enabled = method.range_penalty;
  run.options.solve.penalties.bifurcation_range.weight *= method.range_weight;
  MethodFit fit;
  const auto start = std::chrono::steady_clock::now();
  fit.result = FitRun(run).best;
  fit.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const ModelForm form = run.options.solve.residual.form;
  fit.fitted_jump_down_errors = JumpDownErrors(form, run.fitted, fit.result.parameters, truth);
  fit.held_out_jump_down_errors =
      JumpDownErrors(form, run.validation, fit.result.parameters, truth);
  return fit;
}

double Largest(const std::vector<double>& values) {
  return values.empty() ? 0.0 : *std::max_element(values.begin(), values.end());
}

double Median(const std::vector<double>& values) { return values.empty() ? 0.0 : MedianOf(values); }

double PercentError(double estimate, double reference) {
  if (reference == 0.0) return estimate == 0.0 ? 0.0 : 100.0;
  return 100.0 * std::abs(estimate - reference) / std::abs(reference);
}

// The rows: the free parameters and the effective nonlinearity.
struct Quantity {
  std::string name;
  int index;  // ParameterIndex, or kNumParameters for alpha_e
};

// The rows of the parameters not `fixed` (w in Hz), then alpha_e's.
std::vector<Quantity> Quantities(const std::array<bool, kNumParameters>& fixed,
                                 double omega_ref_rad_s) {
  std::vector<Quantity> rows;
  for (int i = 0; i < kNumParameters; ++i) {
    if (!fixed[i]) rows.push_back({i == kNaturalFrequency ? "w [Hz]" : ParameterName(i), i});
  }
  rows.push_back(
      {StringPrintf("alpha_e at %.4g Hz", RadPerSecondToHz(omega_ref_rad_s)), kNumParameters});
  return rows;
}

double ValueOf(const ParameterVector& p, int index, double omega_ref_rad_s) {
  if (index == kNumParameters) return EffectiveNonlinearity(p, omega_ref_rad_s);
  return index == kNaturalFrequency ? RadPerSecondToHz(p[index]) : p[index];
}

std::string Header(const std::vector<Method>& methods, const std::string& first) {
  std::string text = first;
  std::string rule = "|---|---|";
  for (const Method& m : methods) {
    text += " | " + m.name;
    rule += "---|";
  }
  return text + " |\n" + rule + "\n";
}

// Fits of every method on one dataset (several replicas for the noise study).
struct Comparison {
  std::vector<Method> methods;
  std::vector<std::vector<MethodFit>> fits;  // [method][replica]
  std::vector<Quantity> quantities;
  double omega_ref_rad_s = 0.0;
};

Comparison Compare(const IdentifyConfig& config, const std::vector<Method>& methods,
                   const std::vector<std::optional<std::vector<Sweep>>>& replicas,
                   double phase_bias_rad, const std::optional<ParameterVector>& truth) {
  Comparison c;
  c.methods = methods;
  for (const Method& method : methods) {
    c.fits.emplace_back();
    for (const auto& sweeps : replicas) {
      c.fits.back().push_back(FitMethod(config, sweeps, method, phase_bias_rad, truth));
    }
  }
  // The reference frequency of alpha_e: the config's, else the truth's or the
  // last method's w.
  c.omega_ref_rad_s = config.omega_ref_rad_s.value_or(
      truth ? (*truth)[kNaturalFrequency]
            : c.fits.back().front().result.parameters[kNaturalFrequency]);
  c.quantities = Quantities(config.identification.fixed, c.omega_ref_rad_s);
  return c;
}

// One table row: `cell(method's fits)` per method.
template <typename Cell>
void Row(const Comparison& c, const std::string& name, const std::string& second, const Cell& cell,
         std::ostream& out) {
  out << "| " << name << " | " << second;
  for (const std::vector<MethodFit>& fits : c.fits) out << " | " << cell(fits);
  out << " |\n";
}

template <typename Value>
double Mean(const std::vector<MethodFit>& fits, const Value& value) {
  double sum = 0.0;
  for (const MethodFit& fit : fits) sum += value(fit);
  return sum / static_cast<double>(fits.size());
}

// A row of each method's mean over its fits of `value`, printed with `format`.
template <typename Value>
void MeanRow(const Comparison& c, const std::string& name, const char* format, const Value& value,
             std::ostream& out) {
  Row(
      c, name, "",
      [&](const std::vector<MethodFit>& fits) { return StringPrintf(format, Mean(fits, value)); },
      out);
}

void SolverRows(const Comparison& c, bool wall_time, std::ostream& out) {
  Row(
      c, "converged", "",
      [](const std::vector<MethodFit>& fits) {
        int n = 0;
        for (const MethodFit& fit : fits) n += fit.result.converged;
        return StringPrintf("%d of %zu", n, fits.size());
      },
      out);
  MeanRow(
      c, "iterations", "%.4g", [](const MethodFit& f) { return f.result.iterations; }, out);
  MeanRow(
      c, "fitted jump-downs: largest error %", "%.3g",
      [](const MethodFit& f) { return Largest(f.fitted_jump_down_errors); }, out);
  MeanRow(
      c, "held-out jump-downs: median error %", "%.3g",
      [](const MethodFit& f) { return Median(f.held_out_jump_down_errors); }, out);
  if (wall_time) {
    MeanRow(
        c, "wall time [s]", "%.3g", [](const MethodFit& f) { return f.seconds; }, out);
  }
  out << "\n";
}

// Table 3.1: estimate (and percent error) of every quantity by every method.
void TruthTable(const Comparison& c, const ParameterVector& truth, bool wall_time,
                std::ostream& out) {
  out << Header(c.methods, "| quantity | known value");
  for (const Quantity& q : c.quantities) {
    const double known = ValueOf(truth, q.index, c.omega_ref_rad_s);
    Row(
        c, q.name, StringPrintf("%.6g", known),
        [&](const std::vector<MethodFit>& fits) {
          if (fits.size() == 1) {
            const double estimate = ValueOf(fits[0].result.parameters, q.index, c.omega_ref_rad_s);
            return StringPrintf("%.8g (%.2g %%)", estimate, PercentError(estimate, known));
          }
          return StringPrintf("%.3g %%", Mean(fits, [&](const MethodFit& f) {
                                return PercentError(
                                    ValueOf(f.result.parameters, q.index, c.omega_ref_rad_s),
                                    known);
                              }));
        },
        out);
  }
  SolverRows(c, wall_time, out);
}

// Table 3.2: estimates side by side, each compared with the last method's.
void SideBySideTable(const Comparison& c, bool wall_time, std::ostream& out) {
  out << Header(c.methods, "| quantity | unit");
  const ParameterVector& reference = c.fits.back().front().result.parameters;
  for (const Quantity& q : c.quantities) {
    const double ref = ValueOf(reference, q.index, c.omega_ref_rad_s);
    Row(
        c, q.name, q.index == kNaturalFrequency ? "Hz" : "",
        [&](const std::vector<MethodFit>& f) {
          const double estimate = ValueOf(f[0].result.parameters, q.index, c.omega_ref_rad_s);
          if (ref == 0.0) return StringPrintf("%.6g (-)", estimate);
          return StringPrintf("%.6g (%.3g %%)", estimate, PercentError(estimate, ref));
        },
        out);
  }
  SolverRows(c, wall_time, out);
}

const std::vector<MethodFit>& FitsOf(const Comparison& c, const std::string& name) {
  for (size_t m = 0; m < c.methods.size(); ++m) {
    if (c.methods[m].name == name) return c.fits[m];
  }
  throw InputError("method comparison: no method '" + name + "'");
}

const MethodFit& FitOf(const Comparison& c, const std::string& name, int replica = 0) {
  return FitsOf(c, name)[replica];
}

// The largest relative difference [%] of `a` from `b` over the quantities.
double LargestDifference(const Comparison& c, const ParameterVector& a, const ParameterVector& b) {
  double largest = 0.0;
  for (const Quantity& q : c.quantities) {
    largest = std::max(largest, PercentError(ValueOf(a, q.index, c.omega_ref_rad_s),
                                             ValueOf(b, q.index, c.omega_ref_rad_s)));
  }
  return largest;
}

// The largest difference between two methods' fits of one replica.
double LargestDifference(const Comparison& c, const std::string& a, const std::string& b,
                         int replica = 0) {
  return LargestDifference(c, FitOf(c, a, replica).result.parameters,
                           FitOf(c, b, replica).result.parameters);
}

void Introduction(const MethodComparisonOptions& options, std::ostream& out) {
  out << "# The chapter's methods compared\n\n"
      << "Generated by `build/tools/method_comparison` (from the repository root; see "
         "docs/README.md); do not edit by hand. Each method is a list of `stages:` "
         "(config/README.md) run from the config's start:\n\n"
      << "- **phase lag**: `[phase_lag]`, eqs. (3.9)-(3.10) on the measured phase (section "
         "3.1); **biased phase**: the same with every measured phase "
      << StringPrintf("%+g", options.phase_bias_deg) << " degrees off;\n"
      << "- **least squares (3.11)**: `[algebraic]`, the frequency-response equation alone "
         "(3.2.1);\n"
      << "- **all roots + ranges**: `[algebraic, all_roots]` with `penalties.bifurcation_range` "
         "on: the nearest stable of all six roots, each enforced jump's saddle and node roots "
         "turning complex inside its bracket (3.2.2-3.2.3), the range weight 1e4 times the "
         "config's (the chapter's \"large penalty\");\n"
      << "- **Newton, no penalty** and **Newton + ranges**: `[algebraic, vertical]`, the "
         "vertical error by Newton refinement (3.2.4), without and with the eq. (3.17) "
         "penalty.\n\n"
      << "A run whose first stage is `vertical` or `all_roots` begins with an algebraic start "
         "stage whose end is a candidate start for it (docs/model.md, \"Start stage\"). Here every "
         "such stage follows an explicit algebraic stage, so no start stage runs: each column's "
         "iterations (and `--wall_time`) are those of the stages listed, the algebraic stage's "
         "included in the all-roots and both Newton columns alike.\n\n"
      << "Jump-down errors compare each fold of the fitted model with the true model's fold "
         "(numerical case) or with the centre of the measured bracket (measured data); a "
         "missing fold counts 100 %. Wall-clock times differ between runs and machines, so "
         "this file leaves them out (`method_comparison --wall_time` adds them); the "
         "residuals' cost is timed by `build/benchmarks/method_residual_benchmark`.\n\n";
}

std::vector<std::optional<std::vector<Sweep>>> NoisyReplicas(
    const DwellPlan& plan, const MethodComparisonOptions& options) {
  std::vector<std::optional<std::vector<Sweep>>> replicas;
  for (int r = 0; r < options.noise_seeds; ++r) {
    DwellPlan noisy = plan;
    noisy.noise.relative_sigma = options.relative_noise;
    noisy.noise.seed = options.first_seed + static_cast<std::uint64_t>(r);
    replicas.emplace_back(SimulateDwells(noisy));
  }
  return replicas;
}

void Findings(const Comparison& exact, const Comparison& noisy, const Comparison& measured,
              const DwellPlan& plan, const MethodComparisonOptions& options, std::ostream& out) {
  out << "## Findings\n\n"
      << StringPrintf(
             "- **Phase errors.** On exact data the phase-lag fit is exact (largest "
             "error %.2g %%); with the phase %+g degrees off its largest error is "
             "%.3g %%.\n",
             LargestDifference(exact, FitOf(exact, "phase lag").result.parameters, plan.truth),
             options.phase_bias_deg,
             LargestDifference(exact, FitOf(exact, "phase lag, biased phase").result.parameters,
                               plan.truth));
  auto mean_largest = [](const Comparison& c, const std::string& name) {
    return Mean(FitsOf(c, name),
                [](const MethodFit& f) { return Largest(f.fitted_jump_down_errors); });
  };
  out << StringPrintf(
      "- **Least squares alone and the jump-downs.** Largest fitted jump-down error: with %g %% "
      "noise %.3g %% (least squares) against %.3g %% (Newton + ranges); on the measured beam "
      "%.3g %% against %.3g %%, held-out median %.3g %% against %.3g %%.\n",
      100.0 * options.relative_noise, mean_largest(noisy, "least squares (3.11)"),
      mean_largest(noisy, "Newton + ranges"), mean_largest(measured, "least squares (3.11)"),
      mean_largest(measured, "Newton + ranges"),
      Median(FitOf(measured, "least squares (3.11)").held_out_jump_down_errors),
      Median(FitOf(measured, "Newton + ranges").held_out_jump_down_errors));
  double noisy_difference = 0.0;
  for (int r = 0; r < options.noise_seeds; ++r) {
    noisy_difference = std::max(
        noisy_difference, LargestDifference(noisy, "all roots + ranges", "Newton + ranges", r));
  }
  out << StringPrintf(
      "- **All roots against Newton refinement.** Largest difference between their estimates: "
      "%.2g %% on exact data, %.3g %% over the noisy replicas, %.3g %% on the measured beam. "
      "Per residual evaluation the all-roots residual is the slower; "
      "`build/benchmarks/method_residual_benchmark` measures the ratio.\n\n",
      LargestDifference(exact, "all roots + ranges", "Newton + ranges"), noisy_difference,
      LargestDifference(measured, "all roots + ranges", "Newton + ranges"));
}

std::string DatasetName(const IdentifyConfig& config) {
  const std::string::size_type at = config.config_path.rfind("datasets/");
  return config.config_path.substr(at == std::string::npos ? 0 : at);
}

double StandardErrorOf(const HarmonicBalanceResult& hb, int index) {
  if (index == kNumParameters) return hb.effective_nonlinearity_error;
  return index == kNaturalFrequency ? RadPerSecondToHz(hb.standard_error[index])
                                    : hb.standard_error[index];
}

// The methods on the trace case's dwell points, harmonic balance (on the
// fitted sweeps' traces) as the last column.
Comparison CompareOnTraces(const TraceCase& traces, double phase_bias_rad) {
  Comparison c = Compare(traces.config, Methods(true), {traces.processed.sweeps}, phase_bias_rad,
                         traces.truth);
  const ResolvedRun run = ResolveRun(traces.config, traces.processed.sweeps);
  MethodFit fit;
  fit.harmonic_balance = FittedHarmonicBalance(traces);
  fit.result.parameters = fit.harmonic_balance->estimate;
  fit.result.converged = true;
  const ModelForm form = run.options.solve.residual.form;
  fit.fitted_jump_down_errors =
      JumpDownErrors(form, run.fitted, fit.result.parameters, traces.truth);
  fit.held_out_jump_down_errors =
      JumpDownErrors(form, run.validation, fit.result.parameters, traces.truth);
  c.methods.push_back({"harmonic balance (traces)", {}});
  c.fits.push_back({fit});
  // Every parameter's row: harmonic balance estimates w too.
  c.quantities = Quantities({}, c.omega_ref_rad_s);
  return c;
}

// As TruthTable, with harmonic balance's standard errors and the config's
// fixed parameters marked.
void TraceTable(const Comparison& c, const TraceCase& traces, bool wall_time, std::ostream& out) {
  out << Header(c.methods, "| quantity | known value");
  for (const Quantity& q : c.quantities) {
    const double known = ValueOf(traces.truth, q.index, c.omega_ref_rad_s);
    Row(
        c, q.name, StringPrintf("%.6g", known),
        [&](const std::vector<MethodFit>& fits) {
          const MethodFit& fit = fits[0];
          const double estimate = ValueOf(fit.result.parameters, q.index, c.omega_ref_rad_s);
          const double error = PercentError(estimate, known);
          if (!fit.harmonic_balance) {
            if (q.index < kNumParameters && traces.config.identification.fixed[q.index]) {
              return std::string("fixed");
            }
            return StringPrintf("%.6g (%.2g %%)", estimate, error);
          }
          const double se = StandardErrorOf(*fit.harmonic_balance, q.index);
          return StringPrintf("%.6g ± %.2g (%.2g %%, %.2g se)", estimate, se, error,
                              std::abs(estimate - known) / se);
        },
        out);
  }
  SolverRows(c, wall_time, out);
}

// How harmonic balance compares: what it needs, its errors in standard
// errors, and its bias with noise (errors in the regressors).
void TraceFindings(const Comparison& c, const TraceCase& traces, std::ostream& out) {
  const MethodFit& hb_fit = c.fits.back().front();
  const HarmonicBalanceResult& hb = *hb_fit.harmonic_balance;
  std::string within, beyond;
  for (const Quantity& q : c.quantities) {
    const double known = ValueOf(traces.truth, q.index, c.omega_ref_rad_s);
    const double z = std::abs(ValueOf(hb.estimate, q.index, c.omega_ref_rad_s) - known) /
                     StandardErrorOf(hb, q.index);
    std::string& list = z <= 3.0 ? within : beyond;
    list += (list.empty() ? "" : ", ") + q.name + StringPrintf(" %.2g", z);
  }
  HarmonicBalanceResult all =
      IdentifyHarmonicBalance(traces.processed.harmonics, traces.harmonics, c.omega_ref_rad_s);
  const MethodFit& newton = FitOf(c, "Newton + ranges");
  out << "How it compares:\n\n"
      << StringPrintf(
             "- **Against the truth, in its standard errors:** within 3 se: %s; beyond: "
             "%s.\n",
             within.c_str(), beyond.empty() ? "none" : beyond.c_str())
      << StringPrintf(
             "- **Against Newton + ranges:** alpha_e %.2g %% against %.2g %%, eta_e "
             "%.2g %% against %.2g %%; held-out jump-downs: median %.3g %% against "
             "%.3g %%.\n",
             PercentError(hb.effective_nonlinearity,
                          ValueOf(traces.truth, kNumParameters, c.omega_ref_rad_s)),
             PercentError(ValueOf(newton.result.parameters, kNumParameters, c.omega_ref_rad_s),
                          ValueOf(traces.truth, kNumParameters, c.omega_ref_rad_s)),
             PercentError(hb.estimate[kEtaE], traces.truth[kEtaE]),
             PercentError(newton.result.parameters[kEtaE], traces.truth[kEtaE]),
             Median(hb_fit.held_out_jump_down_errors), Median(newton.held_out_jump_down_errors))
      << "- **What it needs:** the time traces of both channels (the harmonics of u and of the "
         "base, not only a and the lag) and dwells at several drive frequencies and levels: at "
         "one frequency delta and alpha enter the first harmonic only as alpha - (2/3) delta "
         "Omega^2, and `IdentifyHarmonicBalance` refuses columns that cannot separate the six "
         "parameters. It needs no start, no iterations and no jump labels, and w comes out with "
         "the rest; it enforces no measured jump.\n"
      << StringPrintf(
             "- **Its bias with noise:** every column is built from the measured u (u^3, "
             "u u'^2 + u^2 u'', ...), so the noise sits in the regressors as well as in the "
             "right-hand side (errors in variables) and least squares is biased towards zero "
             "beyond its standard errors along the weakly determined direction: delta and alpha, "
             "told apart only by the few per cent by which Omega^2 varies over the sweeps, come "
             "out %.2g %% and %.2g %% off while their combination alpha_e is within its error. "
             "From noise-free traces of the same plan the bias vanishes "
             "(datasets/virtual-beam/README.md). The sweep methods fit the amplitude, the noise "
             "in the response only: it costs them spread (mu1 and mu2 lie inside `identify`'s "
             "95 %% intervals, README) but no bias beyond the first-order model's own (README: "
             "mu1 +7.9 %% on noise-free data), which harmonic balance does not have.\n",
             PercentError(hb.estimate[kDelta], traces.truth[kDelta]),
             PercentError(hb.estimate[kAlpha], traces.truth[kAlpha]))
      << StringPrintf(
             "- **All %d dwells** (validation sweeps included, as "
             "`datasets/virtual-beam/harmonic_balance.yaml`): delta %.6g ± %.2g, alpha "
             "%.6g ± %.2g, alpha_e %.6g ± %.2g.\n\n",
             all.dwells, all.estimate[kDelta], all.standard_error[kDelta], all.estimate[kAlpha],
             all.standard_error[kAlpha], all.effective_nonlinearity,
             all.effective_nonlinearity_error);
}

void TraceSection(const Comparison& c, const TraceCase& traces,
                  const MethodComparisonOptions& options, std::ostream& out) {
  const HarmonicBalanceResult& hb = *c.fits.back().front().harmonic_balance;
  out << "## Virtual beam, from time traces: `" << DatasetName(traces.config) << "`\n\n"
      << StringPrintf(
             "The rig's traces (noise on every dwell's amplitudes, "
             "datasets/virtual-beam/README.md) "
             "processed as `process_traces` does: the sweep methods fit the extracted dwell "
             "points from the config's start (w fixed as the config says); **harmonic balance "
             "(traces)** solves eqs. (3.12)-(3.13) on the %d harmonics of the %d dwells of the "
             "fitted sweeps (%d equations), in one linear least-squares solve (no iterations), "
             "and estimates w as well. Each cell: the estimate and its percent error; harmonic "
             "balance's with its standard error and the error in standard errors.\n\n",
             traces.harmonics, hb.dwells, hb.rows);
  TraceTable(c, traces, options.wall_time, out);
  TraceFindings(c, traces, out);
}

}  // namespace

TraceCase LoadTraceCase(const std::string& config_path, const std::string& plan_path,
                        const std::string& rig_path, const std::string& traces_folder) {
  const RigConfig rig = ReadRigConfig(rig_path);
  const std::vector<DwellTrace> dwells = ReadTraceSet(traces_folder);
  TraceCase traces;
  traces.config = LoadIdentifyConfig(config_path);
  traces.truth = ReadDwellPlan(plan_path).truth;
  traces.processed = ProcessTraces(dwells, rig.processing);
  if (traces.processed.unsettled_dwells > 0) {
    throw InputError(traces_folder, 0, "",
                     StringPrintf("%d dwell(s) look unsettled (process_traces names them); give "
                                  "settled traces",
                                  traces.processed.unsettled_dwells));
  }
  traces.harmonics = rig.processing.harmonics;
  for (const DwellTrace& dwell : dwells) {
    traces.dwell_sweeps.push_back(dwell.sweep + "/" + SweepDirectionName(dwell.direction));
  }
  return traces;
}

HarmonicBalanceResult FittedHarmonicBalance(const TraceCase& traces) {
  if (traces.dwell_sweeps.size() != traces.processed.harmonics.size()) {
    throw InputError(StringPrintf("method comparison: %zu dwell names for %zu dwells' harmonics",
                                  traces.dwell_sweeps.size(), traces.processed.harmonics.size()));
  }
  const ResolvedRun run = ResolveRun(traces.config, traces.processed.sweeps);
  std::vector<DwellHarmonics> fitted;
  for (size_t d = 0; d < traces.dwell_sweeps.size(); ++d) {
    for (const Sweep* sweep : run.fitted) {
      if (sweep->Name() == traces.dwell_sweeps[d]) {
        fitted.push_back(traces.processed.harmonics[d]);
        break;
      }
    }
  }
  return IdentifyHarmonicBalance(
      fitted, traces.harmonics,
      traces.config.omega_ref_rad_s.value_or(traces.truth[kNaturalFrequency]));
}

bool MethodComparisonOptions::IsValid(std::string* error) const {
  // Each seed is a noisy copy of the whole plan and its fits: 10^4 is hours.
  if (noise_seeds < 1 || noise_seeds > 10000) {
    *error = StringPrintf("noise_seeds must be 1 to 10000, got %d", noise_seeds);
    return false;
  }
  if (!(relative_noise > 0.0 && relative_noise < 1.0)) {
    *error = StringPrintf("relative_noise must lie in (0, 1), got %g", relative_noise);
    return false;
  }
  if (!(std::abs(phase_bias_deg) < 90.0)) {
    *error = StringPrintf("phase_bias_deg must lie in (-90, 90), got %g", phase_bias_deg);
    return false;
  }
  return true;
}

std::string MethodComparisonMarkdown(const IdentifyConfig& numerical, const DwellPlan& plan,
                                     const IdentifyConfig& measured, const TraceCase* traces,
                                     const MethodComparisonOptions& options) {
  std::string error;
  if (!options.IsValid(&error)) throw InputError("method comparison: " + error);
  const double bias_rad = options.phase_bias_deg * kPi / 180.0;
  std::ostringstream out;
  Introduction(options, out);
  const Comparison exact = Compare(numerical, Methods(true), {std::nullopt}, bias_rad, plan.truth);
  out << "## Numerical case, exact data (as Table 3.1): `" << DatasetName(numerical) << "`\n\n"
      << "Each cell: the estimate and its percent error.\n\n";
  TruthTable(exact, plan.truth, options.wall_time, out);
  const Comparison noisy =
      Compare(numerical, Methods(true), NoisyReplicas(plan, options), bias_rad, plan.truth);
  out << StringPrintf("## Numerical case, %g %% amplitude noise, %d seeds (%llu-%llu)\n\n",
                      100.0 * options.relative_noise, options.noise_seeds,
                      static_cast<unsigned long long>(options.first_seed),
                      static_cast<unsigned long long>(options.first_seed + options.noise_seeds - 1))
      << "Each cell: the mean over the seeds of the percent error; rows below it, means too. "
         "The phase is the exact fixed point's (noise on the amplitude only).\n\n";
  TruthTable(noisy, plan.truth, options.wall_time, out);
  const Comparison beam = Compare(measured, Methods(false), {std::nullopt}, bias_rad, {});
  out << "## Measured beam (as Table 3.2): `" << DatasetName(measured) << "`\n\n"
      << "No phase was measured, so the phase-lag fit does not apply. Each cell: the estimate "
         "and its percent difference from the last column's.\n\n";
  SideBySideTable(beam, options.wall_time, out);
  std::optional<Comparison> on_traces;
  if (traces) {
    on_traces = CompareOnTraces(*traces, bias_rad);
    TraceSection(*on_traces, *traces, options, out);
  }
  Findings(exact, noisy, beam, plan, options, out);
  return out.str();
}

}  // namespace dwellfit
