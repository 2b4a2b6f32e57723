#include "dwellfit/estimator/studies/model_selection.h"

#include <algorithm>
#include <cmath>
#include <exception>
#include <limits>
#include <map>
#include <set>

#include "dwellfit/estimator/analysis/sweep_prediction.h"
#include "dwellfit/estimator/common/input_error.h"
#include "dwellfit/estimator/common/string_printf.h"
#include "dwellfit/estimator/run/resolved_run.h"
#include "tbb/parallel_for.h"
#include "tbb/task_arena.h"

namespace dwellfit {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

// Holds `index` at the choice's value, or frees it.
void ApplyChoice(const ParameterChoice& choice, ParameterIndex index, IdentifyConfig* config) {
  config->identification.fixed[index] = choice.value.has_value();
  if (!choice.value) return;
  config->initial_guess[index] = *choice.value;
  config->identification.initial[index] = *choice.value;
}

// The config as the variant fits it, on `fit` sweeps, with no validation
// sweeps (the study predicts what it needs) and fits on one thread each.
IdentifyConfig VariantConfig(const IdentifyConfig& config, const ModelVariant& variant,
                             const std::vector<SweepSelection>& fit) {
  IdentifyConfig copy = WithVariant(config, variant);
  copy.fit_sweeps = fit;
  copy.validate_sweeps.clear();
  copy.identification.solve.solver.num_threads = 1;
  copy.multi_start.threads = 1;
  return copy;
}

// Every combination of the block's members and choices: backbone slowest,
// then damping, delta, mu2 and omega. A member's own term replaces the
// chapter's choices of its entry by one: free.
std::vector<ModelVariant> ModelVariants(const ModelSelectionConfig& selection,
                                        Averaging averaging) {
  const std::vector<ParameterChoice> free = {{std::nullopt, "free"}};
  std::vector<ModelVariant> variants;
  for (BackboneTerm backbone : selection.backbone) {
    for (DampingTerm damping : selection.damping) {
      const ModelForm form{averaging, damping, backbone};
      for (const ParameterChoice& delta : form.quintic_stiffness() ? free : selection.delta) {
        for (const ParameterChoice& mu2 : form.cubic_damping() ? free : selection.mu2) {
          for (const ParameterChoice& omega : selection.omega) {
            variants.push_back(ModelVariant{delta, mu2, omega, form});
          }
        }
      }
    }
  }
  return variants;
}

// One held-out sweep's predictions (with s_p when `covariance` is given) and
// their errors: a missing prediction counts 100 % (in Hz the measured
// frequency); without a usable fit the relative RMS is left out.
struct SweepResult {
  PredictionErrors errors;
  std::vector<HeldOutPrediction> predictions;
};

SweepResult PredictHeldOutSweep(ModelForm form, const Sweep& sweep,
                                const ParameterVector& parameters, bool usable,
                                const ParameterMatrix* covariance,
                                const std::array<bool, kNumParameters>& fixed) {
  SweepResult result;
  result.predictions = PredictHeldOut(form, sweep, parameters, usable, covariance, fixed);
  PredictionErrors& errors = result.errors;
  for (const HeldOutPrediction& p : result.predictions) {
    const bool known = std::isfinite(p.predicted);
    const double percent = known ? std::abs(p.ErrorPercent()) : 100.0;
    const double hz = known ? std::abs(p.predicted - p.measured) : p.measured;
    const bool down = p.quantity == HeldOutQuantity::kJumpDown;
    if (p.quantity == HeldOutQuantity::kUpperBranchAmplitude) {
      errors.upper_branch_percent.push_back(percent);
    } else {
      (down ? errors.jump_down_percent : errors.jump_up_percent).push_back(percent);
      (down ? errors.jump_down_hz : errors.jump_up_hz).push_back(hz);
    }
  }
  const double relative_rms =
      usable ? PredictSweep(form, parameters, sweep, /*fitted=*/false).relative_rms_error : kNaN;
  if (std::isfinite(relative_rms)) errors.relative_rms.push_back(relative_rms);
  return result;
}

// The cross-validation plan, the same for every variant: training sets
// (set 0: the config's fit sweeps) and, per pool level, the set it is
// predicted from.
struct Plan {
  std::vector<std::string> levels;
  std::vector<std::vector<SweepSelection>> training;
  std::vector<int> fold_training;                     // per level
  std::vector<std::vector<std::string>> fold_sweeps;  // per level: its pool sweeps' names
  std::vector<std::string> validation;                // the config's validate sweeps' names
  std::vector<std::vector<std::string>> predicts;     // per training set: the sweeps it predicts
};

std::string Key(const std::vector<SweepSelection>& selections) {
  std::string key;
  for (const SweepSelection& s : selections) key += s.Name() + ";";
  return key;
}

int TrainingIndex(const std::vector<SweepSelection>& set, Plan* plan) {
  for (std::size_t i = 0; i < plan->training.size(); ++i) {
    if (Key(plan->training[i]) == Key(set)) return static_cast<int>(i);
  }
  plan->training.push_back(set);
  plan->predicts.emplace_back();
  return static_cast<int>(plan->training.size()) - 1;
}

// The pool's sweeps (checked to exist) and their levels in data order.
std::vector<const Sweep*> PoolSweeps(const IdentifyConfig& config,
                                     const std::vector<SweepSelection>& pool,
                                     const std::vector<Sweep>& sweeps,
                                     std::vector<std::string>* levels) {
  const std::vector<const Sweep*> selected =
      SelectSweeps(sweeps, pool, config.config_path, "model_selection.pool");
  for (const Sweep* sweep : selected) {
    if (std::find(levels->begin(), levels->end(), sweep->id) == levels->end()) {
      levels->push_back(sweep->id);
    }
  }
  return selected;
}

Plan MakePlan(const IdentifyConfig& config, const ModelSelectionConfig& selection,
              const std::vector<Sweep>& sweeps) {
  std::vector<SweepSelection> pool = selection.pool;
  if (pool.empty()) {
    pool = config.fit_sweeps;
    pool.insert(pool.end(), config.validate_sweeps.begin(), config.validate_sweeps.end());
  }
  Plan plan;
  const std::vector<const Sweep*> pool_sweeps = PoolSweeps(config, pool, sweeps, &plan.levels);
  TrainingIndex(config.fit_sweeps, &plan);
  for (const Sweep* sweep :
       SelectSweeps(sweeps, config.validate_sweeps, config.config_path, "validate")) {
    plan.validation.push_back(sweep->Name());
  }
  plan.predicts[0] = plan.validation;
  if (selection.scheme == CrossValidationScheme::kNone) return plan;
  if (plan.levels.size() < 2) {
    throw InputError(config.config_path, 0, "model_selection.pool",
                     "the pool holds " + std::to_string(plan.levels.size()) +
                         " level(s); leave-one-level-out needs at least two");
  }
  for (int level = 0; level < static_cast<int>(plan.levels.size()); ++level) {
    std::vector<SweepSelection> set;
    if (selection.training == CrossValidationTraining::kConfig) {
      set = ConfigTraining(config, plan.levels, level);
    } else {
      for (const SweepSelection& s : pool) {
        if (s.sweep_id != plan.levels[level]) set.push_back(s);
      }
    }
    const int index = TrainingIndex(set, &plan);
    plan.fold_training.push_back(index);
    plan.fold_sweeps.emplace_back();
    for (const Sweep* sweep : pool_sweeps) {
      if (sweep->id != plan.levels[level]) continue;
      plan.fold_sweeps.back().push_back(sweep->Name());
      std::vector<std::string>& names = plan.predicts[index];
      if (std::find(names.begin(), names.end(), sweep->Name()) == names.end()) {
        names.push_back(sweep->Name());
      }
    }
  }
  return plan;
}

// One fit of the study and its predictions, keyed by sweep name.
struct TaskResult {
  VariantFit fit;
  std::map<std::string, SweepResult> predicted;
  std::exception_ptr error;  // an InputError of the config's own fit
};

// A fit the solver calls usable whose parameters are not finite or not
// physical (eta_e or w not positive) is counted as failed, with the reason.
void DemoteImplausibleFit(IdentificationResult* result) {
  if (!result->IsSolutionUsable()) return;
  const ParameterVector& p = result->parameters;
  std::string reason;
  if (!std::all_of(p.begin(), p.end(), [](double v) { return std::isfinite(v); })) {
    reason = "parameters not finite";
  } else if (!(p[kEtaE] > 0.0) || !(p[kNaturalFrequency] > 0.0)) {
    reason = StringPrintf("non-physical parameters (eta_e %.4g, w %.4g rad/s)", p[kEtaE],
                          p[kNaturalFrequency]);
  }
  if (reason.empty()) return;
  result->status = FitStatus::kFailure;
  result->message =
      "counted as failed by the study: " + reason + " (solver: " + result->message + ")";
}

bool Predicts(const Plan& plan, int set, const Sweep& sweep) {
  const auto& names = plan.predicts[set];
  return std::find(names.begin(), names.end(), sweep.Name()) != names.end();
}

TaskResult RunTask(const IdentifyConfig& config, const ModelVariant& variant,
                   const std::vector<Sweep>& sweeps, const Plan& plan, int set) {
  TaskResult task;
  for (const SweepSelection& s : plan.training[set]) task.fit.fitted_sweeps.push_back(s.Name());
  const IdentifyConfig variant_config = VariantConfig(config, variant, plan.training[set]);
  const std::array<bool, kNumParameters>& fixed = variant_config.identification.fixed;
  const ModelForm form = variant_config.identification.solve.residual.form;
  ResolvedRun run;
  try {
    run = ResolveRun(variant_config, sweeps);
  } catch (const InputError& error) {
    if (set == 0) task.error = std::current_exception();
    task.fit.status = FitStatus::kFailure;
    task.fit.message = std::string("could not start: ") + error.what();
    for (const Sweep& sweep : sweeps) {
      if (!Predicts(plan, set, sweep)) continue;
      task.predicted[sweep.Name()] = PredictHeldOutSweep(form, sweep, {}, false, nullptr, fixed);
    }
    return task;
  }
  IdentificationResult result = FitRun(run).best;
  DemoteImplausibleFit(&result);
  task.fit.status = result.status;
  task.fit.message = result.message;
  task.fit.final_cost = result.final_cost;
  task.fit.data_cost = result.stages.empty() ? kNaN : result.stages.back().final_data_cost;
  task.fit.dwells = result.residual_blocks;
  task.fit.iterations = result.iterations;
  task.fit.parameters = result.parameters;
  // The intervals are for the cross-validation's held-out levels.
  const bool held_out_levels = !plan.fold_training.empty();
  const std::optional<ParameterMatrix> covariance =
      held_out_levels && result.IsSolutionUsable()
          ? FitPredictionCovariance(run.fitted, run.options, result.parameters)
          : std::nullopt;
  for (const Sweep& sweep : run.sweeps) {
    if (!Predicts(plan, set, sweep)) continue;
    task.predicted[sweep.Name()] =
        PredictHeldOutSweep(form, sweep, result.parameters, result.IsSolutionUsable(),
                            covariance ? &*covariance : nullptr, fixed);
  }
  return task;
}

// Runs every (variant, training set) fit on `threads` threads; results in
// task order whatever the thread count.
std::vector<TaskResult> RunTasks(const IdentifyConfig& config,
                                 const std::vector<ModelVariant>& variants,
                                 const std::vector<Sweep>& sweeps, const Plan& plan, int threads) {
  const int sets = static_cast<int>(plan.training.size());
  const int count = static_cast<int>(variants.size()) * sets;
  std::vector<TaskResult> results(count);
  tbb::task_arena(std::max(1, std::min({threads, count, tbb::this_task_arena::max_concurrency()})))
      .execute([&] {
        tbb::parallel_for(
            0, count,
            [&](int i) {
              results[i] = RunTask(config, variants[i / sets], sweeps, plan, i % sets);
            },
            tbb::simple_partitioner());
      });
  for (const TaskResult& result : results) {
    if (result.error) std::rethrow_exception(result.error);
  }
  return results;
}

void Criteria(VariantResult* result) {
  const VariantFit& fit = result->fits[0];
  result->aic = result->bic = kNaN;
  if (!(fit.status == FitStatus::kConverged || fit.status == FitStatus::kNoConvergence)) return;
  const double n = fit.dwells;
  const double minus_two_log_likelihood =
      n * (std::log(2.0 * M_PI * 2.0 * fit.data_cost / n) + 1.0);
  result->aic = minus_two_log_likelihood + 2.0 * result->free_parameters;
  result->bic = minus_two_log_likelihood + result->free_parameters * std::log(n);
}

// The spread of `value` (of a fit's parameters) over the fits.
template <typename Value>
ParameterSpread SpreadOf(const std::string& name, ParameterIndex index,
                         const std::vector<const VariantFit*>& fits, const Value& value) {
  std::vector<double> values;
  for (const VariantFit* fit : fits) values.push_back(value(fit->parameters));
  ParameterSpread spread;
  spread.name = name;
  spread.index = index;
  spread.min = *std::min_element(values.begin(), values.end());
  spread.max = *std::max_element(values.begin(), values.end());
  spread.median = MedianOf(values);
  spread.relative_range = spread.median != 0.0 ? (spread.max - spread.min) / std::abs(spread.median)
                                               : (spread.max > spread.min ? kInf : 0.0);
  return spread;
}

// Every free parameter's spread over the usable fits (w in Hz), alpha_e's
// when alpha is free.
std::vector<ParameterSpread> Spreads(const IdentifyConfig& config, ModelForm form,
                                     const std::array<bool, kNumParameters>& fixed,
                                     const std::vector<const VariantFit*>& usable) {
  std::vector<ParameterSpread> spreads;
  std::vector<double> w;
  for (const VariantFit* fit : usable) w.push_back(fit->parameters[kNaturalFrequency]);
  const double omega_ref = config.omega_ref_rad_s.value_or(MedianOf(w));
  for (int j = 0; j < kNumParameters; ++j) {
    if (fixed[j]) continue;
    const bool frequency = j == kNaturalFrequency;
    spreads.push_back(SpreadOf(
        frequency ? "w [Hz]" : ParameterName(form, j), static_cast<ParameterIndex>(j), usable,
        [&](const ParameterVector& p) { return frequency ? RadPerSecondToHz(p[j]) : p[j]; }));
    if (j != kAlpha) continue;
    spreads.push_back(SpreadOf("alpha_e", kAlpha, usable, [&](const ParameterVector& p) {
      return EffectiveNonlinearity(form, p, omega_ref);
    }));
  }
  return spreads;
}

// The spreads of the variant's usable fits, and whether it is unstable
// (kUnstableFrequencyRange, kUnstableScaleRange).
void Stability(const IdentifyConfig& config, VariantResult* result) {
  std::vector<const VariantFit*> usable;
  for (const VariantFit& fit : result->fits) {
    if (fit.status == FitStatus::kConverged || fit.status == FitStatus::kNoConvergence) {
      usable.push_back(&fit);
    }
  }
  if (usable.size() < 2) return;
  result->spread = Spreads(config, result->variant.form,
                           WithVariant(config, result->variant).identification.fixed, usable);
  for (const ParameterSpread& spread : result->spread) {
    const bool frequency = spread.index == kNaturalFrequency;
    const bool scale = spread.name == "eta_e" || spread.name == "mu1" || spread.name == "alpha_e";
    const double limit = frequency ? kUnstableFrequencyRange : kUnstableScaleRange;
    if (!(frequency || scale) || !(spread.relative_range > limit)) continue;
    result->unstable = true;
    result->stability +=
        (result->stability.empty() ? "" : "; ") +
        StringPrintf(
            "%s ranges over %.4g..%.4g across its %zu fits (%.0f %% of its median, "
            "above %.0f %%)",
            spread.name.c_str(), spread.min, spread.max, usable.size(),
            100.0 * spread.relative_range, 100.0 * limit);
  }
}

// The rule's scores: from the cross-validation when it scored a jump-down,
// else from the validate sweeps.
void Scores(VariantResult* result) {
  const PredictionErrors& errors = !result->cross_validation.jump_down_percent.empty()
                                       ? result->cross_validation
                                       : result->validation;
  result->jump_down_hz = MedianOf(errors.jump_down_hz);
  result->jump_down_percent = MedianOf(errors.jump_down_percent);
  result->jump_up_hz = MedianOf(errors.jump_up_hz);
  result->jump_up_percent = MedianOf(errors.jump_up_percent);
  result->upper_branch_percent = MedianOf(errors.upper_branch_percent);
}

VariantResult Assemble(const IdentifyConfig& config, const ModelVariant& variant, const Plan& plan,
                       const std::vector<TaskResult>& tasks, int first_task) {
  VariantResult result;
  result.variant = variant;
  result.free_parameters = variant.FreeParameters(config);
  for (std::size_t s = 0; s < plan.training.size(); ++s) {
    result.fits.push_back(tasks[first_task + s].fit);
    const FitStatus status = result.fits.back().status;
    result.fits_not_converged += status == FitStatus::kNoConvergence;
    result.fits_failed += status != FitStatus::kConverged && status != FitStatus::kNoConvergence;
  }
  result.eligible = result.fits_not_converged == 0 && result.fits_failed == 0;
  Criteria(&result);
  for (const std::string& name : plan.validation) {
    result.validation.Add(tasks[first_task].predicted.at(name).errors);
  }
  for (std::size_t level = 0; level < plan.fold_training.size(); ++level) {
    CrossValidationFold fold;
    fold.held_out_level = plan.levels[level];
    fold.fit = plan.fold_training[level];
    for (const std::string& name : plan.fold_sweeps[level]) {
      const SweepResult& predicted = tasks[first_task + fold.fit].predicted.at(name);
      fold.errors.Add(predicted.errors);
      fold.predictions.insert(fold.predictions.end(), predicted.predictions.begin(),
                              predicted.predictions.end());
    }
    result.cross_validation.Add(fold.errors);
    result.folds.push_back(fold);
  }
  AddPredictionIntervals(&result);
  Stability(config, &result);
  Scores(&result);
  return result;
}

// The resonance's half-power width mu1 / pi Hz (2 mu1 rad/s: the model's
// damping term is 2 mu1 u'), median over the candidates' own fits.
double ResonanceWidthHz(const ModelSelectionReport& report, const std::vector<int>& candidates) {
  std::vector<double> widths;
  for (int i : candidates) widths.push_back(report.variants[i].fits[0].parameters[kMu1] / M_PI);
  return MedianOf(widths);
}

// The best (lowest) of `score` over `candidates`; NaN when none is finite.
template <typename Score>
double Best(const ModelSelectionReport& report, const std::vector<int>& candidates, Score score) {
  double best = kNaN;
  for (int i : candidates) {
    const double value = score(report.variants[i]);
    if (std::isfinite(value) && !(value >= best)) best = value;
  }
  return best;
}

std::string RuleText(const ModelSelectionReport& report) {
  // Without a candidate there is no fit to take the width from.
  const std::string width = std::isfinite(report.jump_tolerance_hz)
                                ? StringPrintf(" = %.3g Hz", report.jump_tolerance_hz)
                                : std::string(" (no candidate to take it from)");
  return StringPrintf(
      "candidates: the variants whose every fit converged, the stable ones first (w's range "
      "over a variant's fits within %.0f %% of its median, eta_e's, mu1's and alpha_e's within "
      "%.0f %%); on each of the median held-out jump-down error, jump-up error (Hz) and "
      "upper-branch amplitude error (%%), a candidate is near-best within a tolerance of the "
      "best candidate's score: the resonance's half-power width mu1/pi%s for the jumps, "
      "%.2g percentage points (a quarter of the best, at least %.0f) for the amplitudes; the "
      "candidate near-best on the most scores wins, the lowest BIC among those tied",
      100.0 * kUnstableFrequencyRange, 100.0 * kUnstableScaleRange, width.c_str(),
      report.amplitude_tolerance_percent, kAmplitudeToleranceFloorPercent);
}

// Step 2 of the rule: how many scores each candidate is near-best on.
void CountNearBest(ModelSelectionReport* report, const std::vector<int>& candidates) {
  const double tolerances[3] = {report->jump_tolerance_hz, report->jump_tolerance_hz,
                                report->amplitude_tolerance_percent};
  const auto score = [](const VariantResult& v, int s) {
    return s == 0 ? v.jump_down_hz : s == 1 ? v.jump_up_hz : v.upper_branch_percent;
  };
  for (int s = 0; s < 3; ++s) {
    const double best =
        Best(*report, candidates, [&](const VariantResult& v) { return score(v, s); });
    for (int i : candidates) {
      const double value = score(report->variants[i], s);
      if (std::isfinite(best) && std::isfinite(value) && value <= best + tolerances[s]) {
        ++report->variants[i].near_best;
      }
    }
  }
}

// What the user must know about the chosen variant: amplitudes much worse
// than the best candidate's, or unstable.
void WarnAbout(ModelSelectionReport* report, const std::vector<int>& candidates, bool any_stable) {
  const VariantResult& chosen = report->variants[report->recommended];
  const double best_amplitude =
      Best(*report, candidates, [](const VariantResult& v) { return v.upper_branch_percent; });
  if (std::isfinite(best_amplitude) &&
      chosen.upper_branch_percent > kMuchWorseFactor * best_amplitude &&
      chosen.upper_branch_percent > best_amplitude + report->amplitude_tolerance_percent) {
    report->warnings.push_back(StringPrintf(
        "its held-out upper-branch amplitudes are off by a median %.1f %%, against %.1f %% for "
        "the best variant: much worse on amplitudes",
        chosen.upper_branch_percent, best_amplitude));
  }
  if (chosen.unstable) {
    report->warnings.push_back("its parameters are unstable across the cross-validation fits: " +
                               chosen.stability);
  }
  if (!any_stable) {
    report->warnings.push_back(
        "every variant is unstable across its fits, so the candidates are all of them");
  }
}

// Step 3 of the rule: the candidate near-best on the most scores (the
// lowest BIC among those tied, the first of equals).
int Choose(const ModelSelectionReport& report, const std::vector<int>& candidates) {
  return *std::min_element(candidates.begin(), candidates.end(), [&](int i, int j) {
    const VariantResult& a = report.variants[i];
    const VariantResult& b = report.variants[j];
    return a.near_best > b.near_best || (a.near_best == b.near_best && a.bic < b.bic);
  });
}

}  // namespace

