#include "dwellfit/estimator/fit/valley_polish.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <utility>

#include "Eigen/Core"
#include "ceres/first_order_function.h"
#include "ceres/gradient_problem.h"
#include "ceres/gradient_problem_solver.h"
#include "ceres/manifold.h"
#include "dwellfit/estimator/fit/jacobian_factor.h"
#include "glog/logging.h"

namespace dwellfit {

CreepWatcher::CreepWatcher(int steps, double min_ratio) : steps_(steps), min_ratio_(min_ratio) {
  CHECK_GE(steps, 1);
  CHECK_GT(min_ratio, 1.0);
}

ceres::CallbackReturnType CreepWatcher::operator()(const ceres::IterationSummary& summary) {
  if (summary.iteration == 0) return ceres::SOLVER_CONTINUE;
  const bool creeping_step = summary.step_is_successful && summary.relative_decrease > min_ratio_;
  in_a_row_ = creeping_step ? in_a_row_ + 1 : 0;
  if (in_a_row_ < steps_) return ceres::SOLVER_CONTINUE;
  creeping_ = true;
  return ceres::SOLVER_TERMINATE_SUCCESSFULLY;
}

namespace {

// Rows of R per chunk of the Jacobian (as the covariance's).
constexpr int kChunkRows = 4096;
// Trial steps of one line search at the most (see PolishOptions).
constexpr int kLineSearchTrials = 8;

// F(u) = F(x0 [+] R^-1 u) and its gradient R^-T g(x) in the whitened
// coordinates u, g the gradient in the blocks' tangent coordinates. A point
// past a bound of the problem fails (the line search steps back).
// Remembers the point of lowest cost it evaluated: a line search that fails
// on a cost that is not smooth (folds, penalties) ends BFGS with a failure,
// after steps that may already have lowered the cost.
class WhitenedCost : public ceres::FirstOrderFunction {
 public:
  WhitenedCost(ceres::Problem* problem, std::vector<double*> blocks, Eigen::MatrixXd r)
      : problem_(problem), blocks_(std::move(blocks)), r_(std::move(r)) {
    evaluate_.parameter_blocks = blocks_;
    for (double* block : blocks_) {
      const int size = problem_->ParameterBlockSize(block);
      start_.emplace_back(block, block + size);
    }
  }

  int NumParameters() const override { return static_cast<int>(r_.rows()); }

  bool Evaluate(const double* u, double* cost, double* gradient) const override {
    MoveTo(u);
    if (!WithinBounds()) return false;
    std::vector<double> g;
    double value = 0.0;
    if (!problem_->Evaluate(evaluate_, &value, nullptr, gradient != nullptr ? &g : nullptr,
                            nullptr) ||
        !std::isfinite(value)) {
      return false;
    }
    *cost = value;
    if (value < best_cost_) {
      best_cost_ = value;
      best_u_.assign(u, u + NumParameters());
    }
    if (gradient != nullptr) {
      Eigen::Map<Eigen::VectorXd> whitened(gradient, NumParameters());
      whitened = r_.transpose().triangularView<Eigen::Lower>().solve(
          Eigen::Map<const Eigen::VectorXd>(g.data(), NumParameters()));
      if (!whitened.allFinite()) return false;
    }
    return true;
  }

  double best_cost() const { return best_cost_; }
  const std::vector<double>& best_u() const { return best_u_; }

  // Sets the blocks to x0 [+] R^-1 u.
  void MoveTo(const double* u) const {
    const Eigen::VectorXd delta = r_.triangularView<Eigen::Upper>().solve(
        Eigen::Map<const Eigen::VectorXd>(u, NumParameters()));
    int offset = 0;
    for (size_t b = 0; b < blocks_.size(); ++b) {
      const ceres::Manifold* manifold = problem_->GetManifold(blocks_[b]);
      if (manifold != nullptr) {
        manifold->Plus(start_[b].data(), delta.data() + offset, blocks_[b]);
      } else {
        for (size_t i = 0; i < start_[b].size(); ++i)
          blocks_[b][i] = start_[b][i] + delta[offset + i];
      }
      offset += problem_->ParameterBlockTangentSize(blocks_[b]);
    }
  }

 private:
  bool WithinBounds() const {
    for (double* block : blocks_) {
      for (int i = 0; i < problem_->ParameterBlockSize(block); ++i) {
        if (block[i] < problem_->GetParameterLowerBound(block, i) ||
            block[i] > problem_->GetParameterUpperBound(block, i)) {
          return false;
        }
      }
    }
    return true;
  }

  ceres::Problem* problem_;
  std::vector<double*> blocks_;
  Eigen::MatrixXd r_;  // upper triangular, k x k
  std::vector<std::vector<double>> start_;
  ceres::Problem::EvaluateOptions evaluate_;
  mutable double best_cost_ = std::numeric_limits<double>::infinity();
  mutable std::vector<double> best_u_;
};

ceres::GradientProblemSolver::Options PolishOptions(const SolverSettings& settings) {
  ceres::GradientProblemSolver::Options options;
  options.line_search_direction_type = ceres::BFGS;
  options.line_search_type = ceres::WOLFE;
  SetConvergenceTests(settings, &options);
  // Fewer trial steps than Ceres' 20: on the floor of a valley whose cost is
  // not smooth (dwells crossing the end of their branch) no step meets the
  // Wolfe conditions.
  options.max_num_line_search_step_size_iterations = kLineSearchTrials;
  options.logging_type = ceres::SILENT;
  return options;
}

}  // namespace

ValleyPolish PolishAlongValley(ceres::Problem* problem, const std::vector<double*>& blocks,
                               const SolverSettings& settings) {
  ValleyPolish polish;
  int k = 0;
  for (double* block : blocks) k += problem->ParameterBlockTangentSize(block);
  std::vector<ceres::ResidualBlockId> rows;
  problem->GetResidualBlocks(&rows);
  Eigen::MatrixXd r;
  if (k == 0 || !FactorJacobian(problem, rows, blocks, k, kChunkRows, &polish.initial_cost, &r)) {
    polish.message = "the Jacobian cannot be evaluated";
    return polish;
  }
  const Eigen::VectorXd diagonal = r.diagonal().cwiseAbs();
  if (!(diagonal.minCoeff() > std::numeric_limits<double>::epsilon() * diagonal.maxCoeff())) {
    polish.message = "the Jacobian is rank-deficient";
    return polish;
  }
  auto* cost = new WhitenedCost(problem, blocks, r);
  const ceres::GradientProblem gradient_problem(cost);  // owns `cost`
  std::vector<double> u(k, 0.0);
  ceres::GradientProblemSolver::Summary summary;
  ceres::Solve(PolishOptions(settings), gradient_problem, u.data(), &summary);
  polish.iterations = std::max(static_cast<int>(summary.iterations.size()) - 1, 0);
  // The lowest cost evaluated, whether or not BFGS ended on a convergence
  // test (or the start, when nothing was lower).
  polish.improved = cost->best_cost() < polish.initial_cost;
  polish.final_cost = polish.improved ? cost->best_cost() : polish.initial_cost;
  u = polish.improved ? cost->best_u() : std::vector<double>(k, 0.0);
  cost->MoveTo(u.data());
  std::ostringstream message;
  message << "BFGS " << polish.iterations << " iterations, cost " << polish.initial_cost << " -> "
          << polish.final_cost << " (" << summary.message << ")";
  polish.message = message.str();
  return polish;
}

}  // namespace dwellfit
