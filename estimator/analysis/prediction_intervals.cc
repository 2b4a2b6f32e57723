#include "dwellfit/estimator/analysis/prediction_intervals.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>

#include "Eigen/Dense"
#include "dwellfit/estimator/analysis/sweep_prediction.h"
#include "dwellfit/estimator/common/name_table.h"
#include "dwellfit/estimator/fit/problem_builder.h"
#include "dwellfit/residuals/model/stable_root.h"

namespace dwellfit {

const char* const kPredictionIntervalRule =
    "predicted +/- 1.96 sqrt(s_p^2 + s_m^2): s_p the parameters' uncertainty by the delta method "
    "(the dwells-alone covariance with each enforced jump as an observation, sd its bracket's "
    "half-width), s_m the prediction times the RMS relative error of the same quantity at the "
    "other levels";

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
// Relative step of the central differences (see Derivatives).
constexpr double kRelativeStep = 1e-5;

// The values `PredictHeldOut` predicts under `p`, in its order: each
// measured jump of a frequency sweep (Hz; NaN when the model lacks the
// fold), then the upper-branch amplitude when `dwells` is not empty.
std::vector<double> Quantities(ModelForm form, const ParameterVector& p, const Sweep& sweep,
                               const std::vector<int>& dwells) {
  std::vector<double> values;
  if (sweep.kind == SweepKind::kFrequency) {
    for (const PredictedJump& jump : PredictJumps(form, p, sweep)) {
      if (!jump.measured) continue;
      values.push_back(jump.exists ? RadPerSecondToHz(jump.control) : kNaN);
    }
  }
  if (!dwells.empty()) {
    double sum = 0.0;
    for (int i : dwells) {
      const DwellPoint& point = sweep.points[i];
      sum += ModelAmplitudeNear(form, p, point.drive_frequency_rad_s, point.a_base, point.branch,
                                point.amplitude)
                 .a;
    }
    values.push_back(sum / static_cast<double>(dwells.size()));
  }
  return values;
}

// `scale` d Quantities / d p_j by central differences: step kRelativeStep of p_j's
// magnitude, or 1e-6 for a parameter at 0 (delta, mu2: their effect is
// linear near 0, so the step's size hardly matters).
std::vector<double> Derivatives(ModelForm form, const ParameterVector& p, int j, const Sweep& sweep,
                                const std::vector<int>& dwells, double scale = 1.0) {
  const double h = std::abs(p[j]) > 0.0 ? kRelativeStep * std::abs(p[j]) : 1e-6;
  ParameterVector plus = p, minus = p;
  plus[j] += h;
  minus[j] -= h;
  std::vector<double> up = Quantities(form, plus, sweep, dwells);
  const std::vector<double> down = Quantities(form, minus, sweep, dwells);
  for (std::size_t q = 0; q < up.size(); ++q) up[q] = scale * (up[q] - down[q]) / (2.0 * h);
  return up;
}

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

// FitPredictionCovariance from C_d = `data_only`.
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
  const Eigen::VectorXd d = data_only.diagonal()(free).cwiseSqrt();
  const Eigen::MatrixXd scaled = data_only(free, free).cwiseQuotient(d * d.transpose());
  Eigen::MatrixXd information = PseudoInverse(scaled);
  int observations = 0;
  for (const Sweep* sweep : fitted) {
    if (sweep->kind != SweepKind::kFrequency) continue;
    for (std::size_t q = 0; q < sweep->jumps.size(); ++q) {
      const JumpBracket& jump = sweep->jumps[q];
      if (!IsEnforced(options.solve.penalties.bifurcation_range, *sweep, jump)) continue;
      const double h_k = RadPerSecondToHz(jump.half_width());
      Eigen::VectorXd g(k);
      bool finite = h_k > 0.0;
      for (int a = 0; a < k && finite; ++a) {
        // d f_k / d q_a = d_a d f_k / d p_j.
        g[a] = Derivatives(options.solve.residual.form, parameters, free[a], *sweep, {}, d[a])[q];
        finite = std::isfinite(g[a]);
      }
      if (!finite) continue;
      information += g * g.transpose() / (h_k * h_k);
      ++observations;
    }
  }
  if (observations == 0) return data_only;
  ParameterMatrix covariance = ParameterMatrix::Zero();
  covariance(free, free) = d.asDiagonal() * PseudoInverse(information) * d.asDiagonal();
  return covariance;
}