// The training set of `level` under `training: config`: the config's fit
// sweeps, the level's own replaced by the nearest pool level not fitted.
std::vector<SweepSelection> ConfigTraining(const IdentifyConfig& config,
                                           const std::vector<std::string>& levels, int level) {
  std::set<std::string> fitted;
  for (const SweepSelection& s : config.fit_sweeps) fitted.insert(s.sweep_id);
  if (!fitted.count(levels[level])) return config.fit_sweeps;
  const int count = static_cast<int>(levels.size());
  for (int distance = 1; distance < count; ++distance) {
    for (int candidate : {level - distance, level + distance}) {
      if (candidate < 0 || candidate >= count || fitted.count(levels[candidate])) continue;
      std::vector<SweepSelection> set = config.fit_sweeps;
      for (SweepSelection& s : set) {
        if (s.sweep_id == levels[level]) s.sweep_id = levels[candidate];
      }
      return set;
    }
  }
  throw InputError(config.config_path, 0, "model_selection.pool",
                   "every pool level is fitted, so level '" + levels[level] +
                       "' has no unfitted level to stand in for it; widen the pool");
}

void RecommendVariant(ModelSelectionReport* report) {
  std::vector<int> eligible, stable;
  for (int i = 0; i < static_cast<int>(report->variants.size()); ++i) {
    const VariantResult& v = report->variants[i];
    if (!v.eligible) continue;
    eligible.push_back(i);
    if (!v.unstable) stable.push_back(i);
  }
  const std::vector<int>& candidates = stable.empty() ? eligible : stable;
  for (VariantResult& v : report->variants) v.near_best = -1;
  for (int i : candidates) report->variants[i].near_best = 0;
  report->jump_tolerance_hz = ResonanceWidthHz(*report, candidates);
  const double best_amplitude =
      Best(*report, candidates, [](const VariantResult& v) { return v.upper_branch_percent; });
  report->amplitude_tolerance_percent =
      std::isfinite(best_amplitude)
          ? std::max(kAmplitudeToleranceFloorPercent, kAmplitudeToleranceShare * best_amplitude)
          : kAmplitudeToleranceFloorPercent;
  report->rule = RuleText(*report);
  if (candidates.empty()) {
    report->verdict =
        "no variant qualifies: every variant has a fit that did not converge or failed (see "
        "the table); fix the config's fit first";
    return;
  }
  CountNearBest(report, candidates);
  report->recommended = Choose(*report, candidates);
  WarnAbout(report, candidates, !stable.empty());
  const VariantResult& chosen = report->variants[report->recommended];
  report->verdict = StringPrintf(
      "recommended: %s (near-best on %d of 3 scores; held-out jump-down %.2f %% (%.3g Hz), "
      "jump-up %.2f %% (%.3g Hz), upper-branch amplitude %.1f %%; BIC %.6g)",
      chosen.variant.Name().c_str(), chosen.near_best, chosen.jump_down_percent,
      chosen.jump_down_hz, chosen.jump_up_percent, chosen.jump_up_hz, chosen.upper_branch_percent,
      chosen.bic);
  for (const std::string& warning : report->warnings) report->verdict += "; WARNING: " + warning;
}

