// The `model_selection:` block of a config (config/README.md): which model
// variants to compare, how to cross-validate them, and over which sweeps; run
// by `select_model` (estimator/studies/model_selection.h).
#ifndef DWELLFIT_CONFIG_MODEL_SELECTION_CONFIG_H_
#define DWELLFIT_CONFIG_MODEL_SELECTION_CONFIG_H_

#include <optional>
#include <string>
#include <vector>

#include "dwellfit/config/config_source.h"
#include "dwellfit/config/strict_yaml.h"
#include "dwellfit/config/sweep_selection.h"
#include "dwellfit/estimator/fit/initial_guess.h"
#include "dwellfit/residuals/model/model_form.h"
#include "dwellfit/residuals/model/model_parameters.h"

namespace dwellfit {

// One choice for a parameter: free, or held at `value` (physical units,
// omega in rad/s).
struct ParameterChoice {
  std::optional<double> value;  // unset: free
  // "free", or the value as the config wrote it (omega in Hz): for names.
  std::string text;
};

enum class CrossValidationScheme {
  kNone,              // only the config's own fit and its validation sweeps
  kLeaveOneLevelOut,  // every level (sweep id) of the pool predicted by a fit without it
};
const char* CrossValidationSchemeName(CrossValidationScheme scheme);

// Which levels a leave-one-level-out fold fits.
enum class CrossValidationTraining {
  // The config's fitted levels; a held-out fitted level is replaced by the
  // nearest pool level (in data order) that is not fitted. Each level is then
  // predicted by the configured estimator (same number of levels, same
  // penalties) trained without it; folds with the same training levels share
  // one fit.
  kConfig,
  // Every other level of the pool (the textbook scheme).
  kAll,
};
const char* CrossValidationTrainingName(CrossValidationTraining training);

struct ModelSelectionConfig {
  // The members of the family compared (model_form.h): every combination of
  // these terms, backbone slowest; the chapter's alone by default.
  std::vector<BackboneTerm> backbone = {BackboneTerm::kInertia};
  std::vector<DampingTerm> damping = {DampingTerm::kQuadratic};
  // The variants of each member are every combination of these choices
  // (delta, then mu2, then omega); each list non-empty, no choice twice.
  // delta's and mu2's apply to the members that have them; a member's own
  // term (alpha5, mu3) is free.
  std::vector<ParameterChoice> delta = {{std::nullopt, "free"}, {0.0, "0"}};
  std::vector<ParameterChoice> mu2 = {{std::nullopt, "free"}, {0.0, "0"}};
  std::vector<ParameterChoice> omega = {{std::nullopt, "free"}};
  CrossValidationScheme scheme = CrossValidationScheme::kLeaveOneLevelOut;
  CrossValidationTraining training = CrossValidationTraining::kConfig;
  // Sweeps whose levels form the cross-validation pool; empty: the config's
  // fit and validate sweeps.
  std::vector<SweepSelection> pool;
  // Fits run on this many threads at once (>= 1); results do not depend on it.
  int threads = 2;

  bool IsValid(std::string* error) const;
};

// Reads the block at `value` (strict keys; errors name the file, line and
// key). `initial_guess` is the config's, for the `initial` choices.
ModelSelectionConfig ReadModelSelectionConfig(const ConfigValue& value, const ConfigSource& source,
                                              const KnownParameters& initial_guess);

}  // namespace dwellfit

#endif  // DWELLFIT_CONFIG_MODEL_SELECTION_CONFIG_H_
