#include "dwellfit/estimator/fit/problem_builder.h"

#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

#include "dwellfit/estimator/common/input_error.h"
#include "dwellfit/estimator/fit/batched_cost_function.h"
#include "dwellfit/estimator/fit/mapped_cost_function.h"
#include "dwellfit/residuals/functors/algebraic_residual.h"
#include "dwellfit/residuals/functors/all_roots_residual.h"
#include "dwellfit/residuals/functors/bifurcation_range_penalty.h"
#include "dwellfit/residuals/functors/branch_stability_penalty.h"
#include "dwellfit/residuals/functors/fold_condition_residual.h"
#include "dwellfit/residuals/functors/phase_lag_residual.h"
#include "dwellfit/residuals/functors/root_transition_penalty.h"
#include "dwellfit/residuals/functors/vertical_error_residual.h"

namespace dwellfit {

ProblemBuilder::ProblemBuilder(const ProblemBuilderOptions& options) : options_(options) {}

double ProblemBuilder::AmplitudeWeight(const DwellPoint& point) const {
  double weight = options_.dwell_weight;
  if (options_.residual_options.use_point_sigma && point.sigma) {
    // sigma is the standard deviation of a; in relative error it becomes
    // that of ln a, sigma / a.
    weight *= options_.residual_options.error == ErrorMeasure::kAbsolute
                  ? 1.0 / *point.sigma
                  : (point.amplitude + options_.residual_options.amplitude_floor) / *point.sigma;
  } else if (options_.residual_options.error == ErrorMeasure::kAbsolute) {
    weight *= std::pow(point.drive_frequency_rad_s, options_.residual_options.response_power);
  }
  return weight;
}

ceres::CostFunction* ProblemBuilder::MakeBatch(
    const std::vector<DwellPoint>& points, size_t first, size_t end,
    std::vector<VerticalErrorResidual*>* warm_started) const {
  if (options_.residual == ResidualKind::kAlgebraic) {
    auto* batch = new FunctorBatch<AlgebraicResidual>(form());
    for (size_t i = first; i < end; ++i) {
      const DwellPoint& point = points[i];
      batch->Add(form(), point.drive_frequency_rad_s, point.a_base, point.amplitude,
                 options_.dwell_weight);
    }
    return batch;
  }
  if (options_.residual == ResidualKind::kVertical) {
    auto* batch = new FunctorBatch<VerticalErrorResidual>(form());
    for (size_t i = first; i < end; ++i) {
      const DwellPoint& point = points[i];
      VerticalErrorResidual* functor =
          batch->Add(form(), point.drive_frequency_rad_s, point.a_base, point.amplitude,
                     point.branch, options_.residual_options.error, AmplitudeWeight(point),
                     options_.residual_options.amplitude_floor);
      if (warm_started != nullptr) warm_started->push_back(functor);
    }
    return batch;
  }
  std::vector<ceres::CostFunction*> members;
  for (size_t i = first; i < end; ++i) members.push_back(MakeResidual(points[i]));
  return new BatchedCostFunction(std::move(members));
}

ceres::CostFunction* ProblemBuilder::MakeResidual(const DwellPoint& point) const {
  if (options_.residual == ResidualKind::kAlgebraic) {
    return AlgebraicResidual::Create(form(), point.drive_frequency_rad_s, point.a_base,
                                     point.amplitude, options_.dwell_weight);
  }
  if (options_.residual == ResidualKind::kPhaseLag) {
    // AddSweep has checked that every dwell carries its phase.
    return PhaseLagResidual::Create(form(), point.drive_frequency_rad_s, point.a_base,
                                    point.amplitude, point.phase_rad.value_or(0.0),
                                    options_.dwell_weight);
  }
  const double weight = AmplitudeWeight(point);
  if (options_.residual == ResidualKind::kAllRoots) {
    return AllRootsResidual::Create(form(), point.drive_frequency_rad_s, point.a_base,
                                    point.amplitude, options_.residual_options.error, weight,
                                    options_.residual_options.amplitude_floor);
  }
  return VerticalErrorResidual::Create(
      form(), point.drive_frequency_rad_s, point.a_base, point.amplitude, point.branch,
      options_.residual_options.error, weight, options_.residual_options.amplitude_floor);
}

void ProblemBuilder::Add(ceres::CostFunction* cost, const ParameterLayout& layout,
                         ceres::Problem* problem, ParallelResidualEvaluator* evaluator) const {
  if (!layout.IsIdentity()) cost = new MappedCostFunction(cost, layout);
  if (evaluator != nullptr) cost = evaluator->Wrap(cost, layout.blocks);
  problem->AddResidualBlock(cost, nullptr, layout.blocks);
}

int ProblemBuilder::AddSweep(const Sweep& sweep, const ParameterLayout& layout,
                             ceres::Problem* problem, ParallelResidualEvaluator* evaluator,
                             std::vector<VerticalErrorResidual*>* warm_started) const {
  if (options_.residual == ResidualKind::kPhaseLag) {
    for (const DwellPoint& point : sweep.points) {
      if (point.phase_rad && std::isfinite(*point.phase_rad)) continue;
      throw InputError(sweep.source_file, point.source_line, "phase_deg",
                       "the phase_lag stage needs the measured phase of every fitted dwell, and "
                       "sweep '" +
                           sweep.Name() +
                           "' has none here; add a phase_deg or phase_rad "
                           "column, or choose other stages");
    }
  }
  const size_t count = sweep.points.size();
  for (size_t first = 0; first < count; first += kDwellsPerBatch) {
    const size_t end = std::min(count, first + kDwellsPerBatch);
    Add(MakeBatch(sweep.points, first, end, warm_started), layout, problem, evaluator);
  }
  return static_cast<int>(count);
}

int ProblemBuilder::ResidualBlocks(const Sweep& sweep) const {
  return static_cast<int>((sweep.points.size() + kDwellsPerBatch - 1) / kDwellsPerBatch);
}

JumpTarget TargetOf(const Sweep& sweep, const JumpBracket& jump) {
  const bool up = jump.kind == JumpKind::kJumpUp;
  if (sweep.kind == SweepKind::kFrequency) {
    return up ? JumpTarget::kFrequencyJumpUp : JumpTarget::kFrequencyJumpDown;
  }
  return up ? JumpTarget::kAmplitudeJumpUp : JumpTarget::kAmplitudeJumpDown;
}

bool IsEnforced(const BifurcationRangeOptions& range, const Sweep& sweep, const JumpBracket& jump) {
  return range.enabled && std::find(range.enforce.begin(), range.enforce.end(),
                                    TargetOf(sweep, jump)) != range.enforce.end();
}

namespace {

// The control the sweep holds at the dwell before the jump, which sits on
// the branch that ends: a_base of a frequency sweep, Omega of an amplitude one.
double HeldControl(const Sweep& sweep, const JumpBracket& jump) {
  const DwellPoint& before = sweep.points[jump.index_before];
  return sweep.kind == SweepKind::kFrequency ? before.a_base : before.drive_frequency_rad_s;
}

// The algebraic fold condition of one measured jump (FoldConditionResidual).
ceres::CostFunction* MakeFoldCondition(ModelForm form, const Sweep& sweep,
                                       const JumpBracket& jump) {
  const DwellPoint& before = sweep.points[jump.index_before];
  const bool frequency = sweep.kind == SweepKind::kFrequency;
  // One jump weighs as much as its sweep's dwells together.
  const double weight = std::sqrt(static_cast<double>(sweep.points.size()));
  return FoldConditionResidual::Create(
      form, frequency ? jump.centre() : before.drive_frequency_rad_s,
      frequency ? before.a_base : jump.centre(), jump.amplitude_before, weight);
}

}  // namespace

ceres::CostFunction* MakeBifurcationRangePenalty(ModelForm form, const Sweep& sweep,
                                                 const JumpBracket& jump,
                                                 const BifurcationRangeOptions& options,
                                                 ResidualKind residual) {
  if (residual == ResidualKind::kAllRoots) {
    // The all-roots method enforces the range through the roots (section 3.2.3).
    return new RootTransitionPenalty(form, sweep.kind, jump.kind, HeldControl(sweep, jump),
                                     jump.control_before, jump.control_after, jump.amplitude_before,
                                     options.weight);
  }
  return BifurcationRangePenalty::Create(form, sweep.kind, jump.kind, HeldControl(sweep, jump),
                                         jump.control_before, jump.control_after,
                                         jump.amplitude_before, options.exponent, options.weight);
}

bool FoldExists(ModelForm form, const Sweep& sweep, const JumpBracket& jump,
                const ParameterVector& p) {
  const BifurcationRangePenalty penalty(form, sweep.kind, jump.kind, HeldControl(sweep, jump),
                                        jump.control_before, jump.control_after,
                                        jump.amplitude_before, 2, 1.0);
  return penalty.SolveFold(p).exists;
}

void ProblemBuilder::AddPenalties(const Sweep& sweep, const ParameterLayout& layout,
                                  ceres::Problem* problem,
                                  ParallelResidualEvaluator* evaluator) const {
  const bool algebraic = options_.residual == ResidualKind::kAlgebraic;
  const BifurcationRangeOptions& range = options_.penalties.bifurcation_range;
  for (const JumpBracket& jump : sweep.jumps) {
    if (!IsEnforced(range, sweep, jump)) continue;
    Add(algebraic ? MakeFoldCondition(form(), sweep, jump)
                  : MakeBifurcationRangePenalty(form(), sweep, jump, range, options_.residual),
        layout, problem, evaluator);
  }
  const BranchStabilityOptions& stability = options_.penalties.branch_stability;
  if (stability.enabled && !algebraic && !sweep.points.empty()) {
    double largest = 0.0;
    for (const DwellPoint& point : sweep.points) largest = std::max(largest, point.amplitude);
    const double lambda = stability.lambda / largest;  // [1/amplitude]
    for (const DwellPoint& point : sweep.points) {
      if (point.branch == Branch::kOnly) continue;
      Add(BranchStabilityPenalty::Create(form(), point.drive_frequency_rad_s, point.amplitude,
                                         point.branch, lambda, stability.weight),
          layout, problem, evaluator);
    }
  }
}

}  // namespace dwellfit
