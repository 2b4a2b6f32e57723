#include "dwellfit/estimator/studies/model_selection_predictions.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "Eigen/Dense"
#include "dwellfit/estimator/analysis/sweep_prediction.h"
#include "dwellfit/residuals/model/stable_root.h"

namespace dwellfit {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
// The 0.975 quantile of the standard normal.
constexpr double kZ95 = 1.959963984540054;
// Relative step of the central differences (see Step).
constexpr double kRelativeStep = 1e-5;

// The values `PredictHeldOut` predicts under `p`, in its order: each
// measured jump of a frequency sweep (Hz; NaN when the model lacks the
// fold), then the upper-branch amplitude when `dwells` is not empty.
std::vector<double> Quantities(const ParameterVector& p, const Sweep& sweep,
                               const std::vector<int>& dwells) {
  std::vector<double> values;
  if (sweep.kind == SweepKind::kFrequency) {
    for (const PredictedJump& jump : PredictJumps(p, sweep)) {
      if (!jump.measured) continue;
      values.push_back(jump.exists ? RadPerSecondToHz(jump.control) : kNaN);
    }
  }
  if (!dwells.empty()) {
    double sum = 0.0;
    for (int i : dwells) {
      const DwellPoint& point = sweep.points[i];
      sum += ModelAmplitudeNear(p, point.drive_frequency_rad_s, point.a_base, point.branch,
                                point.amplitude)
                 .a;
    }
    values.push_back(sum / static_cast<double>(dwells.size()));
  }
  return values;
}

// The central-difference step of parameter j at p: kRelativeStep of its
// magnitude, or 1e-6 for a parameter at 0 (delta, mu2: their effect is
// linear near 0, so the step's size hardly matters).
double Step(const ParameterVector& p, int j) {
  const double magnitude = std::abs(p[j]);
  return magnitude > 0.0 ? kRelativeStep * magnitude : 1e-6;
}

}  // namespace

std::vector<int> UpperBranchDwells(const Sweep& sweep) {
  std::vector<int> dwells;
  if (sweep.kind != SweepKind::kFrequency || sweep.direction != SweepDirection::kUp) return dwells;
  const auto down = std::find_if(sweep.jumps.begin(), sweep.jumps.end(), [](const JumpBracket& j) {
    return j.kind == JumpKind::kJumpDown;
  });
  if (down == sweep.jumps.end() || sweep.points.empty()) return dwells;
  double peak = 0.0;
  for (const DwellPoint& point : sweep.points) peak = std::max(peak, point.amplitude);
  const int last = std::min<int>(down->index_before, static_cast<int>(sweep.points.size()) - 1);
  for (int i = 0; i <= last; ++i) {
    if (sweep.points[i].amplitude > 0.5 * peak) dwells.push_back(i);
  }
  return dwells;
}

std::vector<HeldOutPrediction> PredictHeldOut(const Sweep& sweep, const ParameterVector& parameters,
                                              bool usable, const ParameterMatrix* covariance,
                                              const std::array<bool, kNumParameters>& fixed) {
  std::vector<HeldOutPrediction> predictions;
  const std::vector<int> dwells = UpperBranchDwells(sweep);
  if (sweep.kind == SweepKind::kFrequency) {
    for (const JumpBracket& jump : sweep.jumps) {
      HeldOutPrediction p;
      p.sweep = sweep.Name();
      p.quantity =
          jump.kind == JumpKind::kJumpDown ? HeldOutQuantity::kJumpDown : HeldOutQuantity::kJumpUp;
      p.measured = RadPerSecondToHz(jump.centre());
      predictions.push_back(p);
    }
  }
  if (!dwells.empty()) {
    HeldOutPrediction p;
    p.sweep = sweep.Name();
    p.quantity = HeldOutQuantity::kUpperBranchAmplitude;
    double sum = 0.0;
    for (int i : dwells) sum += sweep.points[i].amplitude;
    p.measured = sum / static_cast<double>(dwells.size());
    predictions.push_back(p);
  }
  if (!usable) {
    for (HeldOutPrediction& p : predictions) p.predicted = p.half_width = kNaN;
    return predictions;
  }
  const std::vector<double> values = Quantities(parameters, sweep, dwells);
  std::vector<double> variance(values.size(), 0.0);
  if (covariance != nullptr) {
    // g_q = d q / d p_j over the free parameters; s_p^2 = g^T C g.
    std::vector<std::array<double, kNumParameters>> gradient(values.size());
    for (auto& g : gradient) g.fill(0.0);
    for (int j = 0; j < kNumParameters; ++j) {
      if (fixed[j] || (*covariance)(j, j) <= 0.0) continue;
      const double h = Step(parameters, j);
      ParameterVector plus = parameters, minus = parameters;
      plus[j] += h;
      minus[j] -= h;
      const std::vector<double> up = Quantities(plus, sweep, dwells);
      const std::vector<double> down = Quantities(minus, sweep, dwells);
      for (std::size_t q = 0; q < values.size(); ++q) {
        const double derivative = (up[q] - down[q]) / (2.0 * h);
        gradient[q][j] = std::isfinite(derivative) ? derivative : 0.0;
      }
    }
    for (std::size_t q = 0; q < values.size(); ++q) {
      for (int i = 0; i < kNumParameters; ++i) {
        for (int j = 0; j < kNumParameters; ++j) {
          variance[q] += gradient[q][i] * (*covariance)(i, j) * gradient[q][j];
        }
      }
    }
  }
  for (std::size_t q = 0; q < predictions.size() && q < values.size(); ++q) {
    predictions[q].predicted = values[q];
    predictions[q].parameter_sd = std::sqrt(std::max(0.0, variance[q]));
  }
  return predictions;
}