IdentifyConfig WithVariant(const IdentifyConfig& config, const ModelVariant& variant) {
  IdentifyConfig copy = config;
  copy.identification.solve.residual.form = variant.form;
  // A member's own terms start at 0 (the chapter's guess of the entry is in
  // another unit).
  const bool own[] = {variant.form.cubic_damping(), variant.form.quintic_stiffness()};
  for (int index : {kMu3, kAlpha5}) {
    if (!own[index == kMu3 ? 0 : 1]) continue;
    copy.initial_guess[index] = 0.0;
    copy.identification.initial[index] = 0.0;
  }
  ApplyChoice(variant.delta, kDelta, &copy);
  ApplyChoice(variant.mu2, kMu2, &copy);
  ApplyChoice(variant.omega, kNaturalFrequency, &copy);
  return copy;
}

std::string ModelVariant::Name() const {
  return std::string(ParameterName(form, kDelta)) + " " + delta.text + ", " +
         ParameterName(form, kMu2) + " " + mu2.text + ", w " +
         (omega.value ? omega.text + " Hz" : omega.text);
}

int ModelVariant::FreeParameters(const IdentifyConfig& config) const {
  std::array<bool, kNumParameters> fixed = config.identification.fixed;
  fixed[kDelta] = delta.value.has_value();
  fixed[kMu2] = mu2.value.has_value();
  fixed[kNaturalFrequency] = omega.value.has_value();
  return static_cast<int>(std::count(fixed.begin(), fixed.end(), false));
}

