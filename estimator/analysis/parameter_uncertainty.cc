#include "dwellfit/estimator/analysis/parameter_uncertainty.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "dwellfit/estimator/common/string_printf.h"
#include "dwellfit/estimator/fit/fit_description.h"
#include "dwellfit/residuals/model/response_model.h"
#include "dwellfit/residuals/model/stable_root.h"

namespace dwellfit {
namespace {

// A tangent coordinate's entry of a null direction smaller than this (the
// direction has unit length) does not implicate its parameter.
constexpr double kNullDirectionShare = 0.1;

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
    return text + StringPrintf(
                      ": %d combination(s) of them are not determined; fix %d of them or add "
                      "sweeps at other levels and frequencies",
                      rank_loss, rank_loss);
  }
  // Two parameters, one lost direction: their Jacobian columns are parallel
  // (|cosine| = 1), and moving both along the null direction leaves the fit
  // unchanged, so their estimates correlate at the sign of that direction.
  const double cosine = std::abs(columns.col(tangent[0]).dot(columns.col(tangent[1])));
  const double sign = null_space(tangent[0], 0) * null_space(tangent[1], 0) > 0.0 ? 1.0 : -1.0;
  text += StringPrintf(
      " (a change of one is undone by a change of the other: their correlation is %+.3f)",
      sign * cosine);
  if (IsPair(involved[0], involved[1], kDelta, kAlpha)) {
    // Along the null direction alpha - (2/3) delta Omega^2 stays constant:
    // d alpha = (2/3) Omega^2 d delta, which gives the Omega the data fix.
    const int d = involved[0] == kDelta ? tangent[0] : tangent[1];
    const int a = involved[0] == kAlpha ? tangent[0] : tangent[1];
    const double omega_squared =
        1.5 * (null_space(a, 0) * unit_scale[a]) / (null_space(d, 0) * unit_scale[d]);
    if (omega_squared > 0.0 && std::isfinite(omega_squared)) {
      text +=
          StringPrintf(": only alpha - (2/3) delta Omega^2 at Omega = 2 pi %.4g Hz is determined",
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
                       ? StringPrintf("%s at %.4g Hz", sweep->Name().c_str(),
                                      RadPerSecondToHz(point.drive_frequency_rad_s))
                       : StringPrintf("%s at a_base %.4g", sweep->Name().c_str(), point.a_base);
    }
  }
  return count;
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

// The covariance's counts, noise and collinearity in `u`.
void CopyCounts(const BlockCovariance& c, ParameterUncertainty* u) {
  u->num_points = c.num_points;
  u->num_free = c.num_free;
  u->degrees_of_freedom = c.degrees_of_freedom;
  u->noise_sigma = c.noise_sigma;
  u->reduced_chi_square = c.reduced_chi_square;
  u->collinearity = c.collinearity;
  u->warnings = c.warnings;
}

// Standard errors, intervals and correlations from the 6 x 6 covariance.
void CopyIntervals(const BlockCovariance& c, ParameterUncertainty* u) {
  u->interval_quantile = c.interval_quantile;
  u->covariance = c.covariance;
  for (int i = 0; i < kNumParameters; ++i) {
    u->standard_error[i] = c.standard_error[i];
    u->ci95_low[i] = c.ci95_low[i];
    u->ci95_high[i] = c.ci95_high[i];
  }
  for (int a : c.free) {
    for (int b : c.free) {
      const double denominator = u->standard_error[a] * u->standard_error[b];
      u->correlation(a, b) = a == b              ? 1.0
                             : denominator > 0.0 ? u->covariance(a, b) / denominator
                                                 : 0.0;
    }
  }
}

// alpha_e = alpha - (2/3) delta Omega_ref^2: variance g^T C g.
void SetEffectiveNonlinearity(ParameterUncertainty* u) {
  Eigen::Matrix<double, kNumParameters, 1> gradient =
      Eigen::Matrix<double, kNumParameters, 1>::Zero();
  gradient[kDelta] = -(2.0 / 3.0) * u->omega_ref_rad_s * u->omega_ref_rad_s;
  gradient[kAlpha] = 1.0;
  u->effective_nonlinearity_standard_error =
      std::sqrt(std::max(gradient.dot(u->covariance * gradient), 0.0));
  u->effective_nonlinearity_ci95_low =
      u->effective_nonlinearity - u->interval_quantile * u->effective_nonlinearity_standard_error;
  u->effective_nonlinearity_ci95_high =
      u->effective_nonlinearity + u->interval_quantile * u->effective_nonlinearity_standard_error;
}

// Warnings: weakly separated pairs, parameters held by their bound.
void AddPairAndBoundWarnings(const std::vector<int>& free, const ParameterVector& estimate,
                             ParameterUncertainty* u) {
  for (size_t x = 0; x < free.size(); ++x) {
    for (size_t y = x + 1; y < free.size(); ++y) {
      const int a = free[x], b = free[y];
      const double rho = u->correlation(a, b);
      if (std::abs(rho) <= kCorrelationWarning) continue;
      std::string warning =
          StringPrintf("%s and %s correlate at %+.3f: ", ParameterName(a), ParameterName(b), rho);
      if (IsPair(a, b, kDelta, kAlpha)) {
        warning += StringPrintf(
            "delta and alpha are weakly separated by these sweeps, while alpha - (2/3) delta "
            "Omega_ref^2 = %.4g +/- %.2g is well determined; ",
            u->effective_nonlinearity, u->effective_nonlinearity_standard_error);
      }
      u->warnings.push_back(warning + PairAdvice(a, b));
    }
  }
  for (int i : free) {
    const bool bounded = i == kEtaE || i == kMu1 || i == kMu2;
    if (bounded && estimate[i] <= 0.0) {
      u->warnings.push_back(std::string(ParameterName(i)) +
                            " sits on its bound 0: the data pull it below zero, and its interval "
                            "ignores the bound");
    }
  }
}

// The warning about fitted dwells past their branch's end, if any.
void WarnAboutDwellsPastTheirBranchEnd(const std::vector<const Sweep*>& fitted,
                                       const ParameterVector& estimate, ParameterUncertainty* u) {
  std::string examples;
  u->dwells_past_branch_end = DwellsPastTheirBranchEnd(fitted, estimate, &examples);
  if (u->dwells_past_branch_end == 0) return;
  u->warnings.push_back(StringPrintf(
      "%d fitted dwell(s) lie past the end of their branch at the estimate (%s%s): the model's "
      "fold falls short of where they were measured, the fit is not smooth there and the "
      "intervals may be too narrow; check the branch labels or enable the branch-stability "
      "penalty",
      u->dwells_past_branch_end, examples.c_str(), u->dwells_past_branch_end > 3 ? ", ..." : ""));
}

}  // namespace

ParameterUncertainty EstimateUncertainty(const std::vector<const Sweep*>& fitted,
                                         const IdentificationOptions& options,
                                         const ParameterVector& estimate, double omega_ref_rad_s) {
  ParameterUncertainty u;
  if (!(omega_ref_rad_s > 0.0)) omega_ref_rad_s = estimate[kNaturalFrequency];
  u.omega_ref_rad_s = omega_ref_rad_s;
  u.effective_nonlinearity = EffectiveNonlinearity(estimate, omega_ref_rad_s);
  if (!std::isfinite(u.effective_nonlinearity)) u.effective_nonlinearity = 0.0;

  ParameterVector parameters = estimate;  // the block the problem reads
  const FitDescription fit = SingleBlockFit(fitted, options.fixed, &parameters);
  const BlockCovariance c = EstimateBlockCovariance(fit, options.residual);
  CopyCounts(c, &u);
  if (c.evaluated) WarnAboutDwellsPastTheirBranchEnd(fitted, estimate, &u);
  if (!c.available) {
    // Entries the data cannot tell apart are named in the model's terms.
    const std::string message =
        c.null_space.cols() == 0
            ? c.message
            : DescribeNullSpace(c.null_space, c.unit_scale, c.free, c.columns) +
                  StringPrintf(" (collinearity %.3g, limit %.3g)", c.collinearity,
                               kMaxCollinearity);
    return Unavailable(u, message);
  }
  CopyIntervals(c, &u);
  SetEffectiveNonlinearity(&u);
  AddPairAndBoundWarnings(c.free, estimate, &u);
  u.available = true;
  u.message = c.message;
  if (!u.warnings.empty())
    u.message += StringPrintf("; %d warning(s)", static_cast<int>(u.warnings.size()));
  return u;
}

}  // namespace dwellfit
