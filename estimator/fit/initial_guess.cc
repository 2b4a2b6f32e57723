#include "dwellfit/estimator/fit/initial_guess.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <optional>
#include <string>
#include <vector>

#include "Eigen/Dense"
#include "dwellfit/estimator/common/input_error.h"
#include "dwellfit/estimator/common/string_printf.h"
#include "dwellfit/residuals/model/response_model.h"

namespace dwellfit {
namespace {

// c of P = Omega a (mu1 + c mu2 a) / eta_e, from k2 = (4 / (3 pi)) mu2 Omega / eta_e.
constexpr double kQuadraticDampingFactor = 4.0 / (3.0 * kPi);
// A dwell is off resonance while P <= kOffResonanceMaxP a_base, i.e. |Q| >= 0.44 a_base.
constexpr double kOffResonanceMaxP = 0.9;
// Abscissae spanning less than this fraction of their largest value fix no slope.
constexpr double kMinRelativeSpread = 0.05;
// When the peak heights cannot separate mu1 from mu2, the share c mu2 a / (mu1 + c mu2 a)
// given to the quadratic damping at the mean backbone amplitude: even with one level
// (no information), small when the levels show no growth of damping with amplitude.
constexpr double kQuadraticShareOneLevel = 0.5;
constexpr double kQuadraticShareNoGrowth = 0.1;

// min |a x - y|, by Eigen's column-pivoting Householder QR on the columns
// scaled to unit norm. Without the scaling the QR's rank threshold, relative
// to the largest column, drops a column that is small only because of the
// data's unit: the backbone's a_k^2 column beside its column of ones is 1e-24
// of it for amplitudes of 1e-12 m, and its slope (alpha) came out 0.
Eigen::VectorXd LeastSquares(const Eigen::MatrixXd& a, const Eigen::VectorXd& y) {
  Eigen::VectorXd norms = a.colwise().norm().transpose();
  for (Eigen::Index j = 0; j < norms.size(); ++j) {
    if (!(norms(j) > 0.0)) norms(j) = 1.0;
  }
  const Eigen::MatrixXd scaled = a * norms.cwiseInverse().asDiagonal();
  return scaled.colPivHouseholderQr().solve(y).cwiseQuotient(norms);
}

// y ~ intercept + slope x by least squares; a given intercept or slope is held.
struct Line {
  double intercept = 0.0;
  double slope = 0.0;
};

Line FitLine(const std::vector<double>& x, const std::vector<double>& y,
             std::optional<double> intercept, std::optional<double> slope) {
  Line line{intercept.value_or(0.0), slope.value_or(0.0)};
  const int num_free = (intercept ? 0 : 1) + (slope ? 0 : 1);
  if (num_free == 0 || x.empty()) return line;
  const int n = static_cast<int>(x.size());
  Eigen::MatrixXd a(n, num_free);
  Eigen::VectorXd rhs(n);
  for (int i = 0; i < n; ++i) {
    rhs(i) = y[i] - line.intercept - line.slope * x[i];  // free entries are 0 here
    int column = 0;
    if (!intercept) a(i, column++) = 1.0;
    if (!slope) a(i, column++) = x[i];
  }
  const Eigen::VectorXd solution = LeastSquares(a, rhs);
  int column = 0;
  if (!intercept) line.intercept = solution(column++);
  if (!slope) line.slope = solution(column++);
  return line;
}

// Whether the values span enough to fix a slope: (max - min) / max.
bool HasSpread(const std::vector<double>& x) {
  if (x.size() < 2) return false;
  const auto [lo, hi] = std::minmax_element(x.begin(), x.end());
  return *hi > 0.0 && (*hi - *lo) / *hi >= kMinRelativeSpread;
}

double Mean(const std::vector<double>& x) {
  return std::accumulate(x.begin(), x.end(), 0.0) / static_cast<double>(x.size());
}

// A dwell where Q ~ 0 and P ~ a_base (step 1 of the header).
struct BackbonePoint {
  double omega = 0.0;  // rad/s
  double a = 0.0;
  double a_base = 0.0;
  std::string description;
};

// The sweeps sharing one held control: a_base (frequency sweeps) or Omega
// (amplitude sweeps), usually the up and down directions of one sweep id.
struct Level {
  SweepKind kind = SweepKind::kFrequency;
  double held = 0.0;
  std::vector<const Sweep*> sweeps;
};

double HeldControl(const Sweep& sweep) {
  const DwellPoint& first = sweep.points.front();
  return sweep.kind == SweepKind::kFrequency ? first.a_base : first.drive_frequency_rad_s;
}

std::vector<Level> GroupLevels(const std::vector<const Sweep*>& sweeps) {
  std::vector<Level> levels;
  for (const Sweep* sweep : sweeps) {
    if (sweep == nullptr || sweep->points.empty()) continue;
    const double held = HeldControl(*sweep);
    auto same = [&](const Level& level) {
      return level.kind == sweep->kind && std::abs(level.held - held) <= 1e-9 * std::abs(held);
    };
    auto it = std::find_if(levels.begin(), levels.end(), same);
    if (it == levels.end()) {
      levels.push_back({sweep->kind, held, {}});
      it = levels.end() - 1;
    }
    it->sweeps.push_back(sweep);
  }
  return levels;
}

bool Usable(const DwellPoint& point) {
  return point.amplitude > 0.0 && point.a_base > 0.0 && point.drive_frequency_rad_s > 0.0;
}

// Frequency level: its largest amplitude, unless at the edge of the band it
// covers (resonance outside the band). Amplitude level: its upper-branch dwell
// with the smallest a_base (the end of the upper branch, next to the fold).
std::optional<BackbonePoint> FindBackbonePoint(const Level& level,
                                               std::vector<std::string>* notes) {
  const std::string id = level.sweeps.front()->id;
  const DwellPoint* best = nullptr;
  double omega_lo = std::numeric_limits<double>::infinity();
  double omega_hi = -omega_lo;
  for (const Sweep* sweep : level.sweeps) {
    for (const DwellPoint& point : sweep->points) {
      if (!Usable(point)) continue;
      omega_lo = std::min(omega_lo, point.drive_frequency_rad_s);
      omega_hi = std::max(omega_hi, point.drive_frequency_rad_s);
      if (level.kind == SweepKind::kFrequency) {
        if (best == nullptr || point.amplitude > best->amplitude) best = &point;
      } else if (point.branch == Branch::kUpper) {
        if (best == nullptr || point.a_base < best->a_base) best = &point;
      }
    }
  }
  if (best == nullptr) {
    notes->push_back(
        StringPrintf("%s: no %s, not a backbone point", id.c_str(),
                     level.kind == SweepKind::kFrequency ? "dwell" : "upper-branch dwell"));
    return std::nullopt;
  }
  const double omega = best->drive_frequency_rad_s;
  if (level.kind == SweepKind::kFrequency && (omega == omega_lo || omega == omega_hi)) {
    notes->push_back(
        StringPrintf("%s: largest amplitude at the edge of the band (%.3f Hz), "
                     "resonance outside it: not a backbone point",
                     id.c_str(), RadPerSecondToHz(omega)));
    return std::nullopt;
  }
  return BackbonePoint{
      omega, best->amplitude, best->a_base,
      StringPrintf("%s %s %.3f Hz a %.4g a_base %.4g", id.c_str(),
                   level.kind == SweepKind::kFrequency ? "peak" : "upper-branch end",
                   RadPerSecondToHz(omega), best->amplitude, best->a_base)};
}

// The damping per unit forcing effectiveness at amplitude a,
//   m(a) = (mu1 + c mu2 a) / eta_e = m1 + m2 a   [1/s per unit of eta_e],
// fitted to the peak heights m_k = a_base_k / (Omega_k a_k) (step 3).
struct DampingLine {
  double m1 = 0.0;
  double m2 = 0.0;
  std::string how;
};

DampingLine FitPeakHeights(const std::vector<BackbonePoint>& backbone,
                           std::optional<double> known_m1, std::optional<double> known_m2) {
  std::vector<double> a, m;
  for (const BackbonePoint& point : backbone) {
    a.push_back(point.a);
    m.push_back(point.a_base / (point.omega * point.a));
  }
  const double m_mean = Mean(m);
  const double a_mean = Mean(a);
  const double m_min = *std::min_element(m.begin(), m.end());
  DampingLine line;
  auto split = [&](double quadratic_share) {
    line.m1 = known_m1.value_or((1.0 - quadratic_share) * m_mean);
    line.m2 = known_m2.value_or(quadratic_share * m_mean / a_mean);
  };
  const int num_free = (known_m1 ? 0 : 1) + (known_m2 ? 0 : 1);
  if (num_free == 2 && !HasSpread(a)) {
    split(kQuadraticShareOneLevel);
    line.how = StringPrintf(
        "one peak amplitude (%.4g): mu1 and mu2 not separable, the damping "
        "mu1 + c mu2 a there split evenly between them",
        a_mean);
    return line;
  }
  const Line fit = FitLine(a, m, known_m1, known_m2);
  line.m1 = fit.intercept;
  line.m2 = fit.slope;
  line.how = StringPrintf("straight line through %d peak heights", static_cast<int>(a.size()));
  if (!known_m2 && !(line.m2 > 0.0)) {
    split(kQuadraticShareNoGrowth);
    line.how += StringPrintf(
        " has slope %.3g <= 0 (no damping growth with amplitude): mu2 set small, "
        "%.0f%% of the damping at a = %.4g",
        fit.slope, 100.0 * kQuadraticShareNoGrowth, a_mean);
  } else if (!known_m1 && !(line.m1 > 0.0)) {
    line.m1 = 0.1 * m_min;
    line.m2 = known_m2.value_or(FitLine(a, m, line.m1, std::nullopt).slope);
    line.how += StringPrintf(
        " has intercept %.3g <= 0: mu1 set to 10%% of the smallest peak damping", fit.intercept);
  }
  return line;
}

// A dwell used off resonance (steps 4 and the one-backbone-point fit).
struct OffResonanceDwell {
  double y = 0.0;   // Omega^2 (1 + delta a^2 / 2) [rad^2/s^2]
  double a2 = 0.0;  // a^2
  double q = 0.0;   // |Q| / a = sqrt(a_base^2 - P^2) / a
  double omega = 0.0;
  Branch branch = Branch::kOnly;
};

std::vector<OffResonanceDwell> CollectOffResonance(const std::vector<const Sweep*>& sweeps,
                                                   const DampingLine& damping, double delta) {
  std::vector<OffResonanceDwell> dwells;
  for (const Sweep* sweep : sweeps) {
    if (sweep == nullptr) continue;
    for (const DwellPoint& point : sweep->points) {
      if (!Usable(point)) continue;
      const double omega = point.drive_frequency_rad_s;
      const double a = point.amplitude;
      // P = Omega a (m1 + m2 a), the damping part of the fixed point.
      const double p = omega * a * (damping.m1 + damping.m2 * a);
      if (!(p <= kOffResonanceMaxP * point.a_base)) continue;
      dwells.push_back({omega * omega * (1.0 + 0.5 * delta * a * a), a * a,
                        std::sqrt(point.a_base * point.a_base - p * p) / a, omega, point.branch});
    }
  }
  return dwells;
}

// Whether the frequency sweeps jump like a softening mode (jump up going up in
// frequency, down going down); hardening otherwise and by default.
bool LooksSoftening(const std::vector<const Sweep*>& sweeps) {
  int hardening = 0, softening = 0;
  for (const Sweep* sweep : sweeps) {
    if (sweep == nullptr || sweep->kind != SweepKind::kFrequency) continue;
    for (const JumpBracket& jump : sweep->jumps) {
      const bool up = sweep->direction == SweepDirection::kUp;
      const bool jump_down = jump.kind == JumpKind::kJumpDown;
      (up == jump_down ? hardening : softening) += 1;
    }
  }
  return softening > hardening;
}

// w^2 and e = 2 eta_e together when the backbone is one point (y0, a0): with
// alpha tied to it, (3/4) alpha = (y0 - w^2) / a0^2, each off-resonance dwell
//   s_i D_i = s_i (w^2 (1 - r_i) + y0 r_i - y_i) = e q_i,  r_i = a_i^2 / a0^2,
// is linear in (w^2, e). The sign s_i of Q_i comes first from the branch
// (hardening: upper branch Q > 0, lower Q < 0; single-valued: Q > 0 below the
// peak frequency), then once more from the sign of D_i at the first solution.
struct JointFit {
  double w2 = 0.0;
  double e = 0.0;
};

JointFit FitFrequencyAndForcing(const std::vector<OffResonanceDwell>& dwells, double y0, double a0,
                                double omega0, bool softening) {
  JointFit fit;
  const int n = static_cast<int>(dwells.size());
  for (int pass = 0; pass < 2; ++pass) {
    Eigen::MatrixXd a(n, 2);
    Eigen::VectorXd rhs(n);
    for (int i = 0; i < n; ++i) {
      const OffResonanceDwell& d = dwells[i];
      const double r = d.a2 / (a0 * a0);
      double sign;
      if (pass == 0) {
        if (d.branch == Branch::kOnly) {
          sign = d.omega < omega0 ? 1.0 : -1.0;
        } else {
          sign = (d.branch == Branch::kUpper) != softening ? 1.0 : -1.0;
        }
      } else {
        sign = fit.w2 * (1.0 - r) + y0 * r - d.y >= 0.0 ? 1.0 : -1.0;
      }
      a(i, 0) = sign * (1.0 - r);
      a(i, 1) = -d.q;
      rhs(i) = sign * (d.y - y0 * r);
    }
    const Eigen::VectorXd solution = LeastSquares(a, rhs);
    fit.w2 = solution(0);
    fit.e = solution(1);
  }
  return fit;
}

std::string RadPerSecondText(double rad_s) {
  return StringPrintf("%.6g rad/s (%.4f Hz)", rad_s, RadPerSecondToHz(rad_s));
}

// Takes parameter `index` as given, when it is ("eta_e = 100: given");
// returns whether it was.
bool TakeGiven(const KnownParameters& known, int index, InitialGuessReport* report) {
  if (!known[index]) return false;
  report->guess[index] = *known[index];
  report->steps.push_back(StringPrintf("%s = %.6g: given", ParameterName(index), *known[index]));
  return true;
}

// Step 1: one backbone point per level that resonates in the band.
std::vector<BackbonePoint> FindBackbone(const std::vector<const Sweep*>& sweeps,
                                        std::vector<std::string>* steps) {
  std::vector<BackbonePoint> backbone;
  std::vector<std::string> notes;
  for (const Level& level : GroupLevels(sweeps)) {
    if (auto point = FindBackbonePoint(level, &notes)) backbone.push_back(*point);
  }
  for (const std::string& note : notes) steps->push_back(note);
  if (backbone.empty()) {
    throw InputError(
        "automatic initial guess: no resonance in the fitted sweeps (no frequency sweep peaks "
        "inside its band, no amplitude sweep reaches the upper branch); give the initial guess");
  }
  std::string points = "backbone points (Q ~ 0, P ~ a_base):";
  for (size_t k = 0; k < backbone.size(); ++k) {
    points += (k == 0 ? " " : "; ") + backbone[k].description;
  }
  steps->push_back(points);
  return backbone;
}

// The backbone Omega_k^2 (1 + delta a_k^2 / 2) = w^2 + b a_k^2, b = (3/4) alpha.
struct BackboneFit {
  double w2 = 0.0;                // [rad^2/s^2]
  double b = 0.0;                 // (3/4) alpha
  std::optional<double> joint_e;  // 2 eta_e, when fitted jointly with w^2
  std::string how;
};

// Step 2: a line through the backbone points, or (one backbone amplitude) a
// joint fit of w^2 and eta_e over the off-resonance dwells.
BackboneFit FitBackbone(const std::vector<const Sweep*>& sweeps,
                        const std::vector<BackbonePoint>& backbone,
                        const std::vector<OffResonanceDwell>& off_resonance,
                        const KnownParameters& known) {
  const double delta = known[kDelta].value_or(0.0);
  auto ordinate = [delta](double omega, double a) {
    return omega * omega * (1.0 + 0.5 * delta * a * a);
  };
  std::vector<double> a2, y;
  for (const BackbonePoint& point : backbone) {
    a2.push_back(point.a * point.a);
    y.push_back(ordinate(point.omega, point.a));
  }
  std::optional<double> known_w2, known_b;
  if (known[kNaturalFrequency]) known_w2 = *known[kNaturalFrequency] * *known[kNaturalFrequency];
  if (known[kAlpha]) known_b = 0.75 * *known[kAlpha];
  BackboneFit fit;
  if (known_w2 || known_b || HasSpread(a2)) {
    const Line line = FitLine(a2, y, known_w2, known_b);
    fit.w2 = line.intercept;
    fit.b = line.slope;
    fit.how = StringPrintf(
        "backbone Omega_k^2 (1 + delta a_k^2 / 2) = w^2 + (3/4) alpha a_k^2 [rad^2/s^2] "
        "through %d point(s)",
        static_cast<int>(backbone.size()));
  } else {
    const BackbonePoint& point =
        *std::min_element(backbone.begin(), backbone.end(),
                          [](const BackbonePoint& l, const BackbonePoint& r) { return l.a < r.a; });
    const double y0 = ordinate(point.omega, point.a);
    const JointFit joint =
        FitFrequencyAndForcing(off_resonance, y0, point.a, point.omega, LooksSoftening(sweeps));
    fit.w2 = joint.w2;
    fit.b = (y0 - joint.w2) / (point.a * point.a);
    fit.joint_e = joint.e;
    fit.how = StringPrintf(
        "one backbone amplitude: least squares over %d off-resonance dwells of "
        "s_i (w^2 + (3/4) alpha a_i^2 - Omega_i^2) = 2 eta_e sqrt(a_base_i^2 - P_i^2) / a_i "
        "for (w^2, eta_e), alpha tied to the backbone point by "
        "Omega_0^2 = w^2 + (3/4) alpha a_0^2",
        static_cast<int>(off_resonance.size()));
  }
  if (!(fit.w2 > 0.0) || !std::isfinite(fit.w2 + fit.b)) {
    throw InputError(StringPrintf(
        "automatic initial guess: the backbone gives w^2 = %.4g rad^2/s^2 (not positive); "
        "give omega",
        fit.w2));
  }
  return fit;
}

// omega, alpha and delta from the backbone fit (or as given).
void SetStiffness(const BackboneFit& fit, const KnownParameters& known,
                  InitialGuessReport* report) {
  ParameterVector& guess = report->guess;
  std::vector<std::string>& steps = report->steps;
  guess[kNaturalFrequency] = known[kNaturalFrequency].value_or(std::sqrt(fit.w2));
  const std::string how =
      known[kNaturalFrequency] ? "given" : fit.how + "; w^2 is its value at a = 0";
  steps.push_back(StringPrintf("omega = %s: %s", RadPerSecondText(guess[kNaturalFrequency]).c_str(),
                               how.c_str()));
  if (!TakeGiven(known, kAlpha, report)) {
    guess[kAlpha] = fit.b / 0.75;
    steps.push_back(StringPrintf(
        "alpha = %.4g: %s; alpha is the slope in a^2 over 3/4%s", guess[kAlpha], fit.how.c_str(),
        known[kDelta] && *known[kDelta] != 0.0 ? "" : " (with delta = 0 it is alpha_e)"));
  }
  if (!TakeGiven(known, kDelta, report)) {
    guess[kDelta] = 0.0;
    steps.push_back(
        "delta = 0: over a narrow band only alpha_e = alpha - (2/3) delta Omega^2 is "
        "identifiable; the fit may free delta");
  }
}

// Step 4: eta_e from |D_i| = 2 eta_e |Q_i| / a_i off resonance.
void SetForcing(const BackboneFit& fit, const std::vector<OffResonanceDwell>& off_resonance,
                const KnownParameters& known, InitialGuessReport* report) {
  ParameterVector& guess = report->guess;
  if (!TakeGiven(known, kEtaE, report) && fit.joint_e) {
    guess[kEtaE] = 0.5 * *fit.joint_e;
    report->steps.push_back(StringPrintf("eta_e = %.4g: %s", guess[kEtaE], fit.how.c_str()));
  } else if (!known[kEtaE]) {
    std::vector<double> q, abs_d;
    for (const OffResonanceDwell& d : off_resonance) {
      q.push_back(d.q);
      abs_d.push_back(std::abs(fit.w2 + fit.b * d.a2 - d.y));
    }
    guess[kEtaE] = 0.5 * FitLine(q, abs_d, 0.0, std::nullopt).slope;
    report->steps.push_back(StringPrintf(
        "eta_e = %.4g: least squares through the origin over %d off-resonance dwells "
        "(P <= %.1f a_base) of |w^2 + (3/4) alpha a^2 - Omega^2 (1 + delta a^2 / 2)| "
        "= 2 eta_e sqrt(a_base^2 - P^2) / a, P = Omega a (mu1 + c mu2 a) / eta_e from the "
        "peak heights",
        guess[kEtaE], static_cast<int>(q.size()), kOffResonanceMaxP));
  }
  if (!(guess[kEtaE] > 0.0) || !std::isfinite(guess[kEtaE])) {
    throw InputError(StringPrintf(
        "automatic initial guess: eta_e estimate %.4g is not positive; give eta_e", guess[kEtaE]));
  }
}

// Step 5: mu1, mu2 from the peak heights a_base_k / (Omega_k a_k) = m1 + m2 a_k,
// m1 = mu1 / eta_e, m2 = c mu2 / eta_e.
void SetDamping(const std::vector<BackbonePoint>& backbone, const KnownParameters& known,
                InitialGuessReport* report) {
  ParameterVector& guess = report->guess;
  const double eta = guess[kEtaE];
  std::optional<double> known_m1, known_m2;
  if (known[kMu1]) known_m1 = *known[kMu1] / eta;
  if (known[kMu2]) known_m2 = kQuadraticDampingFactor * *known[kMu2] / eta;
  const DampingLine damping = FitPeakHeights(backbone, known_m1, known_m2);
  const std::string how =
      "peak heights a_base_k / (Omega_k a_k) = (mu1 + c mu2 a_k) / eta_e, c = 4 / (3 pi): " +
      damping.how;
  if (!TakeGiven(known, kMu1, report)) {
    guess[kMu1] = damping.m1 * eta;
    report->steps.push_back(StringPrintf("mu1 = %.4g 1/s: %s", guess[kMu1], how.c_str()));
  }
  if (!TakeGiven(known, kMu2, report)) {
    guess[kMu2] = damping.m2 * eta / kQuadraticDampingFactor;
    report->steps.push_back(StringPrintf("mu2 = %.4g: %s", guess[kMu2], how.c_str()));
  }
}

}  // namespace

InitialGuessReport AutomaticInitialGuess(const std::vector<const Sweep*>& sweeps,
                                         const KnownParameters& known) {
  InitialGuessReport report;
  const std::vector<BackbonePoint> backbone = FindBackbone(sweeps, &report.steps);
  // Step 3 comes before step 2: the damping per unit eta_e from the peak
  // heights is independent of w and eta_e, and tells which dwells are off
  // resonance.
  const DampingLine data_damping = FitPeakHeights(backbone, std::nullopt, std::nullopt);
  const std::vector<OffResonanceDwell> off_resonance =
      CollectOffResonance(sweeps, data_damping, known[kDelta].value_or(0.0));
  if (off_resonance.empty()) {
    throw InputError(
        "automatic initial guess: every dwell is near resonance (P > 0.9 a_base); no "
        "off-resonance dwell to estimate eta_e from; give eta_e");
  }
  const BackboneFit fit = FitBackbone(sweeps, backbone, off_resonance, known);
  SetStiffness(fit, known, &report);
  SetForcing(fit, off_resonance, known, &report);
  SetDamping(backbone, known, &report);
  return report;
}

InitialGuessReport AutomaticInitialGuess(const std::vector<const Sweep*>& sweeps,
                                         const KnownParameters& known, ModelForm form) {
  if (!form.family_terms()) return AutomaticInitialGuess(sweeps, known);
  std::vector<int> own;  // the entries that hold the member's own terms
  if (form.cubic_damping()) own.push_back(kMu3);
  if (form.quintic_stiffness()) own.push_back(kAlpha5);
  KnownParameters chapter = known;
  for (int index : own) chapter[index] = 0.0;
  InitialGuessReport report = AutomaticInitialGuess(sweeps, chapter);
  for (int index : own) {
    const std::string chapter_step = std::string(ParameterName(index)) + " = ";
    auto& steps = report.steps;
    steps.erase(
        std::remove_if(steps.begin(), steps.end(),
                       [&](const std::string& step) { return step.rfind(chapter_step, 0) == 0; }),
        steps.end());
    report.guess[index] = known[index].value_or(0.0);
    steps.push_back(StringPrintf(
        "%s = %.6g: %s", ParameterName(form, index), report.guess[index],
        known[index] ? "given" : "the member's own term starts at 0 and the fit frees it"));
  }
  return report;
}

}  // namespace dwellfit
