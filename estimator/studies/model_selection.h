// Model selection: the config's fit repeated for every model variant of its
// `model_selection:` block (delta, mu2 and w each free or held at a value),
// each scored by
//   - its fitted cost, AIC and BIC on the config's fitted sweeps, and
//   - cross-validation over the levels (sweep ids) of a pool of sweeps:
//     every level predicted by a fit that did not see it.
// Every fit is the one pipeline of `identify` (ResolveRun, FitRun) on a copy
// of the config with the variant's fixed parameters and the fold's sweeps.
//
// Likelihood: the residuals of the last stage (vertical: a_i - a_model, or
// ln(a_i/a_model) with `residual.error: relative`, over sigma when given)
// taken as independent Gaussian with one variance estimated from the fit,
// sigma^2 = RSS / n, RSS = 2 x the data cost (penalties left out):
//   -2 ln L = n (ln(2 pi RSS / n) + 1),
//   AIC = -2 ln L + 2 k,   BIC = -2 ln L + k ln n,
// n the fitted dwells, k the free model parameters (the variance, common to
// every variant, is not counted). Dwells of a slow continuous sweep are
// correlated, so on measured data these criteria overstate the evidence
// for the larger model; cross-validation does not rely on that assumption.
//
// Prediction errors of a held-out frequency sweep: each measured jump's
// error |f_model - f_measured| / f_measured in percent (f_measured the
// bracket's centre; a fold the model lacks counts 100 %), jump-downs and
// jump-ups apart (PredictJumps), and the sweep's relative RMS amplitude error
// (PredictSweep).
//
// Recommended variant: among the variants whose every fit converged, the
// lowest median held-out jump-down error (cross-validated; without
// cross-validation: over the config's validate sweeps; without those: the
// lowest BIC); errors within kTieTolerancePercent of the lowest tie, and
// the lowest BIC among the tied wins. None when no variant qualifies.
//
// Fits run on `threads` threads, each fit's residuals on one; the report
// does not depend on the thread count.
#ifndef DWELLFIT_ESTIMATOR_STUDIES_MODEL_SELECTION_H_
#define DWELLFIT_ESTIMATOR_STUDIES_MODEL_SELECTION_H_

#include <string>
#include <vector>

#include "dwellfit/config/identify_config.h"
#include "dwellfit/estimator/fit/staged_solve.h"
#include "dwellfit/residuals/model/model_parameters.h"

namespace dwellfit {

// Percentage points within which two median errors count as a tie.
inline constexpr double kTieTolerancePercent = 0.05;

struct ModelVariant {
  ParameterChoice delta, mu2, omega;
  std::string Name() const;  // "delta free, mu2 0, w free"
  int FreeParameters(const IdentifyConfig& config) const;
};

// Every combination of the block's choices, delta slowest, omega fastest.
std::vector<ModelVariant> ModelVariants(const ModelSelectionConfig& selection);

// Errors of predicted sweeps (see above), pooled over the sweeps scored.
struct PredictionErrors {
  std::vector<double> jump_down_percent;  // one per measured jump-down
  std::vector<double> jump_up_percent;
  std::vector<double> relative_rms;  // one per sweep
  void Add(const PredictionErrors& other);
};
// Median of `values`; NaN when empty.
double MedianOf(std::vector<double> values);

// One fit of a variant on a set of sweeps.
struct VariantFit {
  std::vector<std::string> fitted_sweeps;  // the selections, as a config spells them
  FitStatus status = FitStatus::kInvalidInput;
  std::string message;
  double final_cost = 0.0;  // with penalties
  double data_cost = 0.0;   // the dwells alone: 1/2 RSS
  int dwells = 0;
  int iterations = 0;
  ParameterVector parameters{};
};

struct CrossValidationFold {
  std::string held_out_level;  // sweep id
  int fit = 0;                 // index into VariantResult::fits
  PredictionErrors errors;     // of the level's pool sweeps
};

struct VariantResult {
  ModelVariant variant;
  int free_parameters = 0;
  // fits[0] is the config's own fit (its fit sweeps); the rest are the
  // cross-validation's other training sets.
  std::vector<VariantFit> fits;
  double aic = 0.0, bic = 0.0;  // of fits[0]; NaN unless its solution is usable
  PredictionErrors validation;  // the config's validate sweeps, from fits[0]
  std::vector<CrossValidationFold> folds;
  PredictionErrors cross_validation;  // every fold's held-out sweeps
  int fits_not_converged = 0;         // over `fits`
  int fits_failed = 0;                // not usable (failed, invalid, or could not start)
  bool eligible = false;              // every fit converged
};

struct ModelSelectionReport {
  std::string config_path;
  ModelSelectionConfig selection;
  std::vector<std::string> pool_levels;  // in data order
  std::vector<VariantResult> variants;
  int recommended = -1;  // index into variants; -1: none qualifies
  std::string rule;      // the rule applied, in words
  std::string verdict;   // why the recommended variant, or why none
};

// Runs the study of config.model_selection (its defaults when unset).
// `threads` > 0 replaces the block's thread count. Throws InputError naming
// the config for a pool sweep that is not in the data, a pool of fewer than
// two levels, or a config whose own fit cannot be set up (ResolveRun).
ModelSelectionReport RunModelSelection(const IdentifyConfig& config, int threads = 0);

// model_selection.csv: one row per variant (columns documented in
// docs/model-selection.md); model_selection.md: the same as tables, with the
// per-level cross-validation errors and the recommendation.
std::string ModelSelectionCsv(const ModelSelectionReport& report);
std::string ModelSelectionMarkdown(const ModelSelectionReport& report);

}  // namespace dwellfit

#endif  // DWELLFIT_ESTIMATOR_STUDIES_MODEL_SELECTION_H_