namespace {

// The pseudo-inverse of a symmetric positive semi-definite matrix.
Eigen::MatrixXd PseudoInverse(const Eigen::MatrixXd& m) {
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen(m);
  const Eigen::VectorXd& values = eigen.eigenvalues();
  const double cutoff = 1e-12 * values.cwiseAbs().maxCoeff();
  Eigen::VectorXd inverse = Eigen::VectorXd::Zero(values.size());
  for (int i = 0; i < values.size(); ++i) {
    if (values[i] > cutoff) inverse[i] = 1.0 / values[i];
  }
  return eigen.eigenvectors() * inverse.asDiagonal() * eigen.eigenvectors().transpose();
}

bool Enforces(const IdentificationOptions& options, JumpKind kind) {
  const BifurcationRangeOptions& range = options.solve.penalties.bifurcation_range;
  const JumpTarget target =
      kind == JumpKind::kJumpDown ? JumpTarget::kFrequencyJumpDown : JumpTarget::kFrequencyJumpUp;
  return range.enabled &&
         std::find(range.enforce.begin(), range.enforce.end(), target) != range.enforce.end();
}

}  // namespace

ParameterMatrix PredictionCovariance(const ParameterMatrix& data_only,
                                     const std::vector<const Sweep*>& fitted,
                                     const IdentificationOptions& options,
                                     const ParameterVector& parameters) {
  std::vector<int> free;
  for (int j = 0; j < kNumParameters; ++j) {
    if (data_only(j, j) > 0.0) free.push_back(j);
  }
  const int k = static_cast<int>(free.size());
  if (k == 0) return data_only;
  // Scaled coordinates: q_j = p_j / d_j, d_j = sqrt(C_d,jj).
  Eigen::VectorXd d(k);
  Eigen::MatrixXd scaled(k, k);
  for (int a = 0; a < k; ++a) d[a] = std::sqrt(data_only(free[a], free[a]));
  for (int a = 0; a < k; ++a) {
    for (int b = 0; b < k; ++b) scaled(a, b) = data_only(free[a], free[b]) / (d[a] * d[b]);
  }
  Eigen::MatrixXd information = PseudoInverse(scaled);
  int observations = 0;
  for (const Sweep* sweep : fitted) {
    if (sweep->kind != SweepKind::kFrequency) continue;
    for (std::size_t q = 0; q < sweep->jumps.size(); ++q) {
      const JumpBracket& jump = sweep->jumps[q];
      if (!Enforces(options, jump.kind)) continue;
      const double h_k = RadPerSecondToHz(jump.half_width());
      Eigen::VectorXd g(k);
      bool finite = h_k > 0.0;
      for (int a = 0; a < k && finite; ++a) {
        // d f_k / d q_a = d_a d f_k / d p_j, by central differences in p_j.
        const int j = free[a];
        const double h = Step(parameters, j);
        ParameterVector plus = parameters, minus = parameters;
        plus[j] += h;
        minus[j] -= h;
        const std::vector<double> up = Quantities(plus, *sweep, {});
        const std::vector<double> down = Quantities(minus, *sweep, {});
        g[a] = d[a] * (up[q] - down[q]) / (2.0 * h);
        finite = std::isfinite(g[a]);
      }
      if (!finite) continue;
      information += g * g.transpose() / (h_k * h_k);
      ++observations;
    }
  }
  if (observations == 0) return data_only;
  const Eigen::MatrixXd combined = PseudoInverse(information);
  ParameterMatrix covariance = ParameterMatrix::Zero();
  for (int a = 0; a < k; ++a) {
    for (int b = 0; b < k; ++b) covariance(free[a], free[b]) = combined(a, b) * d[a] * d[b];
  }
  return covariance;
}

