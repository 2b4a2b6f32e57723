// Model selection: the config's fit repeated for every model variant of its
// `model_selection:` block (delta, mu2 and w each free or held at a value),
// each scored by its fitted cost, AIC and BIC, and by leave-one-level-out
// cross-validation over a pool of sweeps, each fit made as `identify` makes
// it (ResolveRun, FitRun). docs/model-selection.md states the errors, the
// stability test, the rule and the intervals, with the beam's numbers.
//
// Likelihood: the last stage's residuals taken as independent Gaussian with
// one variance estimated from the fit, sigma^2 = RSS / n, RSS = 2 x the data
// cost (penalties left out):
//   -2 ln L = n (ln(2 pi RSS / n) + 1),
//   AIC = -2 ln L + 2 k,   BIC = -2 ln L + k ln n,
// n the fitted dwells, k the free model parameters (the variance, common to
// every variant, is not counted). Dwells of a slow sweep are correlated, so
// on measured data these criteria overstate the evidence for the larger
// model; cross-validation does not rely on that assumption.
//
// Effective nonlinearity alpha_e = alpha - (2/3) delta Omega_ref^2 (Omega_ref
// the config's reference, else the fits' median w): with delta free, alpha
// and delta trade off along a valley and only alpha_e is determined.
//
// Fits run on `threads` threads; the report does not depend on their count.
#ifndef DWELLFIT_ESTIMATOR_STUDIES_MODEL_SELECTION_H_
#define DWELLFIT_ESTIMATOR_STUDIES_MODEL_SELECTION_H_

#include <string>
#include <vector>

#include "dwellfit/config/identify_config.h"
#include "dwellfit/estimator/analysis/prediction_intervals.h"
#include "dwellfit/estimator/fit/staged_solve.h"
#include "dwellfit/residuals/model/model_parameters.h"

namespace dwellfit {

// A variant is unstable when, over its usable fits, w's relative range
// (max - min) / |median| exceeds kUnstableFrequencyRange or eta_e's, mu1's or
// alpha_e's exceeds kUnstableScaleRange.
inline constexpr double kUnstableFrequencyRange = 0.10;
inline constexpr double kUnstableScaleRange = 1.0;
// The amplitude score's tolerance: this share of the best score, at least
// kAmplitudeToleranceFloorPercent points.
inline constexpr double kAmplitudeToleranceShare = 0.25;
inline constexpr double kAmplitudeToleranceFloorPercent = 1.0;
// "Much worse on amplitudes": more than this multiple of the best score (and
// beyond the tolerance).
inline constexpr double kMuchWorseFactor = 2.0;

struct ModelVariant {
  // Entries kDelta and kMu2: the chapter's delta and mu2, or (a member of the
  // family, `form`) alpha5 and mu3, which are always free.
  ParameterChoice delta, mu2, omega;
  ModelForm form;
  // "delta free, mu2 0, w free"; a member's "alpha5 free, mu3 free, w free".
  std::string Name() const;
  int FreeParameters(const IdentifyConfig& config) const;
};

// Errors of predicted sweeps, pooled over the sweeps scored.
struct PredictionErrors {
  std::vector<double> jump_down_percent;  // one per measured jump-down
  std::vector<double> jump_down_hz;       // the same in Hz
  std::vector<double> jump_up_percent;
  std::vector<double> jump_up_hz;
  std::vector<double> upper_branch_percent;  // |e|, one per up-sweep with a jump-down
  std::vector<double> relative_rms;          // one per sweep
  void Add(const PredictionErrors& other);
};

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
  std::string held_out_level;                  // sweep id
  int fit = 0;                                 // index into VariantResult::fits
  PredictionErrors errors;                     // of the level's pool sweeps
  std::vector<HeldOutPrediction> predictions;  // of the level's pool sweeps
};

// A free parameter's spread over a variant's usable fits (or alpha_e's).
struct ParameterSpread {
  std::string name;  // "eta_e", ..., "w [Hz]" (values in Hz), "alpha_e"
  ParameterIndex index = kEtaE;
  double min = 0.0, median = 0.0, max = 0.0;  // physical units (w in Hz)
  double relative_range = 0.0;                // (max - min) / |median|; inf when median is 0
};