// The model error of one prediction: |q_model| x the RMS relative error of
// the same quantity over every level but `level`.
double ModelSd(const HeldOutPrediction& p, std::size_t level,
               const std::vector<std::vector<HeldOutPrediction>*>& levels) {
  double sum = 0.0;
  int count = 0;
  for (std::size_t other = 0; other < levels.size(); ++other) {
    if (other == level) continue;
    for (const HeldOutPrediction& q : *levels[other]) {
      if (q.quantity != p.quantity || !std::isfinite(q.predicted)) continue;
      const double relative = (q.predicted - q.measured) / q.measured;
      sum += relative * relative;
      ++count;
    }
  }
  return count > 0 ? std::abs(p.predicted) * std::sqrt(sum / count) : 0.0;
}

IntervalCoverage CoverageOf(HeldOutQuantity quantity,
                            const std::vector<std::vector<HeldOutPrediction>*>& levels) {
  IntervalCoverage coverage;
  std::vector<double> widths, percents;
  for (const std::vector<HeldOutPrediction>* level : levels) {
    for (const HeldOutPrediction& p : *level) {
      if (p.quantity != quantity) continue;
      ++coverage.total;
      coverage.inside += p.inside;
      if (!std::isfinite(p.half_width)) continue;
      widths.push_back(p.half_width);
      percents.push_back(100.0 * p.half_width / std::abs(p.predicted));
    }
  }
  coverage.median_half_width = MedianOf(widths);
  coverage.median_half_width_percent = MedianOf(percents);
  return coverage;
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

std::vector<HeldOutPrediction> PredictHeldOut(ModelForm form, const Sweep& sweep,
                                              const ParameterVector& parameters, bool usable,
                                              const ParameterMatrix* covariance,
                                              const std::array<bool, kNumParameters>& fixed) {
  std::vector<HeldOutPrediction> predictions;
  const std::vector<int> dwells = UpperBranchDwells(sweep);
  if (sweep.kind == SweepKind::kFrequency) {
    for (const JumpBracket& jump : sweep.jumps) {
      const bool down = jump.kind == JumpKind::kJumpDown;
      predictions.push_back({sweep.Name(),
                             down ? HeldOutQuantity::kJumpDown : HeldOutQuantity::kJumpUp,
                             RadPerSecondToHz(jump.centre())});
    }
  }
  if (!dwells.empty()) {
    double sum = 0.0;
    for (int i : dwells) sum += sweep.points[i].amplitude;
    predictions.push_back({sweep.Name(), HeldOutQuantity::kUpperBranchAmplitude,
                           sum / static_cast<double>(dwells.size())});
  }
  if (!usable) {
    for (HeldOutPrediction& p : predictions) p.predicted = p.half_width = kNaN;
    return predictions;
  }
  const std::vector<double> values = Quantities(form, parameters, sweep, dwells);
  std::vector<double> variance(values.size(), 0.0);
  if (covariance != nullptr) {
    // g_q = d q / d p_j over the free parameters (column q); s_p^2 = g^T C g.
    Eigen::Matrix<double, kNumParameters, Eigen::Dynamic> gradient =
        Eigen::MatrixXd::Zero(kNumParameters, values.size());
    for (int j = 0; j < kNumParameters; ++j) {
      if (fixed[j] || (*covariance)(j, j) <= 0.0) continue;
      const std::vector<double> derivatives = Derivatives(form, parameters, j, sweep, dwells);
      for (std::size_t q = 0; q < values.size(); ++q) {
        gradient(j, q) = std::isfinite(derivatives[q]) ? derivatives[q] : 0.0;
      }
    }
    for (std::size_t q = 0; q < values.size(); ++q) {
      for (int i = 0; i < kNumParameters; ++i) {
        for (int j = 0; j < kNumParameters; ++j) {
          variance[q] += gradient(i, q) * (*covariance)(i, j) * gradient(j, q);
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

double HeldOutPrediction::ErrorPercent() const {
  return std::isfinite(predicted) ? 100.0 * (predicted - measured) / measured : kNaN;
}

const char* HeldOutQuantityName(HeldOutQuantity quantity) {
  constexpr const char* kNames[] = {"jump-down", "jump-up", "upper-branch amplitude"};
  return NameOf(kNames, quantity);
}

const char* HeldOutQuantityKey(HeldOutQuantity quantity) {
  constexpr const char* kKeys[] = {"jump_down", "jump_up", "upper_branch_amplitude"};
  return NameOf(kKeys, quantity);
}

double MedianOf(std::vector<double> values) {
  if (values.empty()) return kNaN;
  std::sort(values.begin(), values.end());
  const std::size_t n = values.size();
  return n % 2 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
}

std::optional<ParameterMatrix> FitPredictionCovariance(const std::vector<const Sweep*>& fitted,
                                                       const IdentificationOptions& options,
                                                       const ParameterVector& parameters,
                                                       std::string* why) {
  const ParameterUncertainty uncertainty =
      EstimateUncertainty(fitted, options, parameters, 0.0, nullptr, IntervalMethod::kDataOnly);
  if (!uncertainty.available) {
    if (why != nullptr) *why = uncertainty.message;
    return std::nullopt;
  }
  return PredictionCovariance(uncertainty.covariance, fitted, options, parameters);
}

PredictionCoverage AddPredictionIntervals(
    const std::vector<std::vector<HeldOutPrediction>*>& levels) {
  for (std::size_t level = 0; level < levels.size(); ++level) {
    for (HeldOutPrediction& p : *levels[level]) {
      if (!std::isfinite(p.predicted)) {
        p.half_width = kNaN;
        p.inside = false;
        continue;
      }
      p.model_sd = ModelSd(p, level, levels);
      p.half_width = kPredictionIntervalZ * std::hypot(p.parameter_sd, p.model_sd);
      p.inside = std::abs(p.predicted - p.measured) <= p.half_width;
    }
  }
  PredictionCoverage coverage;
  coverage.jump_down = CoverageOf(HeldOutQuantity::kJumpDown, levels);
  coverage.jump_up = CoverageOf(HeldOutQuantity::kJumpUp, levels);
  coverage.upper_branch = CoverageOf(HeldOutQuantity::kUpperBranchAmplitude, levels);
  return coverage;
}

ValidationIntervals PredictValidationIntervals(const std::vector<const Sweep*>& fitted,
                                               const std::vector<const Sweep*>& validation,
                                               const IdentificationOptions& options,
                                               const ParameterVector& parameters, bool usable) {
  ValidationIntervals intervals;
  std::optional<ParameterMatrix> covariance;
  if (usable && !validation.empty()) {
    covariance = FitPredictionCovariance(fitted, options, parameters, &intervals.note);
  }
  intervals.parameter_covariance = covariance.has_value();
  if (!usable) intervals.note = "the fit gave no usable solution";
  if (!covariance && !intervals.note.empty()) {
    intervals.note = "s_p = 0 (no covariance: " + intervals.note + ")";
  }
  std::map<std::string, std::size_t> index;  // sweep id -> level
  for (const Sweep* sweep : validation) {
    const auto [it, added] = index.emplace(sweep->id, intervals.levels.size());
    if (added) intervals.levels.push_back({sweep->id, {}});
    const std::vector<HeldOutPrediction> predicted =
        PredictHeldOut(options.solve.residual.form, *sweep, parameters, usable,
                       covariance ? &*covariance : nullptr, options.fixed);
    std::vector<HeldOutPrediction>& level = intervals.levels[it->second].predictions;
    level.insert(level.end(), predicted.begin(), predicted.end());
  }
  // Amplitude sweeps and frequency sweeps without a measured jump predict
  // nothing here.
  intervals.levels.erase(
      std::remove_if(intervals.levels.begin(), intervals.levels.end(),
                     [](const ValidationLevel& level) { return level.predictions.empty(); }),
      intervals.levels.end());
  std::vector<std::vector<HeldOutPrediction>*> levels;
  for (ValidationLevel& level : intervals.levels) levels.push_back(&level.predictions);
  intervals.coverage = AddPredictionIntervals(levels);
  return intervals;
}

}  // namespace dwellfit