void AddPredictionIntervals(VariantResult* result) {
  std::vector<std::vector<HeldOutPrediction>*> levels;
  for (CrossValidationFold& fold : result->folds) levels.push_back(&fold.predictions);
  const PredictionCoverage coverage = AddPredictionIntervals(levels);
  result->jump_down_coverage = coverage.jump_down;
  result->jump_up_coverage = coverage.jump_up;
  result->upper_branch_coverage = coverage.upper_branch;
}

void PredictionErrors::Add(const PredictionErrors& other) {
  const auto append = [](std::vector<double>* to, const std::vector<double>& from) {
    to->insert(to->end(), from.begin(), from.end());
  };
  append(&jump_down_percent, other.jump_down_percent);
  append(&jump_down_hz, other.jump_down_hz);
  append(&jump_up_percent, other.jump_up_percent);
  append(&jump_up_hz, other.jump_up_hz);
  append(&upper_branch_percent, other.upper_branch_percent);
  append(&relative_rms, other.relative_rms);
}

ModelSelectionReport RunModelSelection(const IdentifyConfig& config, int threads) {
  ModelSelectionReport report;
  report.config_path = config.config_path;
  report.selection = config.model_selection.value_or(ModelSelectionConfig());
  std::string message;
  if (!report.selection.IsValid(&message)) {
    throw InputError(config.config_path, 0, "model_selection", message);
  }
  if (threads > 0) report.selection.threads = threads;
  // The config's own run, resolved once: checks it and labels the sweeps.
  const ResolvedRun base = ResolveRun(config);
  const Plan plan = MakePlan(config, report.selection, base.sweeps);
  report.pool_levels = plan.levels;
  const Averaging averaging = config.identification.solve.residual.form.averaging;
  if (averaging == Averaging::kSecondOrder &&
      (report.selection.backbone != std::vector<BackboneTerm>{BackboneTerm::kInertia} ||
       report.selection.damping != std::vector<DampingTerm>{DampingTerm::kQuadratic})) {
    throw InputError(config.config_path, 0, "model_selection",
                     "the family's terms (backbone: quintic, damping: cubic) are first order "
                     "only; remove them, or model: {averaging: second_order}");
  }
  const std::vector<ModelVariant> variants = ModelVariants(report.selection, averaging);
  const std::vector<TaskResult> tasks =
      RunTasks(config, variants, base.sweeps, plan, report.selection.threads);
  const int sets = static_cast<int>(plan.training.size());
  for (std::size_t v = 0; v < variants.size(); ++v) {
    report.variants.push_back(
        Assemble(config, variants[v], plan, tasks, static_cast<int>(v) * sets));
  }
  RecommendVariant(&report);
  return report;
}

}  // namespace dwellfit