// The training set of leave-one-level-out fold `level` under `training:
// config`: the config's fit sweeps, the held-out level's own replaced by the
// nearest level of `levels` (data order) that is not fitted, the lower on a
// tie. Throws InputError when every level is fitted.
std::vector<SweepSelection> ConfigTraining(const IdentifyConfig& config,
                                           const std::vector<std::string>& levels, int level);

struct VariantResult {
  ModelVariant variant;
  int free_parameters = 0;
  // fits[0] is the config's own fit (its fit sweeps); the rest are the
  // cross-validation's other training sets.
  std::vector<VariantFit> fits;
  double aic = 0.0, bic = 0.0;  // of fits[0]; NaN unless its solution is usable
  PredictionErrors validation;  // the config's validate sweeps, from fits[0]
  std::vector<CrossValidationFold> folds;
  PredictionErrors cross_validation;    // every fold's held-out sweeps
  int fits_not_converged = 0;           // over `fits`
  int fits_failed = 0;                  // not usable (failed, invalid, or could not start)
  bool eligible = false;                // every fit converged
  std::vector<ParameterSpread> spread;  // every free parameter, over the usable fits
  bool unstable = false;                // see kUnstableFrequencyRange
  std::string stability;                // why unstable, in words; empty when stable
  // The scores of the rule (NaN when nothing was scored): medians over the
  // held-out jumps (Hz, and % for the tables) and upper-branch amplitudes.
  double jump_down_hz = 0.0, jump_down_percent = 0.0;
  double jump_up_hz = 0.0, jump_up_percent = 0.0;
  double upper_branch_percent = 0.0;
  int near_best = 0;  // scores on which it is near-best (rule step 2); -1: not a candidate
  IntervalCoverage jump_down_coverage, jump_up_coverage, upper_branch_coverage;  // of the folds
};

struct ModelSelectionReport {
  std::string config_path;
  ModelSelectionConfig selection;
  std::vector<std::string> pool_levels;  // in data order
  std::vector<VariantResult> variants;
  int recommended = -1;                      // index into variants; -1: none qualifies
  std::string rule;                          // the rule applied, in words
  std::string verdict;                       // why the recommended variant, or why none
  double jump_tolerance_hz = 0.0;            // the rule's: the resonance's half-power width
  double amplitude_tolerance_percent = 0.0;  // the rule's, in percentage points
  std::vector<std::string> warnings;         // about the recommendation, also in the verdict
};

// Runs the study of config.model_selection (its defaults when unset);
// `threads` > 0 replaces its thread count. Throws InputError naming the config
// for a pool sweep not in the data, a pool of one level, or a config whose own
// fit cannot be set up (ResolveRun).
ModelSelectionReport RunModelSelection(const IdentifyConfig& config, int threads = 0);

// model_selection.csv: one row per variant (columns documented in
// docs/model-selection.md); model_selection.md: the same as tables, with the
// per-level cross-validation errors and the recommendation.
std::string ModelSelectionCsv(const ModelSelectionReport& report);
std::string ModelSelectionMarkdown(const ModelSelectionReport& report);
// model_selection_levels.csv: one row per held-out prediction of every
// variant (level, sweep, quantity, measured, predicted, error in the unit
// -- Hz, or the data's for amplitudes -- and in %, the 95 % interval's
// half-width and its two parts, inside); no rows without cross-validation.
std::string ModelSelectionLevelsCsv(const ModelSelectionReport& report);

// The config in effect (absolute paths) with the recommended variant applied
// (WithVariant), ready for `identify --config`, under a header saying where
// it came from. Empty when nothing is recommended.
std::string RecommendedConfigYaml(const IdentifyConfig& config, const ModelSelectionReport& report);

// The config with `variant` applied (free, or fixed at its value).
IdentifyConfig WithVariant(const IdentifyConfig& config, const ModelVariant& variant);

// Applies the rule to report->variants: sets recommended, near_best, the
// tolerances, rule, verdict and warnings. Exposed for tests.
void RecommendVariant(ModelSelectionReport* report);

// Fills every fold's prediction intervals and the variant's coverage.
// Exposed for tests.
void AddPredictionIntervals(VariantResult* result);

}  // namespace dwellfit

#endif  // DWELLFIT_ESTIMATOR_STUDIES_MODEL_SELECTION_H_
