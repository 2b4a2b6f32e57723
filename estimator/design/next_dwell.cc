#include "dwellfit/estimator/design/next_dwell.h"

#include <algorithm>
#include <cmath>
#include <memory>

#include "Eigen/Dense"
#include "ceres/cost_function.h"
#include "dwellfit/estimator/analysis/level_noise.h"
#include "dwellfit/estimator/analysis/modal_properties.h"
#include "dwellfit/estimator/common/input_error.h"
#include "dwellfit/estimator/common/string_printf.h"
#include "dwellfit/residuals/functors/vertical_error_residual.h"
#include "dwellfit/residuals/model/fold_point.h"

namespace dwellfit {
namespace {

bool Finite(double x) { return std::isfinite(x); }

// Grid values present + i * step within |i * step| <= reach and [low, high],
// ascending; {present} alone when reach is 0.
std::vector<double> AxisGrid(double present, double step, double reach, double low, double high) {
  std::vector<double> values;
  if (!(reach > 0.0)) return {present};
  const int n = static_cast<int>(std::floor(reach / step + 1e-9));
  for (int i = -n; i <= n; ++i) {
    const double v = present + i * step;
    if (v >= low * (1.0 - 1e-12) && v <= high * (1.0 + 1e-12)) values.push_back(v);
  }
  return values;
}

// The value of the target's quantity at p (kDOptimal: 0); NaN where undefined.
double QuantityValue(ModelForm form, const ParameterVector& p, const DesignTarget& target,
                     double omega_ref_rad_s) {
  switch (target.kind) {
    case TargetKind::kDOptimal:
      return 0.0;
    case TargetKind::kParameter:
      return p[target.parameter];
    case TargetKind::kEffectiveNonlinearity:
      return EffectiveNonlinearity(p, omega_ref_rad_s);
    case TargetKind::kModalFrequency:
      return RadPerSecondToHz(ModalFrequency(form, p, target.amplitude));
    case TargetKind::kJumpFrequency: {
      const double w = p[kNaturalFrequency];
      const FoldPoint fold =
          SolveFrequencyFold(form, p.data(), target.level, target.jump, w, 1e-3 * w);
      return fold.exists ? RadPerSecondToHz(fold.control) : std::nan("");
    }
  }
  return std::nan("");
}

// Settling time [s] of a step to amplitude a_new from a_now (cost model above).
double SettleSeconds(const ParameterVector& p, double k, double a_now, double a_new) {
  const double d = std::abs(a_new - a_now) / a_new;
  const double rate_per_s = p[kMu1] + (2.0 / M_PI) * p[kMu2] * a_new;
  return (k + std::log1p(d)) / rate_per_s;
}

// The gain of the dwells whose rows are G and noise covariance N: see the header.
double Gain(const DesignBasis& basis, const CandidateRows& rows, const Eigen::MatrixXd& noise,
            const ParameterGradient& c, bool d_optimal) {
  const CandidateRows u = rows * basis.covariance;  // G C (C symmetric)
  const Eigen::MatrixXd m = noise + u * rows.transpose();
  if (d_optimal) {
    return Eigen::LDLT<Eigen::MatrixXd>(m).vectorD().array().log().sum() -
           Eigen::LDLT<Eigen::MatrixXd>(noise).vectorD().array().log().sum();
  }
  const Eigen::VectorXd w = u * c;
  return w.dot(Eigen::LDLT<Eigen::MatrixXd>(m).solve(w));
}

// N of a candidate's dwells with level slopes h: see DesignBasis.
Eigen::MatrixXd CandidateNoise(const DesignBasis& basis, const Candidate& candidate,
                               const Eigen::VectorXd& h) {
  const int n = static_cast<int>(h.size());
  const double kappa = basis.level_relative_sigma;
  Eigen::MatrixXd noise = basis.noise_sigma * basis.noise_sigma * Eigen::MatrixXd::Identity(n, n);
  if (candidate.level_step != 0.0) {  // each dwell its own level
    noise.diagonal() += (kappa * h).cwiseAbs2();
  } else {  // one level, the mean of n measured ones
    noise += (kappa * kappa / n) * h * h.transpose();
  }
  return noise;
}

// Single dwells at every grid point but the present one, then (with
// segment_dwells n >= 2) the segments of n dwells stepping along one axis by
// +/- m smallest steps, their last dwell within the range and the largest step.
std::vector<Candidate> CandidateShapes(const RigState& state, const RigLimits& limits,
                                       const DesignOptions& options) {
  const std::vector<double> fs =
      AxisGrid(state.frequency_hz, limits.frequency_step_min_hz, limits.frequency_step_max_hz,
               limits.frequency_min_hz, limits.frequency_max_hz);
  const std::vector<double> ls = AxisGrid(state.level, limits.level_step_min, limits.level_step_max,
                                          limits.level_min, limits.level_max);
  if (static_cast<double>(fs.size()) * ls.size() > options.max_candidates) {
    throw InputError(
        StringPrintf("the limits' grid holds %zu candidates, more than %d; give "
                     "larger smallest steps or smaller largest steps",
                     fs.size() * ls.size(), options.max_candidates));
  }
  std::vector<Candidate> shapes;
  for (double f : fs) {
    for (double level : ls) {
      if (f != state.frequency_hz || level != state.level) shapes.push_back({f, level});
    }
  }
  const int n = options.segment_dwells;
  for (int axis = 0; n >= 2 && axis < 2; ++axis) {
    const bool frequency = axis == 0;
    const double smallest = frequency ? limits.frequency_step_min_hz : limits.level_step_min;
    const double largest = frequency ? limits.frequency_step_max_hz : limits.level_step_max;
    const double now = frequency ? state.frequency_hz : state.level;
    const double low = frequency ? limits.frequency_min_hz : limits.level_min;
    const double high = frequency ? limits.frequency_max_hz : limits.level_max;
    for (int m = 1; n * m * smallest <= largest * (1.0 + 1e-9); ++m) {
      for (const double step : {m * smallest, -m * smallest}) {
        const double last = now + n * step;
        if (last < low * (1.0 - 1e-12) || last > high * (1.0 + 1e-12)) continue;
        Candidate c{state.frequency_hz, state.level, n};
        (frequency ? c.frequency_step_hz : c.level_step) = step;
        (frequency ? c.frequency_hz : c.level) += step;
        shapes.push_back(c);
      }
    }
  }
  return shapes;
}

}  // namespace

std::string DesignTarget::Name() const {
  switch (kind) {
    case TargetKind::kDOptimal:
      return "d_optimal";
    case TargetKind::kParameter:
      return ParameterName(parameter);
    case TargetKind::kEffectiveNonlinearity:
      return "alpha_e";
    case TargetKind::kModalFrequency:
      return StringPrintf("omega_at=%.9g", amplitude);
    case TargetKind::kJumpFrequency:
      return StringPrintf("%s_hz=%.9g", jump == JumpKind::kJumpUp ? "jump_up" : "jump_down", level);
  }
  return "";
}

bool ParseDesignTarget(const std::string& text, DesignTarget* target, std::string* error) {
  DesignTarget t;
  ParameterIndex index;
  const std::string::size_type eq = text.find('=');
  const std::string key = text.substr(0, eq);
  double value = std::nan("");
  if (eq != std::string::npos) {
    char* end = nullptr;
    const std::string number = text.substr(eq + 1);
    value = std::strtod(number.c_str(), &end);
    if (number.empty() || *end != '\0' || !(value > 0.0) || !Finite(value)) {
      *error = "'" + text + "': the value after '=' must be a positive number";
      return false;
    }
  }
  if (eq == std::string::npos && key == "d_optimal") {
    t.kind = TargetKind::kDOptimal;
  } else if (eq == std::string::npos && key == "alpha_e") {
    t.kind = TargetKind::kEffectiveNonlinearity;
  } else if (eq == std::string::npos && ParameterIndexFromName(key, &index)) {
    t.kind = TargetKind::kParameter;
    t.parameter = index;
  } else if (key == "omega_at" && eq != std::string::npos) {
    t.kind = TargetKind::kModalFrequency;
    t.amplitude = value;
  } else if ((key == "jump_up_hz" || key == "jump_down_hz") && eq != std::string::npos) {
    t.kind = TargetKind::kJumpFrequency;
    t.level = value;
    t.jump = key == "jump_up_hz" ? JumpKind::kJumpUp : JumpKind::kJumpDown;
  } else {
    *error = "'" + text +
             "' is not a target; give d_optimal, a parameter (eta_e, mu1, mu2, delta, alpha, "
             "omega), alpha_e, omega_at=<amplitude>, jump_up_hz=<level> or jump_down_hz=<level>";
    return false;
  }
  *target = t;
  return true;
}

bool RigState::IsValid(std::string* error) const {
  if (!(frequency_hz > 0.0) || !Finite(frequency_hz) || !(level > 0.0) || !Finite(level)) {
    *error = "the present frequency f_hz and level must be positive numbers";
    return false;
  }
  return true;
}

bool RigLimits::IsValid(std::string* error) const {
  const bool f_ok = frequency_min_hz > 0.0 && frequency_max_hz >= frequency_min_hz &&
                    Finite(frequency_max_hz) && frequency_step_min_hz > 0.0 &&
                    frequency_step_max_hz >= 0.0 && Finite(frequency_step_max_hz);
  const bool l_ok = level_min > 0.0 && level_max >= level_min && Finite(level_max) &&
                    level_step_min > 0.0 && level_step_max >= 0.0 && Finite(level_step_max);
  if (!f_ok) {
    *error =
        "frequency limits: need 0 < f_min_hz <= f_max_hz, f_step_min_hz > 0, "
        "f_step_max_hz >= 0";
  } else if (!l_ok) {
    *error =
        "level limits: need 0 < level_min <= level_max, level_step_min > 0, "
        "level_step_max >= 0";
  } else if (frequency_step_max_hz == 0.0 && level_step_max == 0.0) {
    *error = "f_step_max_hz and level_step_max are both 0: no step is possible";
  } else {
    return true;
  }
  return false;
}

bool DesignOptions::IsValid(std::string* error) const {
  if (!(settle_time_constants >= 0.0) || !Finite(settle_time_constants)) {
    *error = "settle_time_constants must be a number >= 0";
  } else if (!(recording_seconds >= 0.0) || !Finite(recording_seconds)) {
    *error = "recording_seconds must be a number >= 0";
  } else if (!(noise_sigma >= 0.0) || !Finite(noise_sigma)) {
    *error = "noise_sigma must be a number >= 0 (0: the fit's own)";
  } else if (top < 1 || max_candidates < 1) {
    *error = "top and max_candidates must be at least 1";
  } else if (segment_dwells < 1 || segment_dwells > 20) {
    *error = "segment_dwells must lie in [1, 20]";
  } else {
    return true;
  }
  return false;
}

bool LandingPoint(ModelForm form, const ParameterVector& p, Branch from, double a_now,
                  double frequency_hz, double level, Branch* branch, double* amplitude,
                  bool* jumps) {
  const double omega = HzToRadPerSecond(frequency_hz);
  const auto k = ResponseCoefficients<double>::FromParameters(form, p.data(), omega);
  const TurningPoints tp = FindTurningPoints(k);
  const double target = level * level;
  const bool lower_reaches = tp.exist && k.G(tp.a_lower_end) > target;
  const bool upper_reaches = tp.exist && k.G(tp.a_upper_end) < target;
  const bool two = lower_reaches && upper_reaches;
  *jumps =
      tp.exist && !two &&
      ((from == Branch::kLower && !lower_reaches) || (from == Branch::kUpper && !upper_reaches));
  Branch on = Branch::kOnly;
  if (two && from != Branch::kOnly) {
    on = from;  // stays: the branch reaches a_b here
  } else if (two) {
    on = SolveStableRoot(k, level, Branch::kOnly, a_now).branch;
  }
  const StableRoot root = ModelAmplitude(form, p, omega, level, on, a_now);
  if (root.status != RootStatus::kOnBranch || !(root.a > 0.0)) return false;
  *branch = on;
  *amplitude = root.a;
  return true;
}

bool ResidualGradient(const DesignBasis& basis, double frequency_hz, double level, Branch branch,
                      double amplitude, ParameterGradient* g, double* level_slope) {
  const std::unique_ptr<ceres::CostFunction> cost(VerticalErrorResidual::Create(
      basis.residual.form, HzToRadPerSecond(frequency_hz), level, amplitude, branch,
      basis.residual.error, 1.0, basis.residual.amplitude_floor));
  const double* parameters[] = {basis.estimate.data()};
  double residual = 0.0;
  double row[kNumParameters];
  double* jacobians[] = {row};
  if (!cost->Evaluate(parameters, &residual, jacobians)) return false;
  for (int j = 0; j < kNumParameters; ++j) (*g)(j) = basis.fixed[j] ? 0.0 : row[j];
  if (level_slope != nullptr) {
    *level_slope = LevelSlope(basis.estimate, row[kEtaE]);
    if (!std::isfinite(*level_slope)) return false;
  }
  return g->allFinite();
}

bool QuantityGradient(const DesignBasis& basis, const DesignTarget& target, double* value,
                      ParameterGradient* c) {
  c->setZero();
  *value = QuantityValue(basis.residual.form, basis.estimate, target, basis.omega_ref_rad_s);
  if (!Finite(*value)) return false;
  if (target.kind == TargetKind::kDOptimal) return true;
  for (int j = 0; j < kNumParameters; ++j) {
    if (basis.fixed[j]) continue;
    // Central differences, a step of 1e-6 of the parameter's magnitude (its
    // standard error where the value is 0).
    const double scale =
        std::max(std::abs(basis.estimate[j]), std::sqrt(std::max(basis.covariance(j, j), 0.0)));
    const double h = 1e-6 * (scale > 0.0 ? scale : 1.0);
    ParameterVector plus = basis.estimate, minus = basis.estimate;
    plus[j] += h;
    minus[j] -= h;
    (*c)(j) = (QuantityValue(basis.residual.form, plus, target, basis.omega_ref_rad_s) -
               QuantityValue(basis.residual.form, minus, target, basis.omega_ref_rad_s)) /
              (2.0 * h);
  }
  return c->allFinite();
}

bool WalkCandidate(const DesignBasis& basis, Branch from, double a_now,
                   const DesignOptions& options, Candidate* candidate, CandidateRows* rows,
                   Eigen::MatrixXd* noise) {
  rows->resize(candidate->dwells, kNumParameters);
  Eigen::VectorXd h(candidate->dwells);
  candidate->settle_seconds = 0.0;
  for (int k = 0; k < candidate->dwells; ++k) {
    const double f = candidate->frequency_hz + k * candidate->frequency_step_hz;
    const double level = candidate->level + k * candidate->level_step;
    Branch branch;
    double a;
    bool jumps;
    ParameterGradient g;
    if (!LandingPoint(basis.residual.form, basis.estimate, from, a_now, f, level, &branch, &a,
                      &jumps) ||
        !ResidualGradient(basis, f, level, branch, a, &g, &h[k])) {
      return false;
    }
    if (k == 0) {
      candidate->branch = branch;
      candidate->amplitude = a;
      candidate->jumps = jumps;
    }
    rows->row(k) = g.transpose();
    candidate->settle_seconds +=
        SettleSeconds(basis.estimate, options.settle_time_constants, a_now, a);
    from = branch;  // kOnly: the next dwell lands on the stable root nearer a
    a_now = a;
  }
  candidate->record_seconds = candidate->dwells * options.recording_seconds;
  *noise = CandidateNoise(basis, *candidate, h);
  return true;
}

ParameterMatrix CovarianceAfter(const ParameterMatrix& covariance, const CandidateRows& rows,
                                const Eigen::MatrixXd& noise) {
  const CandidateRows u = rows * covariance;
  const Eigen::MatrixXd m = noise + u * rows.transpose();
  return covariance - u.transpose() * Eigen::LDLT<Eigen::MatrixXd>(m).solve(u);
}

Recommendation RecommendNextDwell(const DesignBasis& given, const RigState& state,
                                  const RigLimits& limits, const DesignOptions& options) {
  Recommendation out;
  out.target = options.target;
  out.basis = given;
  const DesignBasis& basis = out.basis;
  if (options.noise_sigma > 0.0 && given.noise_sigma > 0.0) {
    const double ratio = options.noise_sigma / given.noise_sigma;
    out.basis.covariance *= ratio * ratio;
    out.basis.noise_sigma = options.noise_sigma;
  }
  if (!(basis.noise_sigma > 0.0)) {
    throw InputError(
        "noise_sigma: the fit's residual noise is 0, so the dwells so far give no "
        "covariance to design from; fit noisy data");
  }
  ParameterGradient c;
  if (!QuantityGradient(basis, options.target, &out.quantity, &c)) {
    throw InputError("target " + options.target.Name() +
                     ": the quantity is undefined at the estimate (no such jump or backbone "
                     "there); choose another target");
  }
  out.quantity_variance = c.dot(basis.covariance * c);
  const StableRoot now =
      ModelAmplitude(basis.residual.form, basis.estimate, HzToRadPerSecond(state.frequency_hz),
                     state.level, state.branch, 0.0);
  out.state = state;
  out.present_amplitude = now.a;
  if (now.status == RootStatus::kFailed) {
    throw InputError(
        "the estimate has no stable response at the present state: check the "
        "fit's status and --state");
  }
  if (!(basis.estimate[kMu1] + basis.estimate[kMu2] > 0.0)) {
    throw InputError(
        "the estimate has no damping (mu1 = mu2 = 0), so no settling time: fit "
        "more dwells, or fix mu1 at a value from a decay test");
  }
  const bool d_optimal = options.target.kind == TargetKind::kDOptimal;
  CandidateRows rows;
  Eigen::MatrixXd noise;
  for (Candidate candidate : CandidateShapes(state, limits, options)) {
    if (!WalkCandidate(basis, state.branch, now.a, options, &candidate, &rows, &noise)) continue;
    candidate.gain = Gain(basis, rows, noise, c, d_optimal);
    candidate.gain_per_second =
        candidate.gain / (candidate.settle_seconds + candidate.record_seconds);
    out.ranked.push_back(candidate);
  }
  std::stable_sort(
      out.ranked.begin(), out.ranked.end(),
      [](const Candidate& a, const Candidate& b) { return a.gain_per_second > b.gain_per_second; });
  return out;
}

}  // namespace dwellfit
