#include "dwellfit/estimator/fit/problem_builder.h"

#include <algorithm>
#include <cmath>

#include "dwellfit/estimator/fit/scaled_subset_manifold.h"
#include "glog/logging.h"
#include "dwellfit/residuals/functors/algebraic_residual.h"
#include "dwellfit/residuals/functors/bifurcation_range_penalty.h"
#include "dwellfit/residuals/functors/branch_stability_penalty.h"
#include "dwellfit/residuals/functors/vertical_error_residual.h"

namespace dwellfit {

bool ProblemBuilderOptions::IsValid(std::string* error) const {
  if (scale) {
    for (int i = 0; i < kNumParameters; ++i) {
      if (!fixed[i] && !((*scale)[i] > 0.0 && std::isfinite((*scale)[i]))) {
        *error = std::string("scale of ") + ParameterName(i) + " must be positive and finite";
        return false;
      }
    }
  }
  return true;
}

ProblemBuilder::ProblemBuilder(const ProblemBuilderOptions& options) : options_(options) {
  std::string error;
  CHECK(options_.IsValid(&error)) << error;
}

ceres::CostFunction* ProblemBuilder::MakeResidual(const DwellPoint& point) const {
  if (options_.residual == ResidualKind::kAlgebraic) {
    return AlgebraicResidual::Create(point.drive_frequency_rad_s, point.a_base, point.amplitude,
                                     1.0);
  }
  double weight = 1.0;
  if (options_.residual_options.use_point_sigma && point.sigma) {
    // sigma is the standard deviation of a; in relative error it becomes
    // that of ln a, sigma / a.
    weight = options_.residual_options.error == ErrorMeasure::kAbsolute
                 ? 1.0 / *point.sigma
                 : (point.amplitude + options_.residual_options.amplitude_floor) / *point.sigma;
  }
  return VerticalErrorResidual::Create(point.drive_frequency_rad_s, point.a_base, point.amplitude,
                                       point.branch, options_.residual_options.error, weight,
                                       options_.residual_options.amplitude_floor);
}

namespace {

// `cost` as the problem receives it: through `evaluator` when there is one.
ceres::CostFunction* Evaluated(ceres::CostFunction* cost, ParallelResidualEvaluator* evaluator) {
  return evaluator != nullptr ? evaluator->Wrap(cost) : cost;
}

}  // namespace

int ProblemBuilder::AddSweep(const Sweep& sweep, double* parameters, ceres::Problem* problem,
                             ParallelResidualEvaluator* evaluator) const {
  for (const DwellPoint& point : sweep.points) {
    problem->AddResidualBlock(Evaluated(MakeResidual(point), evaluator), nullptr, parameters);
  }
  return static_cast<int>(sweep.points.size());
}

JumpTarget TargetOf(const Sweep& sweep, const JumpBracket& jump) {
  const bool up = jump.kind == JumpKind::kJumpUp;
  if (sweep.kind == SweepKind::kFrequency) {
    return up ? JumpTarget::kFrequencyJumpUp : JumpTarget::kFrequencyJumpDown;
  }
  return up ? JumpTarget::kAmplitudeJumpUp : JumpTarget::kAmplitudeJumpDown;
}

ceres::CostFunction* MakeBifurcationRangePenalty(const Sweep& sweep, const JumpBracket& jump,
                                                 const BifurcationRangeOptions& options) {
  const DwellPoint& before = sweep.points[jump.index_before];
  const bool frequency = sweep.kind == SweepKind::kFrequency;
  // A jump-up ends the lower branch, a jump-down the upper one; the dwell
  // before the jump sits on the branch that ends.
  return BifurcationRangePenalty::Create(
      frequency ? ControlKind::kDriveFrequency : ControlKind::kBaseLevel,
      jump.kind == JumpKind::kJumpUp ? FoldKind::kLowerBranchEnd : FoldKind::kUpperBranchEnd,
      frequency ? before.a_base : before.drive_frequency_rad_s, jump.control_before,
      jump.control_after, jump.amplitude_before, options.exponent, options.weight);
}

int ProblemBuilder::AddPenalties(const Sweep& sweep, double* parameters, ceres::Problem* problem,
                                 ParallelResidualEvaluator* evaluator) const {
  int blocks = 0;
  const BifurcationRangeOptions& range = options_.penalties.bifurcation_range;
  if (range.enabled) {
    for (const JumpBracket& jump : sweep.jumps) {
      const JumpTarget target = TargetOf(sweep, jump);
      if (std::find(range.enforce.begin(), range.enforce.end(), target) == range.enforce.end()) {
        continue;
      }
      problem->AddResidualBlock(
          Evaluated(MakeBifurcationRangePenalty(sweep, jump, range), evaluator), nullptr,
          parameters);
      ++blocks;
    }
  }
  const BranchStabilityOptions& stability = options_.penalties.branch_stability;
  if (stability.enabled && !sweep.points.empty()) {
    double largest = 0.0;
    for (const DwellPoint& point : sweep.points) largest = std::max(largest, point.amplitude);
    const double lambda = stability.lambda / largest;  // [1/amplitude]
    for (const DwellPoint& point : sweep.points) {
      if (point.branch == Branch::kOnly) continue;
      problem->AddResidualBlock(
          Evaluated(BranchStabilityPenalty::Create(point.drive_frequency_rad_s, point.amplitude,
                                                   point.branch, lambda, stability.weight),
                    evaluator),
          nullptr, parameters);
      ++blocks;
    }
  }
  return blocks;
}

void ProblemBuilder::ConfigureParameters(double* parameters, ceres::Problem* problem) const {
  CHECK(problem->HasParameterBlock(parameters)) << "add residuals before configuring";
  problem->SetParameterLowerBound(parameters, kEtaE, 0.0);
  if (options_.bound_damping) {
    for (int i : {kMu1, kMu2}) problem->SetParameterLowerBound(parameters, i, 0.0);
  }
  bool any_free = false;
  for (bool f : options_.fixed) any_free = any_free || !f;
  if (!any_free) {
    problem->SetParameterBlockConstant(parameters);
    return;
  }
  ParameterVector scale;
  for (int i = 0; i < kNumParameters; ++i) {
    scale[i] = options_.scale ? (*options_.scale)[i] : std::abs(parameters[i]);
    if (!(scale[i] > 0.0)) scale[i] = 1.0;
  }
  problem->SetManifold(parameters, new ScaledSubsetManifold(scale, options_.fixed));
}

bool ReflectDampingIntoPhysicalRange(ParameterVector* parameters) {
  ParameterVector& p = *parameters;
  const ParameterVector before = p;
  p[kEtaE] = std::abs(p[kEtaE]);
  if (p[kMu1] <= 0.0 && p[kMu2] <= 0.0) {
    p[kMu1] = -p[kMu1];
    p[kMu2] = -p[kMu2];
  }
  for (int i : {kMu1, kMu2}) p[i] = std::max(p[i], 0.0);
  return p != before;
}

}  // namespace dwellfit
