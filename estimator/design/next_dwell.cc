#include "dwellfit/estimator/design/next_dwell.h"

#include <algorithm>
#include <cmath>
#include <memory>

#include "ceres/cost_function.h"
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
double QuantityValue(const ParameterVector& p, const DesignTarget& target, double omega_ref_rad_s) {
  switch (target.kind) {
    case TargetKind::kDOptimal:
      return 0.0;
    case TargetKind::kParameter:
      return p[target.parameter];
    case TargetKind::kEffectiveNonlinearity:
      return EffectiveNonlinearity(p, omega_ref_rad_s);
    case TargetKind::kModalFrequency:
      return RadPerSecondToHz(ModalFrequency(p, target.amplitude));
    case TargetKind::kJumpFrequency: {
      const double w = p[kNaturalFrequency];
      const FoldPoint fold = SolveFrequencyFold(p.data(), target.level, target.jump, w, 1e-3 * w);
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

// The gain of the dwell whose row is g: see the header.
double Gain(const DesignBasis& basis, const ParameterGradient& g, const ParameterGradient& c,
            double s2, bool d_optimal) {
  const ParameterGradient u = basis.covariance * g;
  const double gcg = g.dot(u);
  if (d_optimal) return std::log1p(gcg / s2);
  const double cu = c.dot(u);
  return cu * cu / (s2 + gcg);
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
  } else {
    return true;
  }
  return false;
}

bool LandingPoint(const ParameterVector& p, Branch from, double a_now, double frequency_hz,
                  double level, Branch* branch, double* amplitude, bool* jumps) {
  const double omega = HzToRadPerSecond(frequency_hz);
  const auto k = ResponseCoefficients<double>::FromParameters(p.data(), omega);
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
  const StableRoot root = ModelAmplitude(p, omega, level, on, a_now);
  if (root.status != RootStatus::kOnBranch || !(root.a > 0.0)) return false;
  *branch = on;
  *amplitude = root.a;
  return true;
}

bool ResidualGradient(const DesignBasis& basis, double frequency_hz, double level, Branch branch,
                      double amplitude, ParameterGradient* g) {
  const std::unique_ptr<ceres::CostFunction> cost(
      VerticalErrorResidual::Create(HzToRadPerSecond(frequency_hz), level, amplitude, branch,
                                    basis.residual.error, 1.0, basis.residual.amplitude_floor));
  const double* parameters[] = {basis.estimate.data()};
  double residual = 0.0;
  double row[kNumParameters];
  double* jacobians[] = {row};
  if (!cost->Evaluate(parameters, &residual, jacobians)) return false;
  for (int j = 0; j < kNumParameters; ++j) (*g)(j) = basis.fixed[j] ? 0.0 : row[j];
  return g->allFinite();
}

bool QuantityGradient(const DesignBasis& basis, const DesignTarget& target, double* value,
                      ParameterGradient* c) {
  c->setZero();
  *value = QuantityValue(basis.estimate, target, basis.omega_ref_rad_s);
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
    (*c)(j) = (QuantityValue(plus, target, basis.omega_ref_rad_s) -
               QuantityValue(minus, target, basis.omega_ref_rad_s)) /
              (2.0 * h);
  }
  return c->allFinite();
}

ParameterMatrix CovarianceAfter(const ParameterMatrix& covariance, const ParameterGradient& g,
                                double noise_sigma) {
  const ParameterGradient u = covariance * g;
  return covariance - u * u.transpose() / (noise_sigma * noise_sigma + g.dot(u));
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
  const StableRoot now = ModelAmplitude(basis.estimate, HzToRadPerSecond(state.frequency_hz),
                                        state.level, state.branch, 0.0);
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
  const double s2 = basis.noise_sigma * basis.noise_sigma;
  const bool d_optimal = options.target.kind == TargetKind::kDOptimal;
  for (double f : fs) {
    for (double level : ls) {
      if (f == state.frequency_hz && level == state.level) continue;  // not a step
      Candidate cand;
      cand.frequency_hz = f;
      cand.level = level;
      ParameterGradient g;
      if (!LandingPoint(basis.estimate, state.branch, now.a, f, level, &cand.branch,
                        &cand.amplitude, &cand.jumps) ||
          !ResidualGradient(basis, f, level, cand.branch, cand.amplitude, &g)) {
        continue;
      }
      cand.settle_seconds =
          SettleSeconds(basis.estimate, options.settle_time_constants, now.a, cand.amplitude);
      cand.record_seconds = options.recording_seconds;
      cand.gain = Gain(basis, g, c, s2, d_optimal);
      cand.gain_per_second = cand.gain / (cand.settle_seconds + cand.record_seconds);
      out.ranked.push_back(cand);
    }
  }
  std::stable_sort(
      out.ranked.begin(), out.ranked.end(),
      [](const Candidate& a, const Candidate& b) { return a.gain_per_second > b.gain_per_second; });
  return out;
}

}  // namespace dwellfit
