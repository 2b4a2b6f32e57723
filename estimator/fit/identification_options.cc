#include "dwellfit/estimator/fit/identification_options.h"

#include <cmath>
#include <sstream>

namespace dwellfit {

const char* ResidualKindName(ResidualKind kind) {
  return kind == ResidualKind::kAlgebraic ? "algebraic" : "vertical";
}

bool ResidualKindFromName(const std::string& name, ResidualKind* kind) {
  for (ResidualKind k : {ResidualKind::kAlgebraic, ResidualKind::kVertical}) {
    if (name == ResidualKindName(k)) {
      *kind = k;
      return true;
    }
  }
  return false;
}

const char* ErrorMeasureName(ErrorMeasure measure) {
  return measure == ErrorMeasure::kAbsolute ? "absolute" : "relative";
}

bool ErrorMeasureFromName(const std::string& name, ErrorMeasure* measure) {
  for (ErrorMeasure m : {ErrorMeasure::kAbsolute, ErrorMeasure::kRelative}) {
    if (name == ErrorMeasureName(m)) {
      *measure = m;
      return true;
    }
  }
  return false;
}

bool SolverSettings::IsValid(std::string* error) const {
  if (max_iterations < 1) {
    *error = "solver.max_iterations must be at least 1";
    return false;
  }
  if (!(function_tolerance >= 0) || !(gradient_tolerance >= 0) || !(parameter_tolerance >= 0)) {
    *error = "solver tolerances must be non-negative numbers";
    return false;
  }
  if (num_threads < 0) {
    *error = "solver.num_threads must be at least 0 (0: one per processor available)";
    return false;
  }
  return true;
}

const char* JumpTargetName(JumpTarget target) {
  switch (target) {
    case JumpTarget::kFrequencyJumpUp:
      return "frequency_jump_up";
    case JumpTarget::kFrequencyJumpDown:
      return "frequency_jump_down";
    case JumpTarget::kAmplitudeJumpUp:
      return "amplitude_jump_up";
    case JumpTarget::kAmplitudeJumpDown:
      return "amplitude_jump_down";
  }
  return "frequency_jump_down";
}

bool JumpTargetFromName(const std::string& name, JumpTarget* target) {
  for (JumpTarget t : {JumpTarget::kFrequencyJumpUp, JumpTarget::kFrequencyJumpDown,
                       JumpTarget::kAmplitudeJumpUp, JumpTarget::kAmplitudeJumpDown}) {
    if (name == JumpTargetName(t)) {
      *target = t;
      return true;
    }
  }
  return false;
}

bool BifurcationRangeOptions::IsValid(std::string* error) const {
  if (exponent < 2 || exponent % 2 != 0) {
    *error = "penalties.bifurcation_range.exponent must be an even integer >= 2";
    return false;
  }
  if (!(weight >= 0.0) || !std::isfinite(weight)) {
    *error = "penalties.bifurcation_range.weight must be a non-negative number";
    return false;
  }
  return true;
}

bool BranchStabilityOptions::IsValid(std::string* error) const {
  if (!(lambda > 0.0) || !std::isfinite(lambda)) {
    *error = "penalties.branch_stability.lambda must be a positive number";
    return false;
  }
  if (!(weight >= 0.0) || !std::isfinite(weight)) {
    *error = "penalties.branch_stability.weight must be a non-negative number";
    return false;
  }
  return true;
}

bool PenaltyOptions::IsValid(std::string* error) const {
  return bifurcation_range.IsValid(error) && branch_stability.IsValid(error);
}

bool IdentificationOptions::IsValid(std::string* error) const {
  for (int i = 0; i < kNumParameters; ++i) {
    if (!std::isfinite(initial[i])) {
      *error = std::string("initial value of ") + ParameterName(i) + " is not a finite number";
      return false;
    }
  }
  for (int i : {kEtaE, kMu1, kMu2}) {
    if (initial[i] < 0.0) {
      *error = std::string("initial value of ") + ParameterName(i) +
               " must be non-negative (it is bounded below by 0)";
      return false;
    }
  }
  if (!(initial[kEtaE] > 0.0)) {
    *error = "initial value of eta_e must be positive";
    return false;
  }
  if (!(initial[kOmega] > 0.0)) {
    *error = "initial value of omega (natural frequency) must be positive";
    return false;
  }
  if (stages.empty()) {
    *error = "at least one fit stage is required";
    return false;
  }
  return penalties.IsValid(error) && solver.IsValid(error);
}

}  // namespace dwellfit
