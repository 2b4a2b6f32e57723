// Options of one identification run, one struct per component, each with
// defaults in the body and `bool IsValid(std::string* error) const`.
#ifndef DWELLFIT_ESTIMATOR_IDENTIFICATION_OPTIONS_H_
#define DWELLFIT_ESTIMATOR_IDENTIFICATION_OPTIONS_H_

#include <array>
#include <string>
#include <vector>

#include "residuals/model_parameters.h"
#include "residuals/vertical_error_residual.h"

namespace dwellfit {

// Which residual a fit stage minimises.
enum class ResidualKind {
  kAlgebraic,  // (G(a_i) - a_base_i^2) / a_base_i^2, eq. (3.11): smooth, branch-free
  kVertical,   // a_i - a_model(Omega_i, a_base_i) on the point's stable branch
};
const char* ResidualKindName(ResidualKind kind);
bool ResidualKindFromName(const std::string& name, ResidualKind* kind);

const char* ErrorMeasureName(ErrorMeasure measure);
bool ErrorMeasureFromName(const std::string& name, ErrorMeasure* measure);

struct ResidualOptions {
  ErrorMeasure error = ErrorMeasure::kAbsolute;
  // Divide each point's residual by its `sigma` column when the data has one.
  bool use_point_sigma = true;
};

struct SolverSettings {
  int max_iterations = 200;
  // Convergence tests of ceres::Solver::Options. The defaults are tight
  // because parameters span nine orders of magnitude (see ProblemBuilder).
  double function_tolerance = 1e-14;
  double gradient_tolerance = 1e-30;
  double parameter_tolerance = 1e-20;
  int num_threads = 1;
  bool IsValid(std::string* error) const;
};

// Jump detection in measured sweeps (issue: brackets and branch labels).
struct JumpDetectionOptions {
  // A jump is a step between consecutive dwells whose amplitude ratio exceeds
  // this (either way).
  double min_ratio = 2.0;
  // ... and whose larger side exceeds this fraction of the sweep's largest
  // amplitude (ignores hops in the noise floor far from resonance).
  double min_relative_amplitude = 0.2;
  bool IsValid(std::string* error) const;
};

struct IdentificationOptions {
  // Starting point, ParameterIndex order, physical units (omega in rad/s).
  ParameterVector initial = {0, 0, 0, 0, 0, 0};
  // Parameters held at their initial value.
  std::array<bool, kNumParameters> fixed = {false, false, false, false, false, false};
  // Fit stages run in order, each starting where the previous one ended.
  std::vector<ResidualKind> stages = {ResidualKind::kAlgebraic, ResidualKind::kVertical};
  ResidualOptions residual;
  SolverSettings solver;
  bool IsValid(std::string* error) const;
};

}  // namespace dwellfit

#endif  // DWELLFIT_ESTIMATOR_IDENTIFICATION_OPTIONS_H_
