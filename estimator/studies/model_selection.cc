#include "dwellfit/estimator/studies/model_selection.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <exception>
#include <limits>
#include <map>
#include <set>
#include <thread>
#include <utility>

#include "dwellfit/estimator/analysis/sweep_prediction.h"
#include "dwellfit/estimator/common/input_error.h"
#include "dwellfit/estimator/common/string_printf.h"
#include "dwellfit/estimator/run/resolved_run.h"

namespace dwellfit {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

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
  IdentifyConfig copy = config;
  ApplyChoice(variant.delta, kDelta, &copy);
  ApplyChoice(variant.mu2, kMu2, &copy);
  ApplyChoice(variant.omega, kNaturalFrequency, &copy);
  copy.fit_sweeps = fit;
  copy.validate_sweeps.clear();
  copy.identification.solve.solver.num_threads = 1;
  copy.multi_start.threads = 1;
  return copy;
}

bool SelectedByAny(const Sweep& sweep, const std::vector<SweepSelection>& selections) {
  return std::any_of(selections.begin(), selections.end(),
                     [&](const SweepSelection& s) { return s.Selects(sweep); });
}

// The errors of one held-out sweep under `parameters`; with no usable fit,
// every measured jump counts 100 % and the amplitude error is left out.
PredictionErrors SweepErrors(const Sweep& sweep, const ParameterVector& parameters, bool usable) {
  PredictionErrors errors;
  const bool frequency = sweep.kind == SweepKind::kFrequency;
  if (!usable) {
    for (const JumpBracket& jump : sweep.jumps) {
      if (!frequency) continue;
      (jump.kind == JumpKind::kJumpDown ? errors.jump_down_percent : errors.jump_up_percent)
          .push_back(100.0);
    }
    return errors;
  }
  const SweepPrediction prediction = PredictSweep(parameters, sweep, /*fitted=*/false);
  errors.relative_rms.push_back(prediction.relative_rms_error);
  if (!frequency) return errors;
  for (const PredictedJump& jump : prediction.jumps) {
    if (!jump.measured) continue;
    const double measured = jump.bracket.centre();
    const double error = jump.exists ? 100.0 * std::abs(jump.control - measured) / measured : 100.0;
    (jump.kind == JumpKind::kJumpDown ? errors.jump_down_percent : errors.jump_up_percent)
        .push_back(error);
  }
  return errors;
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
  // Per training set: the sweeps (names) it predicts.
  std::vector<std::vector<std::string>> predicts;
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

// The pool's sweeps (checked to exist) and their levels in data order.
std::vector<const Sweep*> PoolSweeps(const IdentifyConfig& config,
                                     const std::vector<SweepSelection>& pool,
                                     const std::vector<Sweep>& sweeps,
                                     std::vector<std::string>* levels) {
  for (const SweepSelection& selection : pool) {
    if (std::none_of(sweeps.begin(), sweeps.end(),
                     [&](const Sweep& sweep) { return selection.Selects(sweep); })) {
      throw InputError(config.config_path, 0, "model_selection.pool",
                       "sweep '" + selection.Name() + "' is not in the data");
    }
  }
  std::vector<const Sweep*> selected;
  for (const Sweep& sweep : sweeps) {
    if (!SelectedByAny(sweep, pool)) continue;
    selected.push_back(&sweep);
    if (std::find(levels->begin(), levels->end(), sweep.id) == levels->end()) {
      levels->push_back(sweep.id);
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
  for (const Sweep& sweep : sweeps) {
    if (SelectedByAny(sweep, config.validate_sweeps)) plan.validation.push_back(sweep.Name());
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
  std::map<std::string, PredictionErrors> predicted;
  std::exception_ptr error;  // an InputError of the config's own fit
};

// A fit the solver calls usable, but whose parameters are not finite or
// not physical (eta_e or w not positive), is counted as failed, with the
// reason. (A fit that ends without an enforced fold or dominated by the
// penalties already has FitStatus::kFailure.)
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

TaskResult RunTask(const IdentifyConfig& config, const ModelVariant& variant,
                   const std::vector<Sweep>& sweeps, const Plan& plan, int set) {
  TaskResult task;
  task.fit.fitted_sweeps.clear();
  for (const SweepSelection& s : plan.training[set]) task.fit.fitted_sweeps.push_back(s.Name());
  ResolvedRun run;
  try {
    run = ResolveRun(VariantConfig(config, variant, plan.training[set]), sweeps);
  } catch (const InputError& error) {
    if (set == 0) task.error = std::current_exception();
    task.fit.status = FitStatus::kFailure;
    task.fit.message = std::string("could not start: ") + error.what();
    for (const Sweep& sweep : sweeps) {
      const auto& names = plan.predicts[set];
      if (std::find(names.begin(), names.end(), sweep.Name()) == names.end()) continue;
      task.predicted[sweep.Name()] = SweepErrors(sweep, {}, false);
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
  for (const Sweep& sweep : run.sweeps) {
    const auto& names = plan.predicts[set];
    if (std::find(names.begin(), names.end(), sweep.Name()) == names.end()) continue;
    task.predicted[sweep.Name()] = SweepErrors(sweep, result.parameters, result.IsSolutionUsable());
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
  std::atomic<int> next{0};
  auto work = [&]() {
    for (int i = next++; i < count; i = next++) {
      results[i] = RunTask(config, variants[i / sets], sweeps, plan, i % sets);
    }
  };
  std::vector<std::thread> pool;
  for (int t = 1; t < std::min(threads, count); ++t) pool.emplace_back(work);
  work();
  for (std::thread& thread : pool) thread.join();
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
    result.validation.Add(tasks[first_task].predicted.at(name));
  }
  for (std::size_t level = 0; level < plan.fold_training.size(); ++level) {
    CrossValidationFold fold;
    fold.held_out_level = plan.levels[level];
    fold.fit = plan.fold_training[level];
    for (const std::string& name : plan.fold_sweeps[level]) {
      fold.errors.Add(tasks[first_task + fold.fit].predicted.at(name));
    }
    result.cross_validation.Add(fold.errors);
    result.folds.push_back(fold);
  }
  return result;
}

// What the rule ranks by (lower is better): the median held-out jump-down
// error of the cross-validation when it scored any jump-down, else of the
// validate sweeps, else BIC. Which jumps are scored does not depend on the
// variant (a missing fold counts 100 %), so every variant ranks by the same.
enum class Ranking { kCrossValidated, kValidation, kBic };

Ranking RankingOf(const ModelSelectionReport& report) {
  if (report.variants.empty()) return Ranking::kBic;
  const VariantResult& any = report.variants[0];
  if (!any.cross_validation.jump_down_percent.empty()) return Ranking::kCrossValidated;
  if (!any.validation.jump_down_percent.empty()) return Ranking::kValidation;
  return Ranking::kBic;
}

double Score(Ranking ranking, const VariantResult& result) {
  switch (ranking) {
    case Ranking::kCrossValidated:
      return MedianOf(result.cross_validation.jump_down_percent);
    case Ranking::kValidation:
      return MedianOf(result.validation.jump_down_percent);
    case Ranking::kBic:
      return result.bic;
  }
  return kNaN;
}

void Recommend(ModelSelectionReport* report) {
  const Ranking ranking = RankingOf(*report);
  const double tolerance = ranking == Ranking::kBic ? 0.0 : kTieTolerancePercent;
  report->rule =
      std::string("among the variants whose every fit converged, the lowest ") +
      (ranking == Ranking::kCrossValidated
           ? "median cross-validated (leave-one-level-out) held-out jump-down error"
       : ranking == Ranking::kValidation
           ? "median jump-down error over the config's validate sweeps"
           : "BIC (no held-out jump-down to score)") +
      (ranking == Ranking::kBic
           ? std::string()
           : StringPrintf("; errors within %.2g percentage points tie, and the lowest BIC "
                          "among them wins",
                          kTieTolerancePercent));
  double best = kNaN;
  for (const VariantResult& v : report->variants) {
    const double score = Score(ranking, v);
    if (v.eligible && std::isfinite(score) && !(score >= best)) best = score;
  }
  for (int i = 0; i < static_cast<int>(report->variants.size()); ++i) {
    const VariantResult& v = report->variants[i];
    const double score = Score(ranking, v);
    if (!v.eligible || !std::isfinite(score) || score > best + tolerance) continue;
    if (report->recommended < 0 || v.bic < report->variants[report->recommended].bic) {
      report->recommended = i;
    }
  }
  if (report->recommended < 0) {
    report->verdict =
        "no variant qualifies: every variant has a fit that did not converge or failed (see "
        "the table); fix the config's fit first";
    return;
  }
  const VariantResult& chosen = report->variants[report->recommended];
  report->verdict = StringPrintf("recommended: %s (score %.4g, BIC %.6g)",
                                 chosen.variant.Name().c_str(), Score(ranking, chosen), chosen.bic);
}

}  // namespace

std::string ModelVariant::Name() const {
  return "delta " + delta.text + ", mu2 " + mu2.text + ", w " +
         (omega.value ? omega.text + " Hz" : omega.text);
}

int ModelVariant::FreeParameters(const IdentifyConfig& config) const {
  std::array<bool, kNumParameters> fixed = config.identification.fixed;
  fixed[kDelta] = delta.value.has_value();
  fixed[kMu2] = mu2.value.has_value();
  fixed[kNaturalFrequency] = omega.value.has_value();
  return static_cast<int>(std::count(fixed.begin(), fixed.end(), false));
}

std::vector<ModelVariant> ModelVariants(const ModelSelectionConfig& selection) {
  std::vector<ModelVariant> variants;
  for (const ParameterChoice& delta : selection.delta) {
    for (const ParameterChoice& mu2 : selection.mu2) {
      for (const ParameterChoice& omega : selection.omega) {
        variants.push_back(ModelVariant{delta, mu2, omega});
      }
    }
  }
  return variants;
}

void PredictionErrors::Add(const PredictionErrors& other) {
  jump_down_percent.insert(jump_down_percent.end(), other.jump_down_percent.begin(),
                           other.jump_down_percent.end());
  jump_up_percent.insert(jump_up_percent.end(), other.jump_up_percent.begin(),
                         other.jump_up_percent.end());
  relative_rms.insert(relative_rms.end(), other.relative_rms.begin(), other.relative_rms.end());
}

double MedianOf(std::vector<double> values) {
  if (values.empty()) return kNaN;
  std::sort(values.begin(), values.end());
  const std::size_t n = values.size();
  return n % 2 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
}

ModelSelectionReport RunModelSelection(const IdentifyConfig& config, int threads) {
  ModelSelectionReport report;
  report.config_path = config.config_path;
  report.selection = config.model_selection.value_or(ModelSelectionConfig::Defaults());
  std::string message;
  if (!report.selection.IsValid(&message)) {
    throw InputError(config.config_path, 0, "model_selection", message);
  }
  if (threads > 0) report.selection.threads = threads;
  // The config's own run, resolved once: checks it and labels the sweeps.
  const ResolvedRun base = ResolveRun(config);
  const Plan plan = MakePlan(config, report.selection, base.sweeps);
  report.pool_levels = plan.levels;
  const std::vector<ModelVariant> variants = ModelVariants(report.selection);
  const std::vector<TaskResult> tasks =
      RunTasks(config, variants, base.sweeps, plan, report.selection.threads);
  const int sets = static_cast<int>(plan.training.size());
  for (std::size_t v = 0; v < variants.size(); ++v) {
    report.variants.push_back(
        Assemble(config, variants[v], plan, tasks, static_cast<int>(v) * sets));
  }
  Recommend(&report);
  return report;
}

}  // namespace dwellfit
