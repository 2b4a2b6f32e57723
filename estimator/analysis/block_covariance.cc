#include "dwellfit/estimator/analysis/block_covariance.h"

#include <algorithm>
#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "Eigen/SVD"
#include "boost/math/distributions/normal.hpp"
#include "boost/math/distributions/students_t.hpp"
#include "ceres/covariance.h"
#include "ceres/normal_prior.h"
#include "dwellfit/estimator/common/string_printf.h"
#include "dwellfit/estimator/fit/jacobian_factor.h"
#include "dwellfit/estimator/fit/scaled_subset_manifold.h"
#include "dwellfit/estimator/fit/stage_problem.h"

namespace dwellfit {
namespace {

// One tangent unit per entry's magnitude (1 for 0).
std::vector<double> TangentScale(const std::vector<double>& values) {
  std::vector<double> scale;
  for (double value : values) scale.push_back(value != 0.0 ? std::abs(value) : 1.0);
  return scale;
}

// The vertical-error problem at the blocks' current values in TangentScale
// units, every dwell weighted by `dwell_weight`; the caller's residual
// blocks when `with_caller`, whose own blocks are held.
std::unique_ptr<StageProblem> AssembleDataProblem(const FitDescription& fit,
                                                  const ResidualOptions& residual,
                                                  double dwell_weight, bool with_caller) {
  StageSetup setup;
  setup.residuals.residual = ResidualKind::kVertical;
  setup.residuals.residual_options = residual;
  setup.residuals.dwell_weight = dwell_weight;
  setup.threaded_evaluation = false;  // evaluated twice: no threads needed
  setup.scale = TangentScale(fit.Values());
  auto problem = std::make_unique<StageProblem>(fit, setup);
  if (with_caller) problem->AddCallerResiduals();
  problem->Configure();
  std::vector<double*> blocks;
  problem->problem()->GetParameterBlocks(&blocks);
  for (double* block : blocks) {
    if (fit.BlockOf(block) < 0) problem->problem()->SetParameterBlockConstant(block);
  }
  return problem;
}

// The described blocks with a free entry, in order.
std::vector<double*> FreeBlocks(const FitDescription& fit) {
  const std::vector<bool> fixed = fit.FixedEntries();
  std::vector<double*> blocks;
  for (size_t b = 0; b < fit.blocks.size(); ++b) {
    const auto begin = fixed.begin() + fit.Offset(static_cast<int>(b));
    if (std::count(begin, begin + fit.blocks[b].size, false) > 0) {
      blocks.push_back(fit.blocks[b].values);
    }
  }
  return blocks;
}

BlockCovariance Unavailable(BlockCovariance c, const std::string& message) {
  c.available = false;
  c.message = message;
  if (!std::isfinite(c.noise_sigma)) c.noise_sigma = 0.0;
  if (!std::isfinite(c.reduced_chi_square)) c.reduced_chi_square = 0.0;
  if (std::isnan(c.collinearity)) c.collinearity = 0.0;
  return c;
}

// Counts, free entries, zeroed results and the point-sigma flag; false
// (`c->message` says why) when there is nothing to estimate.
bool Prepare(const FitDescription& fit, const ResidualOptions& residual, BlockCovariance* c) {
  if (!fit.IsValid(&c->message) || !residual.IsValid(&c->message)) return false;
  c->values = fit.Values();
  const int n = static_cast<int>(c->values.size());
  c->standard_error.assign(n, 0.0);
  c->ci95_low.assign(n, 0.0);
  c->ci95_high.assign(n, 0.0);
  c->covariance.setZero(n, n);
  const std::vector<bool> fixed = fit.FixedEntries();
  for (int i = 0; i < n; ++i) {
    if (!fixed[i]) c->free.push_back(i);
  }
  c->num_free = static_cast<int>(c->free.size());
  int with_sigma = 0;
  for (const FitDataset& dataset : fit.datasets) {
    for (const Sweep* sweep : dataset.sweeps) {
      c->num_points += static_cast<int>(sweep->points.size());
      for (const DwellPoint& point : sweep->points) with_sigma += point.sigma.has_value();
    }
  }
  c->degrees_of_freedom = c->num_points - c->num_free;
  const bool use_sigma = residual.use_point_sigma;
  c->all_standardised = use_sigma && c->num_points > 0 && with_sigma == c->num_points;
  if (c->num_free == 0) {
    c->message = "every parameter is fixed: nothing was estimated";
    return false;
  }
  if (use_sigma && with_sigma > 0 && !c->all_standardised) {
    c->warnings.push_back(
        "only some points have a sigma: residuals mix standardised and raw units, so the noise "
        "estimate and the intervals are rough; give every point a sigma or none");
  }
  return true;
}

// s from the dwells' cost; false when it cannot be estimated.
bool EstimateNoise(BlockCovariance* c) {
  if (c->degrees_of_freedom > 0) c->reduced_chi_square = 2.0 * c->data_cost / c->degrees_of_freedom;
  if (c->all_standardised) {
    c->noise_sigma = 1.0;
  } else if (c->degrees_of_freedom > 0) {
    c->noise_sigma = std::sqrt(c->reduced_chi_square);
  } else {
    c->message = StringPrintf(
        "%d points for %d free parameters leave no degrees of freedom to estimate the noise: add "
        "dwells or fix parameters",
        c->num_points, c->num_free);
    return false;
  }
  return true;
}

// Normalises the columns of `r` (R of J, so the same column norms) into R_n
// and sets c->unit_scale and c->column_cosines (R_n^T R_n = J_n^T J_n);
// false for a column without effect.
bool NormaliseColumns(const FitDescription& fit, const std::vector<double>& tangent_scale,
                      Eigen::MatrixXd* r, BlockCovariance* c) {
  const int k = c->num_free;
  c->unit_scale.resize(k);
  for (int j = 0; j < k; ++j) {
    const int entry = c->free[j];
    const double norm = r->col(j).norm();
    if (!(norm > 0.0)) {
      // E.g. mu1 with mu1 = mu2 = 0: G depends on the damping through k1^2,
      // k2^2 and k1 k2 only, so its first derivative vanishes there.
      const std::string advice =
          c->values[entry] == 0.0
              ? " = 0 has no first-order effect on the fitted amplitudes, so no interval can be "
                "given; check the start and the data, or fix it"
              : " does not change the fitted amplitudes at all: fix it or add a sweep it affects";
      c->message = fit.EntryName(entry) + advice;
      return false;
    }
    r->col(j) /= norm;
    c->unit_scale[j] = tangent_scale[entry] / norm;
  }
  c->column_cosines = r->transpose() * *r;
  return true;
}

// The collinearity of J_n from R_n (same singular values); false above
// kMaxCollinearity, with the null directions and their entries named.
bool CheckCollinearity(const FitDescription& fit, const Eigen::MatrixXd& r_normalised,
                       BlockCovariance* c) {
  const int k = c->num_free;
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(r_normalised, Eigen::ComputeFullV);
  const Eigen::VectorXd& singular = svd.singularValues();
  c->collinearity = singular[0] / singular[k - 1];
  if (c->collinearity <= kMaxCollinearity) return true;
  int rank = k;
  while (rank > 1 && !(singular[0] / singular[rank - 1] <= kMaxCollinearity)) --rank;
  c->null_space = svd.matrixV().rightCols(k - rank);
  std::string names;
  int involved = 0;
  for (int j = 0; j < k; ++j) {
    if (c->null_space.row(j).norm() < kNullDirectionShare) continue;
    names += (involved++ > 0 ? ", " : "") + fit.EntryName(c->free[j]);
  }
  c->message = StringPrintf(
      "%s cannot be told apart by these data: %d combination(s) of them are not determined; fix "
      "%d of them, add data that affect them differently, or a prior (collinearity %.3g, limit "
      "%.3g)",
      names.c_str(), k - rank, k - rank, c->collinearity, kMaxCollinearity);
  return false;
}

// `factor` (J^T J)^-1 by ceres::Covariance, in physical units, into
// c->covariance. Its problem holds a copy x of every entry stepping in the
// normalised units (ScaledSubsetManifold: x = x0 + unit_scale_j t_j) and one
// linear block r = M (x - x0) (ceres::NormalPrior), M's column of free entry
// j R_n.col(j) / unit_scale_j: its Jacobian in t is R_n, so Ceres inverts
// R_n^T R_n = J_n^T J_n and lifts it to the entries with the manifold's
// PlusJacobian.
bool ComputeCovariance(const FitDescription& fit, double factor,
                       const Eigen::MatrixXd& r_normalised, BlockCovariance* c) {
  const int n = fit.NumEntries();
  const int k = c->num_free;
  const std::vector<bool> fixed = fit.FixedEntries();
  std::vector<double> unit(n, 1.0);  // unused for fixed entries
  ceres::Matrix m = ceres::Matrix::Zero(k, n);
  for (int j = 0; j < k; ++j) {
    unit[c->free[j]] = c->unit_scale[j];
    m.col(c->free[j]) = r_normalised.col(j) / c->unit_scale[j];
  }
  std::vector<double> x = c->values;
  const ceres::Vector x0 = Eigen::Map<const ceres::Vector>(c->values.data(), n);
  // The problem's own context: Ceres' covariance starts its one thread
  // there (options.num_threads), joined with the problem.
  ceres::Problem problem;
  problem.AddParameterBlock(x.data(), n, new ScaledSubsetManifold(unit, fixed));
  problem.AddResidualBlock(new ceres::NormalPrior(m, x0), nullptr, x.data());

  ceres::Covariance::Options options;
  options.algorithm_type = ceres::DENSE_SVD;
  options.min_reciprocal_condition_number = 1.0 / (kMaxCollinearity * kMaxCollinearity);
  options.null_space_rank = 0;  // rank deficient: fail, never truncate
  ceres::Covariance covariance(options);
  const std::vector<const double*> blocks = {x.data()};
  Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> inverse(n, n);
  if (!covariance.Compute(blocks, &problem) ||
      !covariance.GetCovarianceMatrix(blocks, inverse.data()) || !inverse.allFinite()) {
    return false;
  }
  c->covariance = factor * inverse;
  return true;
}

void SetIntervals(BlockCovariance* c) {
  c->interval_quantile = IntervalQuantile(c->all_standardised, c->degrees_of_freedom);
  IntervalsFromCovariance(c);
  c->available = true;
  c->message = StringPrintf(
      "%d points, %d free parameters, %d degrees of freedom; noise sigma %.3g (%s); "
      "collinearity %.3g",
      c->num_points, c->num_free, c->degrees_of_freedom, c->noise_sigma,
      c->all_standardised ? "point sigmas given" : "estimated from the residuals", c->collinearity);
  if (c->caller_residuals > 0) {
    c->message += StringPrintf("; with %d residual(s) of the caller's", c->caller_residuals);
  }
}

}  // namespace

double IntervalQuantile(bool noise_known, int degrees_of_freedom, double confidence) {
  const double p = 0.5 * (1.0 + confidence);
  if (noise_known) return boost::math::quantile(boost::math::normal_distribution<double>(), p);
  return boost::math::quantile(boost::math::students_t_distribution<double>(degrees_of_freedom), p);
}

double SimultaneousIntervalQuantile(bool noise_known, int degrees_of_freedom, int count,
                                    double confidence) {
  return IntervalQuantile(noise_known, degrees_of_freedom,
                          std::pow(confidence, 1.0 / static_cast<double>(count)));
}

void IntervalsFromCovariance(BlockCovariance* c) {
  for (size_t i = 0; i < c->values.size(); ++i) c->ci95_low[i] = c->ci95_high[i] = c->values[i];
  for (int i : c->free) {
    c->standard_error[i] = std::sqrt(std::max(c->covariance(i, i), 0.0));
    c->ci95_low[i] = c->values[i] - c->interval_quantile * c->standard_error[i];
    c->ci95_high[i] = c->values[i] + c->interval_quantile * c->standard_error[i];
  }
}

bool BlockCovarianceOptions::IsValid(std::string* error) const {
  if (chunk_rows >= 1) return true;
  *error =
      StringPrintf("BlockCovarianceOptions::chunk_rows is %d: it must be at least 1", chunk_rows);
  return false;
}

BlockCovariance EstimateBlockCovariance(const FitDescription& fit, const ResidualOptions& residual,
                                        const BlockCovarianceOptions& options) {
  BlockCovariance c;
  if (!options.IsValid(&c.message)) return Unavailable(c, c.message);
  if (!Prepare(fit, residual, &c)) return Unavailable(c, c.message);
  const std::vector<double*> blocks = FreeBlocks(fit);

  // The dwells alone: their cost gives the noise.
  std::unique_ptr<StageProblem> problem = AssembleDataProblem(fit, residual, 1.0, false);
  Eigen::MatrixXd r;  // R of J = Q R, k x k
  if (!FactorJacobian(problem->dwell_problem(), problem->dwell_blocks(), blocks, c.num_free,
                      options.chunk_rows, &c.data_cost, &r)) {
    return Unavailable(c, "the model cannot be evaluated at the estimate on every fitted dwell");
  }
  c.evaluated = true;
  if (!EstimateNoise(&c)) return Unavailable(c, c.message);

  // With the caller's residual blocks: the dwells weighted by 1/s beside them.
  double factor = c.noise_sigma * c.noise_sigma;
  if (fit.add_residuals && !(c.noise_sigma > 0.0)) {
    return Unavailable(c,
                       "the dwells fit exactly (noise sigma 0): there is no scale to weigh them "
                       "against the caller's residual blocks");
  }
  if (fit.add_residuals) {
    problem.reset();  // one problem of the dwells at a time
    problem = AssembleDataProblem(fit, residual, 1.0 / c.noise_sigma, true);
    std::vector<ceres::ResidualBlockId> rows = problem->dwell_blocks();
    for (ceres::ResidualBlockId id : problem->caller_blocks()) {
      rows.push_back(id);
      c.caller_residuals +=
          problem->problem()->GetCostFunctionForResidualBlock(id)->num_residuals();
    }
    double cost = 0.0;
    if (!FactorJacobian(problem->problem(), rows, blocks, c.num_free, options.chunk_rows, &cost,
                        &r)) {
      return Unavailable(c, "the caller's residual blocks cannot be evaluated at the estimate");
    }
    factor = 1.0;
  }
  problem.reset();
  if (!NormaliseColumns(fit, TangentScale(c.values), &r, &c) || !CheckCollinearity(fit, r, &c)) {
    return Unavailable(c, c.message);
  }
  if (!ComputeCovariance(fit, factor, r, &c)) {
    return Unavailable(c, StringPrintf("the covariance could not be computed (collinearity %.3g)",
                                       c.collinearity));
  }
  SetIntervals(&c);
  return c;
}

}  // namespace dwellfit
