#include "dwellfit/estimator/analysis/parameter_uncertainty.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "Eigen/SVD"
#include "boost/math/distributions/normal.hpp"
#include "boost/math/distributions/students_t.hpp"
#include "ceres/covariance.h"
#include "ceres/crs_matrix.h"
#include "ceres/problem.h"
#include "dwellfit/estimator/fit/problem_builder.h"
#include "dwellfit/estimator/fit/scaled_subset_manifold.h"
#include "dwellfit/residuals/model/response_model.h"
#include "dwellfit/residuals/model/stable_root.h"

namespace dwellfit {
namespace {

// printf-style formatting into a std::string.
template <typename... Args>
std::string Format(const char* format, Args... args) {
  char buffer[512];
  std::snprintf(buffer, sizeof(buffer), format, args...);
  return buffer;
}

// A tangent coordinate's entry of a null direction smaller than this (the
// direction has unit length) does not implicate its parameter.
constexpr double kNullDirectionShare = 0.1;

// The data residuals of the vertical-error fit on a caller-owned block.
struct DataProblem {
  std::unique_ptr<ceres::Problem> problem;
  std::vector<int> free;  // ambient index of each tangent coordinate
  ParameterVector scale;  // physical change per tangent unit
  int num_points = 0;
  bool all_standardised = false;  // every residual divided by its point's sigma
  bool some_standardised = false;
};

DataProblem BuildDataProblem(const std::vector<const Sweep*>& fitted,
                             const IdentificationOptions& options, double* parameters) {
  DataProblem data;
  ProblemBuilderOptions builder_options;
  builder_options.residual = ResidualKind::kVertical;
  builder_options.residual_options = options.residual;
  builder_options.fixed = options.fixed;
  // One tangent unit per parameter magnitude (1 for a zero value).
  ParameterVector scale;
  for (int i = 0; i < kNumParameters; ++i) {
    scale[i] = std::abs(parameters[i]) > 0.0 ? std::abs(parameters[i]) : 1.0;
  }
  builder_options.scale = scale;
  data.scale = scale;
  const ProblemBuilder builder(builder_options);
  data.problem = std::make_unique<ceres::Problem>();
  int with_sigma = 0;
  for (const Sweep* sweep : fitted) {
    data.num_points += builder.AddSweep(*sweep, parameters, data.problem.get());
    for (const DwellPoint& point : sweep->points) with_sigma += point.sigma.has_value();
  }
  const bool use_sigma = options.residual.use_point_sigma;
  data.all_standardised = use_sigma && data.num_points > 0 && with_sigma == data.num_points;
  data.some_standardised = use_sigma && with_sigma > 0;
  for (int i = 0; i < kNumParameters; ++i) {
    if (!options.fixed[i]) data.free.push_back(i);
  }
  if (data.num_points > 0) builder.ConfigureParameters(parameters, data.problem.get());
  return data;
}

// Cost F = (1/2) sum r_i^2 and the tangent-space Jacobian (n x k) of `data`.
bool EvaluateJacobian(DataProblem* data, double* cost, Eigen::MatrixXd* jacobian) {
  ceres::CRSMatrix crs;
  if (!data->problem->Evaluate(ceres::Problem::EvaluateOptions(), cost, nullptr, nullptr, &crs)) {
    return false;
  }
  jacobian->setZero(crs.num_rows, crs.num_cols);
  for (int row = 0; row < crs.num_rows; ++row) {
    for (int k = crs.rows[row]; k < crs.rows[row + 1]; ++k) {
      (*jacobian)(row, crs.cols[k]) = crs.values[k];
    }
  }
  return std::isfinite(*cost) && jacobian->allFinite();
}

std::string JoinNames(const std::vector<int>& parameters) {
  std::string joined;
  for (size_t i = 0; i < parameters.size(); ++i) {
    if (i > 0) joined += i + 1 == parameters.size() ? " and " : ", ";
    joined += ParameterName(parameters[i]);
  }
  return joined;
}

bool IsPair(int a, int b, int first, int second) {
  return (a == first && b == second) || (a == second && b == first);
}

// What to do about two free parameters the sweeps hardly separate.
std::string PairAdvice(int a, int b) {
  if (IsPair(a, b, kDelta, kAlpha)) {
    return "fix delta (fixed: [delta]) or add a sweep far from this frequency band";
  }
  if (IsPair(a, b, kMu1, kMu2)) {
    return "the damping split is weakly determined: add a sweep at a lower or higher level";
  }
  return "add a sweep that excites them differently (another level or frequency band), or fix "
         "one of them";
}

// The plain-words account of what the sweeps cannot see. `null_space` (k x r)
// holds orthonormal null directions of the column-normalised Jacobian
// `columns`; `unit_scale` is the physical change of each tangent coordinate
// per unit. A parameter is implicated when its row of `null_space` has a norm
// of at least kNullDirectionShare (the row norms do not depend on which basis
// of the null space the SVD returned).
std::string DescribeNullSpace(const Eigen::MatrixXd& null_space, const Eigen::VectorXd& unit_scale,
                              const std::vector<int>& free, const Eigen::MatrixXd& columns) {
  std::vector<int> involved;
  std::vector<int> tangent;
  for (int j = 0; j < null_space.rows(); ++j) {
    if (null_space.row(j).norm() >= kNullDirectionShare) {
      involved.push_back(free[j]);
      tangent.push_back(j);
    }
  }
  const int rank_loss = static_cast<int>(null_space.cols());
  std::string text = JoinNames(involved) + " cannot be told apart by these sweeps";
  if (rank_loss != 1 || involved.size() != 2) {
    return text + Format(
                      ": %d combination(s) of them are not determined; fix %d of them or add "
                      "sweeps at other levels and frequencies",
                      rank_loss, rank_loss);
  }
  // Two parameters, one lost direction: their Jacobian columns are parallel
  // (|cosine| = 1), and moving both along the null direction leaves the fit
  // unchanged, so their estimates correlate at the sign of that direction.
  const double cosine = std::abs(columns.col(tangent[0]).dot(columns.col(tangent[1])));
  const double sign = null_space(tangent[0], 0) * null_space(tangent[1], 0) > 0.0 ? 1.0 : -1.0;
  text +=
      Format(" (a change of one is undone by a change of the other: their correlation is %+.3f)",
             sign * cosine);
  if (IsPair(involved[0], involved[1], kDelta, kAlpha)) {
    // Along the null direction alpha - (2/3) delta Omega^2 stays constant:
    // d alpha = (2/3) Omega^2 d delta, which gives the Omega the data fix.
    const int d = involved[0] == kDelta ? tangent[0] : tangent[1];
    const int a = involved[0] == kAlpha ? tangent[0] : tangent[1];
    const double omega_squared =
        1.5 * (null_space(a, 0) * unit_scale[a]) / (null_space(d, 0) * unit_scale[d]);
    if (omega_squared > 0.0 && std::isfinite(omega_squared)) {
      text += Format(": only alpha - (2/3) delta Omega^2 at Omega = 2 pi %.4g Hz is determined",
                     RadPerSecondToHz(std::sqrt(omega_squared)));
    }
  }
  return text + "; " + PairAdvice(involved[0], involved[1]);
}

// The fitted dwells whose measured branch does not reach their a_base at
// `parameters` (RootStatus::kBranchEnd): the vertical error then measures
// them from the fold where that branch ends, and the cost has a kink as the
// fold passes a dwell. Returns their number and names up to three of them.
int DwellsPastTheirBranchEnd(const std::vector<const Sweep*>& fitted,
                             const ParameterVector& parameters, std::string* examples) {
  int count = 0;
  for (const Sweep* sweep : fitted) {
    for (const DwellPoint& point : sweep->points) {
      const auto k = ResponseCoefficients<double>::FromParameters(parameters.data(),
                                                                  point.drive_frequency_rad_s);
      if (SolveStableRoot(k, point.a_base, point.branch, point.amplitude).status !=
          RootStatus::kBranchEnd) {
        continue;
      }
      if (++count > 3) continue;
      if (!examples->empty()) *examples += ", ";
      *examples += sweep->kind == SweepKind::kFrequency
                       ? Format("%s at %.4g Hz", sweep->Name().c_str(),
                                RadPerSecondToHz(point.drive_frequency_rad_s))
                       : Format("%s at a_base %.4g", sweep->Name().c_str(), point.a_base);
    }
  }
  return count;
}

// Student's t (s estimated) or the normal (s known) 0.975 quantile.
double IntervalQuantile(bool noise_known, int degrees_of_freedom) {
  if (noise_known) return boost::math::quantile(boost::math::normal_distribution<double>(), 0.975);
  return boost::math::quantile(boost::math::students_t_distribution<double>(degrees_of_freedom),
                               0.975);
}

ParameterUncertainty Unavailable(ParameterUncertainty u, const std::string& message) {
  ParameterUncertainty out;
  out.available = false;
  out.message = message;
  out.num_points = u.num_points;
  out.num_free = u.num_free;
  out.degrees_of_freedom = u.degrees_of_freedom;
  out.noise_sigma = std::isfinite(u.noise_sigma) ? u.noise_sigma : 0.0;
  out.reduced_chi_square = std::isfinite(u.reduced_chi_square) ? u.reduced_chi_square : 0.0;
  out.collinearity = std::isnan(u.collinearity) ? 0.0 : u.collinearity;
  out.omega_ref_rad_s = u.omega_ref_rad_s;
  out.effective_nonlinearity = u.effective_nonlinearity;
  out.dwells_past_branch_end = u.dwells_past_branch_end;
  out.warnings = u.warnings;
  return out;
}

}  // namespace

ParameterUncertainty EstimateUncertainty(const std::vector<const Sweep*>& fitted,
                                         const IdentificationOptions& options,
                                         const ParameterVector& estimate, double omega_ref_rad_s) {
  ParameterUncertainty u;
  if (!(omega_ref_rad_s > 0.0)) omega_ref_rad_s = estimate[kOmega];
  u.omega_ref_rad_s = omega_ref_rad_s;
  u.effective_nonlinearity = EffectiveNonlinearity(estimate, omega_ref_rad_s);
  if (!std::isfinite(u.effective_nonlinearity)) u.effective_nonlinearity = 0.0;

  ParameterVector parameters = estimate;  // the block the problem reads
  DataProblem data = BuildDataProblem(fitted, options, parameters.data());
  u.num_points = data.num_points;
  u.num_free = static_cast<int>(data.free.size());
  u.degrees_of_freedom = u.num_points - u.num_free;
  if (u.num_points == 0) return Unavailable(u, "no dwell points were fitted");
  if (u.num_free == 0) return Unavailable(u, "every parameter is fixed: nothing was estimated");
  if (data.some_standardised && !data.all_standardised) {
    u.warnings.push_back(
        "only some points have a sigma: residuals mix standardised and raw units, so the noise "
        "estimate and the intervals are rough; give every point a sigma or none");
  }

  // Residuals and J at the estimate, in the builder's tangent coordinates.
  double cost = 0.0;
  Eigen::MatrixXd jacobian;
  if (!EvaluateJacobian(&data, &cost, &jacobian)) {
    return Unavailable(u, "the model cannot be evaluated at the estimate on every fitted dwell");
  }

  std::string examples;
  u.dwells_past_branch_end = DwellsPastTheirBranchEnd(fitted, estimate, &examples);
  if (u.dwells_past_branch_end > 0) {
    u.warnings.push_back(Format(
        "%d fitted dwell(s) lie past the end of their branch at the estimate (%s%s): the model's "
        "fold falls short of where they were measured, the fit is not smooth there and the "
        "intervals may be too narrow; check the branch labels or enable the branch-stability "
        "penalty",
        u.dwells_past_branch_end, examples.c_str(), u.dwells_past_branch_end > 3 ? ", ..." : ""));
  }

  // Noise: s^2 = 2 F / (n - k) unless the residuals are standardised (s = 1).
  if (u.degrees_of_freedom > 0) u.reduced_chi_square = 2.0 * cost / u.degrees_of_freedom;
  if (data.all_standardised) {
    u.noise_sigma = 1.0;
  } else if (u.degrees_of_freedom > 0) {
    u.noise_sigma = std::sqrt(u.reduced_chi_square);
  } else {
    return Unavailable(u, Format("%d points for %d free parameters leave no degrees of freedom to "
                                 "estimate the noise: add dwells or fix parameters",
                                 u.num_points, u.num_free));
  }

  // Column-normalise: tangent coordinate j then moves the residuals by a unit
  // vector. unit_scale_j is the physical change per unit of coordinate j.
  const int k = u.num_free;
  Eigen::VectorXd unit_scale(k);
  Eigen::MatrixXd columns = jacobian;
  for (int j = 0; j < k; ++j) {
    const int i = data.free[j];
    const double norm = jacobian.col(j).norm();
    if (!(norm > 0.0)) {
      // E.g. mu1 with mu1 = mu2 = 0: G depends on the damping through k1^2,
      // k2^2 and k1 k2 only, so its first derivative vanishes there.
      const std::string name = ParameterName(i);
      const std::string advice =
          estimate[i] == 0.0
              ? " = 0 has no first-order effect on the fitted amplitudes, so no interval can be "
                "given; check the start and the data, or fix it"
              : " does not change the fitted amplitudes at all: fix it or add a sweep it affects";
      return Unavailable(u, name + advice);
    }
    columns.col(j) /= norm;
    unit_scale[j] = data.scale[i] / norm;
  }
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(columns, Eigen::ComputeThinV);
  const Eigen::VectorXd& singular = svd.singularValues();
  u.collinearity = singular[0] / singular[k - 1];
  if (!(u.collinearity <= kMaxCollinearity)) {
    int rank = k;
    while (rank > 1 && !(singular[0] / singular[rank - 1] <= kMaxCollinearity)) --rank;
    const Eigen::MatrixXd null_space = svd.matrixV().rightCols(k - rank);
    return Unavailable(
        u, DescribeNullSpace(null_space, unit_scale, data.free, columns) +
               Format(" (collinearity %.3g, limit %.3g)", u.collinearity, kMaxCollinearity));
  }

  // (J^T J)^-1 by ceres::Covariance on the column-normalised problem; its
  // ambient block is in physical units.
  ParameterVector manifold_scale;
  manifold_scale.fill(1.0);
  for (int j = 0; j < k; ++j) manifold_scale[data.free[j]] = unit_scale[j];
  data.problem->SetManifold(parameters.data(),
                            new ScaledSubsetManifold(manifold_scale, options.fixed));
  ceres::Covariance::Options covariance_options;
  covariance_options.algorithm_type = ceres::DENSE_SVD;
  covariance_options.min_reciprocal_condition_number = 1.0 / (kMaxCollinearity * kMaxCollinearity);
  covariance_options.null_space_rank = 0;  // rank deficient: fail, never truncate
  ceres::Covariance covariance(covariance_options);
  const std::vector<const double*> blocks = {parameters.data()};
  Eigen::Matrix<double, kNumParameters, kNumParameters, Eigen::RowMajor> inverse;
  if (!covariance.Compute(blocks, data.problem.get()) ||
      !covariance.GetCovarianceBlock(parameters.data(), parameters.data(), inverse.data()) ||
      !inverse.allFinite()) {
    return Unavailable(
        u, Format("the covariance could not be computed (collinearity %.3g)", u.collinearity));
  }
  u.covariance = u.noise_sigma * u.noise_sigma * inverse;

  // Standard errors, intervals, correlations.
  u.interval_quantile = IntervalQuantile(data.all_standardised, u.degrees_of_freedom);
  for (int i = 0; i < kNumParameters; ++i) {
    u.ci95_low[i] = u.ci95_high[i] = estimate[i];
    if (options.fixed[i]) continue;
    u.standard_error[i] = std::sqrt(std::max(u.covariance(i, i), 0.0));
    u.ci95_low[i] = estimate[i] - u.interval_quantile * u.standard_error[i];
    u.ci95_high[i] = estimate[i] + u.interval_quantile * u.standard_error[i];
  }
  for (int a : data.free) {
    for (int b : data.free) {
      const double denominator = u.standard_error[a] * u.standard_error[b];
      u.correlation(a, b) = a == b              ? 1.0
                            : denominator > 0.0 ? u.covariance(a, b) / denominator
                                                : 0.0;
    }
  }

  // alpha_e = alpha - (2/3) delta Omega_ref^2: variance g^T C g.
  Eigen::Matrix<double, kNumParameters, 1> gradient =
      Eigen::Matrix<double, kNumParameters, 1>::Zero();
  gradient[kDelta] = -(2.0 / 3.0) * omega_ref_rad_s * omega_ref_rad_s;
  gradient[kAlpha] = 1.0;
  u.effective_nonlinearity_standard_error =
      std::sqrt(std::max(gradient.dot(u.covariance * gradient), 0.0));
  u.effective_nonlinearity_ci95_low =
      u.effective_nonlinearity - u.interval_quantile * u.effective_nonlinearity_standard_error;
  u.effective_nonlinearity_ci95_high =
      u.effective_nonlinearity + u.interval_quantile * u.effective_nonlinearity_standard_error;

  // Warnings: weakly separated pairs, parameters held by their bound.
  for (size_t x = 0; x < data.free.size(); ++x) {
    for (size_t y = x + 1; y < data.free.size(); ++y) {
      const int a = data.free[x], b = data.free[y];
      const double rho = u.correlation(a, b);
      if (std::abs(rho) <= kCorrelationWarning) continue;
      std::string warning =
          Format("%s and %s correlate at %+.3f: ", ParameterName(a), ParameterName(b), rho);
      if (IsPair(a, b, kDelta, kAlpha)) {
        warning += Format(
            "delta and alpha are weakly separated by these sweeps, while alpha - (2/3) delta "
            "Omega_ref^2 = %.4g +/- %.2g is well determined; ",
            u.effective_nonlinearity, u.effective_nonlinearity_standard_error);
      }
      u.warnings.push_back(warning + PairAdvice(a, b));
    }
  }
  for (int i : data.free) {
    const bool bounded = i == kEtaE || i == kMu1 || i == kMu2;
    if (bounded && estimate[i] <= 0.0) {
      u.warnings.push_back(std::string(ParameterName(i)) +
                           " sits on its bound 0: the data pull it below zero, and its interval "
                           "ignores the bound");
    }
  }

  u.available = true;
  u.message = Format(
      "%d points, %d free parameters, %d degrees of freedom; noise sigma %.3g (%s); "
      "collinearity %.3g",
      u.num_points, u.num_free, u.degrees_of_freedom, u.noise_sigma,
      data.all_standardised ? "point sigmas given" : "estimated from the residuals",
      u.collinearity);
  if (!u.warnings.empty())
    u.message += Format("; %d warning(s)", static_cast<int>(u.warnings.size()));
  return u;
}

}  // namespace dwellfit