PredictionErrors ErrorsOf(const std::vector<HeldOutPrediction>& predictions, double relative_rms) {
  PredictionErrors errors;
  for (const HeldOutPrediction& p : predictions) {
    const bool known = std::isfinite(p.predicted);
    const double percent = known ? std::abs(p.ErrorPercent()) : 100.0;
    const double hz = known ? std::abs(p.predicted - p.measured) : p.measured;
    switch (p.quantity) {
      case HeldOutQuantity::kJumpDown:
        errors.jump_down_percent.push_back(percent);
        errors.jump_down_hz.push_back(hz);
        break;
      case HeldOutQuantity::kJumpUp:
        errors.jump_up_percent.push_back(percent);
        errors.jump_up_hz.push_back(hz);
        break;
      case HeldOutQuantity::kUpperBranchAmplitude:
        errors.upper_branch_percent.push_back(percent);
        break;
    }
  }
  if (std::isfinite(relative_rms)) errors.relative_rms.push_back(relative_rms);
  return errors;
}

double HeldOutPrediction::ErrorPercent() const {
  return std::isfinite(predicted) ? 100.0 * (predicted - measured) / measured : kNaN;
}

const char* HeldOutQuantityName(HeldOutQuantity quantity) {
  switch (quantity) {
    case HeldOutQuantity::kJumpDown:
      return "jump-down";
    case HeldOutQuantity::kJumpUp:
      return "jump-up";
    case HeldOutQuantity::kUpperBranchAmplitude:
      return "upper-branch amplitude";
  }
  return "?";
}

void AddPredictionIntervals(VariantResult* result) {
  for (std::size_t level = 0; level < result->folds.size(); ++level) {
    for (HeldOutPrediction& p : result->folds[level].predictions) {
      if (!std::isfinite(p.predicted)) {
        p.half_width = kNaN;
        p.inside = false;
        continue;
      }
      // s_m: RMS relative error of the same quantity at the other levels.
      double sum = 0.0;
      int count = 0;
      for (std::size_t other = 0; other < result->folds.size(); ++other) {
        if (other == level) continue;
        for (const HeldOutPrediction& q : result->folds[other].predictions) {
          if (q.quantity != p.quantity || !std::isfinite(q.predicted)) continue;
          const double relative = (q.predicted - q.measured) / q.measured;
          sum += relative * relative;
          ++count;
        }
      }
      p.model_sd = count > 0 ? std::abs(p.predicted) * std::sqrt(sum / count) : 0.0;
      p.half_width = kZ95 * std::hypot(p.parameter_sd, p.model_sd);
      p.inside = std::abs(p.predicted - p.measured) <= p.half_width;
    }
  }
  struct Entry {
    HeldOutQuantity quantity;
    IntervalCoverage* coverage;
  };
  for (const Entry& entry :
       {Entry{HeldOutQuantity::kJumpDown, &result->jump_down_coverage},
        Entry{HeldOutQuantity::kJumpUp, &result->jump_up_coverage},
        Entry{HeldOutQuantity::kUpperBranchAmplitude, &result->upper_branch_coverage}}) {
    IntervalCoverage coverage;
    std::vector<double> widths, percents;
    for (const CrossValidationFold& fold : result->folds) {
      for (const HeldOutPrediction& p : fold.predictions) {
        if (p.quantity != entry.quantity) continue;
        ++coverage.total;
        coverage.inside += p.inside;
        if (!std::isfinite(p.half_width)) continue;
        widths.push_back(p.half_width);
        percents.push_back(100.0 * p.half_width / std::abs(p.predicted));
      }
    }
    coverage.median_half_width = MedianOf(widths);
    coverage.median_half_width_percent = MedianOf(percents);
    *entry.coverage = coverage;
  }
}

}  // namespace dwellfit
