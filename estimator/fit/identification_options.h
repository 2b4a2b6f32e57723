// Options of one identification run, one struct per component; each
// IsValid message names the field (as the config spells it) and its bound.
#ifndef DWELLFIT_ESTIMATOR_FIT_IDENTIFICATION_OPTIONS_H_
#define DWELLFIT_ESTIMATOR_FIT_IDENTIFICATION_OPTIONS_H_

#include <array>
#include <string>
#include <vector>

#include "dwellfit/residuals/functors/error_measure.h"
#include "dwellfit/residuals/model/model_form.h"
#include "dwellfit/residuals/model/model_parameters.h"

namespace dwellfit {

// Which residual a fit stage minimises.
enum class ResidualKind {
  kAlgebraic,  // (G(a_i) - a_base_i^2) / a_base_i^2, eq. (3.11): smooth, branch-free
  kVertical,   // a_i - a_model(Omega_i, a_base_i) on the point's stable branch
  // The chapter's earlier methods (docs/method-comparison.md):
  kPhaseLag,  // eqs. (3.9)-(3.10) from the measured phase: two residuals per dwell
  kAllRoots,  // a_i - the nearest stable root of all six of (3.11); jumps through the roots
};
const char* ResidualKindName(ResidualKind kind);
bool ResidualKindFromName(const std::string& name, ResidualKind* kind);

const char* ErrorMeasureName(ErrorMeasure measure);
bool ErrorMeasureFromName(const std::string& name, ErrorMeasure* measure);

struct ResidualOptions {
  ErrorMeasure error = ErrorMeasure::kAbsolute;
  bool use_point_sigma = true;  // divide by a point's `sigma` where given
  // f of the relative error ln(a_i + f) - ln(a_model + f), in the data's
  // amplitude unit: the measurement's noise floor (0: purely relative).
  double amplitude_floor = 0.0;
  // p: the measured amplitude is Omega^p times the model's displacement
  // amplitude (measured_quantity.h). The absolute error of a dwell without
  // a used sigma is weighted by Omega^p, so that it stays the error of the
  // measured quantity: Omega^p (a_i - a_model) = y_i - y_model.
  int response_power = 0;
  // The response model every residual, penalty and prediction evaluates
  // (config `model: {averaging: ...}`; model_form.h).
  ModelForm form;
  bool IsValid(std::string* error) const;
};

struct SolverSettings {
  int max_iterations = 200;
  // Convergence tests of ceres::Solver::Options. The gradient and parameter
  // tests are off in effect (parameters span nine decades); a relative cost
  // change of 1e-8 is far below the noise's 1/N.
  double function_tolerance = 1e-8;
  // The same for an algebraic stage whose end only starts a later stage
  // (docs/performance.md).
  double start_function_tolerance = 1e-5;
  double gradient_tolerance = 1e-30;
  double parameter_tolerance = 1e-20;
  // Threads that evaluate the residual blocks, 0 for one per processor
  // available. Results do not depend on it.
  int num_threads = 0;
  // ceres::Solver::Options::use_nonmonotonic_steps: faster along the narrow
  // valleys of measured data with penalties.
  bool nonmonotonic_steps = false;
  // Finish a vertical or all-roots solve that creeps with a quasi-Newton
  // polish (valley_polish.h).
  bool valley_polish = true;
  bool IsValid(std::string* error) const;
};

// Sets the iteration limit and convergence tests of `settings` on
// ceres::Solver::Options or ceres::GradientProblemSolver::Options.
template <typename CeresOptions>
void SetConvergenceTests(const SolverSettings& settings, CeresOptions* options) {
  options->max_num_iterations = settings.max_iterations;
  options->function_tolerance = settings.function_tolerance;
  options->gradient_tolerance = settings.gradient_tolerance;
  options->parameter_tolerance = settings.parameter_tolerance;
}

// The jumps a bifurcation-range penalty can enforce (jump-up: the lower
// branch ends; jump-down: the upper one).
enum class JumpTarget {
  kFrequencyJumpUp,
  kFrequencyJumpDown,
  kAmplitudeJumpUp,
  kAmplitudeJumpDown,
};
const char* JumpTargetName(JumpTarget target);  // "frequency_jump_down", ...
bool JumpTargetFromName(const std::string& name, JumpTarget* target);

// Eq. (3.17): each enforced measured jump adds the cost
//   weight s^2 ((c_model - c_centre) / c_halfwidth)^exponent
// (s^2: the data's mean squared residual where the fit stage starts)
// where c is the jump's control (Omega [rad/s] or a_base) and c_model the
// model's fold for that bracket.
struct BifurcationRangeOptions {
  bool enabled = false;
  int exponent = 10;  // n of eq. (3.17): even, >= 2
  double weight = 1.0;
  // As the chapter.
  std::vector<JumpTarget> enforce = {JumpTarget::kFrequencyJumpDown, JumpTarget::kAmplitudeJumpUp};
  bool IsValid(std::string* error) const;
};

// Eq. (3.19): each dwell measured on the upper branch adds the cost
//   weight s^2 exp(Lambda (a_fold - a_i)),
// a_fold the amplitude where the upper branch ends at the dwell's frequency
// (mirror for the lower branch: weight exp(Lambda (a_i - a_fold))), with
// Lambda = lambda / (largest measured amplitude of the sweep).
struct BranchStabilityOptions {
  bool enabled = false;
  double lambda = 50.0;  // dimensionless: Lambda times the sweep's amplitude scale
  double weight = 1.0;
  bool IsValid(std::string* error) const;
};

struct PenaltyOptions {
  BifurcationRangeOptions bifurcation_range;
  BranchStabilityOptions branch_stability;
  bool IsValid(std::string* error) const;
};

// The stages of a staged solve (staged_solve.h) and how each is solved.
struct StagedSolveOptions {
  std::vector<ResidualKind> stages = {ResidualKind::kAlgebraic, ResidualKind::kVertical};
  ResidualOptions residual;
  PenaltyOptions penalties;  // added to every vertical-error stage
  SolverSettings solver;
  // Run the start stage before a branch-labelled first stage
  // (staged_solve.h). false: the first stage starts at the given start (for
  // studying a residual's own basin).
  bool algebraic_start_candidate = true;
  bool IsValid(std::string* error) const;
};

// The single-dataset identification (Identify, identification.h).
struct IdentificationOptions {
  // Starting point, ParameterIndex order, physical units (omega in rad/s).
  ParameterVector initial = {0, 0, 0, 0, 0, 0};
  // Parameters held at their initial value.
  std::array<bool, kNumParameters> fixed = {false, false, false, false, false, false};
  StagedSolveOptions solve;
  bool InitialIsValid(std::string* error) const;  // finite, in the model's range
  bool IsValid(std::string* error) const;
};

}  // namespace dwellfit

#endif  // DWELLFIT_ESTIMATOR_FIT_IDENTIFICATION_OPTIONS_H_
