#include "dwellfit/estimator/fit/identification_options.h"

#include <cmath>
#include <utility>

#include "dwellfit/estimator/common/name_table.h"
#include "dwellfit/estimator/common/string_printf.h"

namespace dwellfit {
namespace {

// Names in enumerator order.
constexpr const char* kResidualKindNames[] = {"algebraic", "vertical", "phase_lag", "all_roots"};
constexpr const char* kErrorMeasureNames[] = {"absolute", "relative"};
constexpr const char* kJumpTargetNames[] = {"frequency_jump_up", "frequency_jump_down",
                                            "amplitude_jump_up", "amplitude_jump_down"};

// Whether `value` is a non-negative number; else *error names `field`.
bool IsNonNegative(const std::string& field, double value, std::string* error) {
  if (value >= 0.0 && std::isfinite(value)) return true;
  *error = field + " must be a non-negative number (>= 0), got " + StringPrintf("%g", value);
  return false;
}

}  // namespace

const char* ResidualKindName(ResidualKind kind) { return NameOf(kResidualKindNames, kind); }

bool ResidualKindFromName(const std::string& name, ResidualKind* kind) {
  return FromName(name, kResidualKindNames, kind);
}

const char* ErrorMeasureName(ErrorMeasure measure) { return NameOf(kErrorMeasureNames, measure); }

bool ErrorMeasureFromName(const std::string& name, ErrorMeasure* measure) {
  return FromName(name, kErrorMeasureNames, measure);
}

bool ResidualOptions::IsValid(std::string* error) const {
  if (response_power < 0 || response_power > 2) {
    *error = "residual.response_power must be 0, 1 or 2 (displacement, velocity, acceleration)";
    return false;
  }
  if (response_power != 0 && this->error == ErrorMeasure::kRelative && amplitude_floor > 0.0) {
    *error =
        "residual.amplitude_floor is a floor of the measured velocity or acceleration, but the "
        "fit's amplitude is the displacement y / Omega^p, and ln(y + f) - ln(y_model + f) is no "
        "error of the displacement with one floor; set amplitude_floor: 0 (the relative error is "
        "then exact) or use error: absolute";
    return false;
  }
  return IsNonNegative("residual.amplitude_floor", amplitude_floor, error);
}

bool SolverSettings::IsValid(std::string* error) const {
  if (max_iterations < 1) {
    *error = "solver.max_iterations must be at least 1";
    return false;
  }
  const std::pair<const char*, double> tolerances[] = {
      {"function_tolerance", function_tolerance},
      {"start_function_tolerance", start_function_tolerance},
      {"gradient_tolerance", gradient_tolerance},
      {"parameter_tolerance", parameter_tolerance}};
  for (const auto& [name, value] : tolerances) {
    if (!IsNonNegative(std::string("solver.") + name, value, error)) return false;
  }
  if (num_threads < 0) {
    *error = "solver.num_threads must be at least 0 (0: one per processor available)";
    return false;
  }
  return true;
}

const char* JumpTargetName(JumpTarget target) { return NameOf(kJumpTargetNames, target); }

bool JumpTargetFromName(const std::string& name, JumpTarget* target) {
  return FromName(name, kJumpTargetNames, target);
}

bool BifurcationRangeOptions::IsValid(std::string* error) const {
  if (exponent < 2 || exponent % 2 != 0) {
    *error = "penalties.bifurcation_range.exponent must be an even integer >= 2";
    return false;
  }
  return IsNonNegative("penalties.bifurcation_range.weight", weight, error);
}

bool BranchStabilityOptions::IsValid(std::string* error) const {
  if (!(lambda > 0.0) || !std::isfinite(lambda)) {
    *error = "penalties.branch_stability.lambda must be a positive number";
    return false;
  }
  return IsNonNegative("penalties.branch_stability.weight", weight, error);
}

bool PenaltyOptions::IsValid(std::string* error) const {
  return bifurcation_range.IsValid(error) && branch_stability.IsValid(error);
}

bool StagedSolveOptions::IsValid(std::string* error) const {
  if (stages.empty()) {
    *error = "stages must list at least one fit stage (algebraic or vertical)";
    return false;
  }
  return residual.IsValid(error) && penalties.IsValid(error) && solver.IsValid(error);
}

bool IdentificationOptions::InitialIsValid(std::string* error) const {
  for (int i = 0; i < kNumParameters; ++i) {
    const std::string field = std::string("initial.") + ParameterName(solve.residual.form, i);
    if (!std::isfinite(initial[i])) {
      *error = field + " must be a finite number, got " + StringPrintf("%g", initial[i]);
      return false;
    }
    const bool positive = i == kEtaE || i == kNaturalFrequency;
    if (positive && !(initial[i] > 0.0)) {
      *error = field + " must be positive (> 0), got " + StringPrintf("%g", initial[i]);
      return false;
    }
    if ((i == kMu1 || i == kMu2) && initial[i] < 0.0) {
      *error = field + " must be non-negative (>= 0: it is bounded below by 0), got " +
               StringPrintf("%g", initial[i]);
      return false;
    }
  }
  return true;
}

bool IdentificationOptions::IsValid(std::string* error) const {
  return InitialIsValid(error) && solve.IsValid(error);
}

}  // namespace dwellfit
