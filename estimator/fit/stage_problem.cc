#include "dwellfit/estimator/fit/stage_problem.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <memory>
#include <sstream>
#include <unordered_set>

#include "ceres/loss_function.h"
#include "dwellfit/estimator/common/string_printf.h"
#include "dwellfit/estimator/fit/scaled_subset_manifold.h"
#include "glog/logging.h"

namespace dwellfit {

ceres::Problem::Options StageProblem::ProblemOptions(ParallelResidualEvaluator* evaluator) {
  ceres::Problem::Options options;
  options.evaluation_callback = evaluator;
  options.cost_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;  // cost_functions_ owns them
  return options;
}

std::vector<ceres::ResidualBlockId> StageProblem::AddOwned(ceres::Problem* problem, bool may_share,
                                                           const std::function<void()>& add) {
  const size_t before = problem->NumResidualBlocks();
  std::vector<ceres::ResidualBlockId> all;
  const auto own = [&] {
    problem->GetResidualBlocks(&all);
    std::unordered_set<const ceres::CostFunction*> owned;
    cost_functions_.reserve(cost_functions_.size() + all.size() - before);
    for (size_t i = before; i < all.size(); ++i) {
      const ceres::CostFunction* cost = problem->GetCostFunctionForResidualBlock(all[i]);
      if (!may_share || owned.insert(cost).second) cost_functions_.emplace_back(cost);
    }
  };
  try {
    add();
  } catch (...) {  // what was added before the throw is owned all the same
    own();
    throw;
  }
  own();
  return {all.begin() + before, all.end()};
}

std::vector<ParallelResidualEvaluator::Block> StageProblem::EvaluatedBlocks(
    const FitDescription& fit) {
  std::vector<ParallelResidualEvaluator::Block> blocks;
  for (const FitBlock& block : fit.blocks) blocks.push_back({block.values, block.size});
  return blocks;
}

StageProblem::StageProblem(const FitDescription& fit, const StageSetup& setup)
    : fit_(fit),
      setup_(setup),
      held_constant_(fit.blocks.size(), false),
      builder_(setup.residuals),
      eta_e_entries_(fit.EntriesHolding({kEtaE})),
      damping_entries_(fit.EntriesHolding({kMu1, kMu2})),
      fixed_(fit.FixedEntries()),
      evaluator_(EvaluatedBlocks(fit), setup.num_threads),
      problem_(ProblemOptions(Evaluator())),
      dwell_problem_(ProblemOptions(nullptr)) {
  CHECK_EQ(setup.scale.size(), fixed_.size());
  for (const FitBlock& block : fit.blocks) problem_.AddParameterBlock(block.values, block.size);
  int blocks = 0;
  for (const FitDataset& dataset : fit.datasets) {
    for (const Sweep* sweep : dataset.sweeps) blocks += builder_.ResidualBlocks(*sweep);
  }
  const int points = fit.NumDwells();
  if (setup.threaded_evaluation) evaluator_.Reserve(blocks, points);
  if (setup.residuals.residual == ResidualKind::kVertical) warm_started_.reserve(points);
  AddDwells();
  if (setup.threaded_evaluation && !dwell_blocks_.empty()) {
    std::vector<double*> all;
    for (const FitBlock& block : fit.blocks) all.push_back(block.values);
    ceres::CostFunction* compressed = evaluator_.Compress();
    cost_functions_.emplace_back(compressed);
    problem_.AddResidualBlock(compressed, nullptr, all);
  }
}

void StageProblem::AddDwells() {
  ceres::Problem* problem = dwell_problem();
  dwell_blocks_ = AddOwned(problem, false, [&] {
    for (const FitDataset& dataset : fit_.datasets) {
      layouts_.push_back(LayoutOf(fit_, dataset.parameters));
      for (const Sweep* sweep : dataset.sweeps) {
        dwells_ += builder_.AddSweep(*sweep, layouts_.back(), problem, Evaluator(), &warm_started_);
      }
    }
  });
}

void StageProblem::AddPenalties(const PenaltyOptions& penalties) {
  ProblemBuilderOptions options = setup_.residuals;
  options.penalties = penalties;
  const ProblemBuilder penalty_builder(options);
  const std::vector<ceres::ResidualBlockId> added = AddOwned(&problem_, false, [&] {
    for (size_t d = 0; d < fit_.datasets.size(); ++d) {
      for (const Sweep* sweep : fit_.datasets[d].sweeps) {
        penalty_builder.AddPenalties(*sweep, layouts_[d], &problem_, Evaluator());
      }
    }
  });
  penalty_blocks_.insert(penalty_blocks_.end(), added.begin(), added.end());
}

std::vector<std::string> StageProblem::MissingFolds(const BifurcationRangeOptions& range) const {
  std::vector<std::string> missing;
  if (!range.enabled) return missing;
  for (size_t d = 0; d < fit_.datasets.size(); ++d) {
    const ParameterVector p = layouts_[d].Values();
    for (const Sweep* sweep : fit_.datasets[d].sweeps) {
      for (const JumpBracket& jump : sweep->jumps) {
        if (!IsEnforced(range, *sweep, jump) ||
            FoldExists(setup_.residuals.residual_options.form, *sweep, jump, p))
          continue;
        const bool frequency = sweep->kind == SweepKind::kFrequency;
        const double scale = frequency ? 1.0 / kTwoPi : 1.0;
        missing.push_back(StringPrintf("%s: no %s fold near its measured bracket %.6g..%.6g %s",
                                       sweep->Name().c_str(), JumpKindName(jump.kind),
                                       jump.control_before * scale, jump.control_after * scale,
                                       frequency ? "Hz" : "(a_base)"));
      }
    }
  }
  return missing;
}

void StageProblem::AddCallerResiduals() {
  if (!fit_.add_residuals) return;
  caller_blocks_ = AddOwned(&problem_, true, [this] { fit_.add_residuals(&problem_); });
}

bool StageProblem::IsBounded(int entry) const {
  return eta_e_entries_[entry] || (setup_.bound_damping && damping_entries_[entry]);
}

bool StageProblem::IsHeld(int entry) const {
  return fixed_[entry] || (!held_.empty() && held_[entry]);
}

void StageProblem::EvaluateAfresh() {
  for (VerticalErrorResidual* functor : warm_started_) functor->ForgetRoot();
  evaluator_.Invalidate();
}

void StageProblem::Hold(const std::vector<bool>& held) {
  CHECK(held.empty() || held.size() == fixed_.size());
  held_ = held;
}

void StageProblem::Configure() {
  for (size_t b = 0; b < fit_.blocks.size(); ++b) {
    const FitBlock& block = fit_.blocks[b];
    const int offset = fit_.Offset(static_cast<int>(b));
    std::vector<bool> held(block.size);
    std::vector<double> scale(block.size);
    bool any_free = false;
    for (int i = 0; i < block.size; ++i) {
      if (IsBounded(offset + i)) problem_.SetParameterLowerBound(block.values, i, 0.0);
      held[i] = IsHeld(offset + i);
      scale[i] = setup_.scale[offset + i];
      any_free = any_free || !held[i];
    }
    // Configured before (a solve again after Hold): a block held constant
    // then may move now, and one with none free now drops its manifold.
    if (!any_free) {
      if (problem_.HasManifold(block.values)) problem_.SetManifold(block.values, nullptr);
      problem_.SetParameterBlockConstant(block.values);
      held_constant_[b] = true;
      continue;
    }
    if (held_constant_[b]) problem_.SetParameterBlockVariable(block.values);
    held_constant_[b] = false;
    problem_.SetManifold(block.values, new ScaledSubsetManifold(scale, held));
  }
}

namespace {

// `cost` at `blocks` with every Jacobian (row-major, one per block); false
// if it fails.
bool EvaluateWithJacobians(const ceres::CostFunction& cost, const std::vector<double*>& blocks,
                           std::vector<double>* residuals,
                           std::vector<std::vector<double>>* jacobians) {
  residuals->resize(cost.num_residuals());
  jacobians->resize(blocks.size());
  std::vector<double*> pointers;
  for (size_t j = 0; j < blocks.size(); ++j) {
    (*jacobians)[j].resize(cost.num_residuals() * cost.parameter_block_sizes()[j]);
    pointers.push_back((*jacobians)[j].data());
  }
  return cost.Evaluate(blocks.data(), residuals->data(), pointers.data());
}

// Whether `cost` evaluates at `blocks`, with finite residuals and Jacobian.
bool EvaluatesFinite(const ceres::CostFunction& cost, const std::vector<double*>& blocks) {
  std::vector<double> residuals;
  std::vector<std::vector<double>> jacobians;
  if (!EvaluateWithJacobians(cost, blocks, &residuals, &jacobians)) return false;
  const auto finite = [](const std::vector<double>& values) {
    return std::all_of(values.begin(), values.end(), [](double v) { return std::isfinite(v); });
  };
  return finite(residuals) && std::all_of(jacobians.begin(), jacobians.end(), finite);
}

double CostOf(const std::vector<ceres::ResidualBlockId>& blocks, ceres::Problem* problem) {
  if (blocks.empty()) return 0.0;
  ceres::Problem::EvaluateOptions evaluate;
  evaluate.residual_blocks = blocks;
  double cost = 0.0;
  if (!problem->Evaluate(evaluate, &cost, nullptr, nullptr, nullptr) || !std::isfinite(cost)) {
    return std::numeric_limits<double>::infinity();
  }
  return cost;
}

}  // namespace

double StageProblem::DataCost() {
  // The dwells' own blocks answer from the evaluator's values at the point.
  if (setup_.threaded_evaluation) evaluator_.PrepareForEvaluation(false, true);
  return CostOf(dwell_blocks_, dwell_problem());
}

double StageProblem::PenaltyCost() { return CostOf(penalty_blocks_, &problem_); }

double StageProblem::TotalCost() {
  const double data = DataCost();
  return data + PenaltyCost() + CostOf(caller_blocks_, &problem_);
}

bool StageProblem::CostGradient(std::vector<double>* gradient) {
  std::vector<ceres::ResidualBlockId> direct = caller_blocks_;
  if (setup_.threaded_evaluation) {
    const std::vector<double> point = fit_.Values();
    if (!evaluator_.CostGradient(point.data(), gradient)) return false;
  } else {
    gradient->assign(fit_.NumEntries(), 0.0);
    problem_.GetResidualBlocks(&direct);
  }
  // Blocks the evaluator does not hold add rho'(|r|^2) J^T r each.
  for (ceres::ResidualBlockId id : direct) {
    const ceres::CostFunction* cost = problem_.GetCostFunctionForResidualBlock(id);
    std::vector<double*> blocks;
    problem_.GetParameterBlocksForResidualBlock(id, &blocks);
    const int rows = cost->num_residuals();
    std::vector<double> residuals;
    std::vector<std::vector<double>> jacobians;
    if (!EvaluateWithJacobians(*cost, blocks, &residuals, &jacobians)) return false;
    double weight = 1.0;
    if (const ceres::LossFunction* loss = problem_.GetLossFunctionForResidualBlock(id)) {
      double squared_norm = 0.0;
      for (double r : residuals) squared_norm += r * r;
      double rho[3];
      loss->Evaluate(squared_norm, rho);
      weight = rho[1];
    }
    for (size_t j = 0; j < blocks.size(); ++j) {
      const int b = fit_.BlockOf(blocks[j]);
      if (b < 0) continue;  // a block of the caller's own
      const int size = fit_.blocks[b].size;
      for (int row = 0; row < rows; ++row) {
        for (int col = 0; col < size; ++col) {
          (*gradient)[fit_.Offset(b) + col] +=
              weight * jacobians[j][row * size + col] * residuals[row];
        }
      }
    }
  }
  return true;
}

std::vector<BoundRestWatcher::Entry> StageProblem::WatchedBounds() const {
  std::vector<BoundRestWatcher::Entry> watched;
  for (size_t b = 0; b < fit_.blocks.size(); ++b) {
    const int offset = fit_.Offset(static_cast<int>(b));
    for (int i = 0; i < fit_.blocks[b].size; ++i) {
      if (IsBounded(offset + i) && !IsHeld(offset + i)) {
        const double* value = fit_.blocks[b].values + i;
        const double* iterate =
            setup_.threaded_evaluation ? evaluator_.IterateEntry(value) : nullptr;
        watched.push_back({value, 0.0, offset + i, iterate});
      }
    }
  }
  return watched;
}

void StageProblem::MoveToIterate() {
  if (!setup_.threaded_evaluation) return;
  for (const FitBlock& block : fit_.blocks) {
    const double* iterate = evaluator_.IterateEntry(block.values);
    std::copy(iterate, iterate + block.size, block.values);
  }
}

std::string StageProblem::DescribeFailure(const std::string& ceres_message) {
  // Each dwell on its own (the problem may hold them in batches).
  int dwells = 0;
  int bad_dwells = 0;
  const Sweep* sweep = nullptr;  // of the first dwell that fails
  const DwellPoint* point = nullptr;
  for (size_t d = 0; d < fit_.datasets.size(); ++d) {
    ParameterVector p = layouts_[d].Values();
    const std::vector<double*> block = {p.data()};
    for (const Sweep* s : fit_.datasets[d].sweeps) {
      for (const DwellPoint& dwell : s->points) {
        ++dwells;
        const std::unique_ptr<ceres::CostFunction> cost(builder_.MakeResidual(dwell));
        if (EvaluatesFinite(*cost, block) || bad_dwells++ > 0) continue;
        sweep = s;
        point = &dwell;
      }
    }
  }
  bool bad_other = false;
  for (const std::vector<ceres::ResidualBlockId>* ids : {&penalty_blocks_, &caller_blocks_}) {
    for (ceres::ResidualBlockId id : *ids) {
      std::vector<double*> blocks;
      problem_.GetParameterBlocksForResidualBlock(id, &blocks);
      bad_other =
          bad_other || !EvaluatesFinite(*problem_.GetCostFunctionForResidualBlock(id), blocks);
    }
  }
  if (point == nullptr) {
    return bad_other ? "a penalty or caller's term is not finite there (penalties, "
                       "config/README.md)"
                     : "Ceres: " + ceres_message;
  }
  std::ostringstream text;
  text << (bad_dwells == dwells
               ? "no dwell's residual is finite there, so the parameters are at fault (the "
                 "first dwell: "
               : std::to_string(bad_dwells) + " dwell(s) have a residual that is not finite " +
                     "there (the first: ")
       << sweep->source_file << ":" << point->source_line << ", sweep " << sweep->Name() << ", "
       << RadPerSecondToHz(point->drive_frequency_rad_s) << " Hz, a_base " << point->a_base
       << ", a " << point->amplitude << ")";
  return text.str();
}

}  // namespace dwellfit
