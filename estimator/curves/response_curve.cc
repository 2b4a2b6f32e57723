#include "dwellfit/estimator/curves/response_curve.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

#include "boost/math/tools/minima.hpp"
#include "boost/math/tools/toms748_solve.hpp"
#include "dwellfit/estimator/common/input_error.h"
#include "dwellfit/estimator/common/string_printf.h"
#include "dwellfit/residuals/model/equivalent_oscillator.h"
#include "dwellfit/residuals/model/fold_point.h"
#include "dwellfit/residuals/model/response_model.h"

namespace dwellfit {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// C^2 x^2 + c1 x + c0 = 0 in x = Omega^2 at amplitude a (header comment).
struct FrequencyQuadratic {
  double c2 = 0.0, c1 = 0.0, c0 = 0.0, disc = 0.0;
  double backbone_x = kNaN;  // B / C
};

// A member of the family (model_form.h) keeps the quadratic: mu3 enters D as
// mu3 a^2 / 4, alpha5 enters B as (5/2) alpha5 a^4, and delta is then 0.
FrequencyQuadratic MakeQuadratic(ModelForm form, const ParameterVector& p, double a_base,
                                 double a) {
  const double eta_e = p[kEtaE];
  const EquivalentOscillator o = EquivalentOscillatorAt(form, p, a);
  const double d = o.damping * a / eta_e;
  const double b = a * o.stiffness / (8.0 * eta_e);
  const double c = a * o.mass / (8.0 * eta_e);
  FrequencyQuadratic q;
  q.c2 = c * c;
  q.c1 = d * d - 2.0 * b * c;
  q.c0 = (b - a_base) * (b + a_base);
  q.disc = d * d * (d * d - 4.0 * b * c) + 4.0 * c * c * a_base * a_base;
  if (c != 0.0) q.backbone_x = b / c;
  return q;
}

// Omega [rad/s] on `side` (0: left root x-, 1: right root x+ >= x-) at
// amplitude a; NaN where that root is not a positive x. A discriminant
// rounded just below 0 at a piece's end counts as 0.
double SideFrequency(ModelForm form, const ParameterVector& p, double a_base, double a, int side) {
  const FrequencyQuadratic q = MakeQuadratic(form, p, a_base, a);
  if (std::isnan(q.disc) || !(q.c2 > 0.0)) return kNaN;
  const double s = std::sqrt(std::max(q.disc, 0.0));
  const double big = -0.5 * (q.c1 + std::copysign(s, q.c1));
  double r1 = big / q.c2;
  double r2 = big != 0.0 ? q.c0 / big : r1;
  if (r1 > r2) std::swap(r1, r2);
  const double x = side == 0 ? r1 : r2;
  return x > 0.0 ? std::sqrt(x) : kNaN;
}

double DgDa(ModelForm form, const ParameterVector& p, double omega, double a) {
  return ResponseCoefficients<double>::FromParameters(form, p.data(), omega).dG(a);
}

// Solves f on [lo, hi] (a sign change) to full double precision.
template <typename F>
double Toms748(const F& f, double lo, double hi) {
  const double f_lo = f(lo);
  const double f_hi = f(hi);
  if (f_lo == 0.0) return lo;
  if (f_hi == 0.0) return hi;
  if (!(f_lo * f_hi < 0.0)) return kNaN;
  std::uintmax_t iterations = 200;
  const auto bracket = boost::math::tools::toms748_solve(
      f, lo, hi, f_lo, f_hi, boost::math::tools::eps_tolerance<double>(52), iterations);
  return 0.5 * (bracket.first + bracket.second);
}

// The second order (model_form.h): 1/D depends on Omega, so G = A^2 is no
// quadratic in Omega^2. At amplitude a, G(a; Omega) has its minimum near the
// backbone (Brent's minimisation, Boost, over a bracket about the first
// order's backbone, clear of the superharmonic resonance Omega = w/3); the
// left and right roots of G(a; Omega) = A^2 lie on either side of it, each
// solved by TOMS 748 in Omega on a bracket grown outward from the minimum.
struct SecondOrderSlice {
  double omega_min = kNaN;  // [rad/s] where G(a; Omega) is least
  double excess = kNaN;     // A^2 - G(a; omega_min): >= 0 where the roots are real
};

double SliceG(const ParameterVector& p, double omega, double a) {
  return ResponseCoefficients<double>::FromParameters(kSecondOrderForm, p.data(), omega).G(a);
}

SecondOrderSlice MakeSecondOrderSlice(const ParameterVector& p, double a_base, double a) {
  SecondOrderSlice slice;
  const double x = MakeQuadratic(kSecondOrderForm, p, a_base, a).backbone_x;
  const double w = p[kNaturalFrequency];
  const double centre = x > 0.0 ? std::sqrt(x) : w;
  const double lo = std::max(0.6 * centre, 0.45 * w);
  const double hi = std::max(1.6 * centre, 1.1 * lo);
  std::uintmax_t iterations = 200;
  const auto minimum = boost::math::tools::brent_find_minima(
      [&](double omega) { return SliceG(p, omega, a); }, lo, hi, 52, iterations);
  slice.omega_min = minimum.first;
  slice.excess = a_base * a_base - minimum.second;
  return slice;
}

// Omega [rad/s] on `side` (0: left, 1: right) of the second-order curve at
// amplitude a; NaN where G(a; Omega) = A^2 has no root on that side.
double SecondOrderSideFrequency(const ParameterVector& p, double a_base, double a, int side) {
  const SecondOrderSlice slice = MakeSecondOrderSlice(p, a_base, a);
  const double target = a_base * a_base;
  // An excess rounded just below 0 at a piece's end counts as 0.
  if (!(slice.excess >= -1e-12 * target)) return kNaN;
  if (slice.excess <= 0.0) return slice.omega_min;
  auto f = [&](double omega) { return SliceG(p, omega, a) - target; };
  const double w = p[kNaturalFrequency];
  const double direction = side == 0 ? -1.0 : 1.0;
  double step = 1e-3 * slice.omega_min;
  double far = slice.omega_min;
  for (int i = 0; i < 60; ++i, step *= 2.0) {
    far = slice.omega_min + direction * step;
    if (side == 0 && far < 0.4 * w) return kNaN;  // towards the superharmonic resonance
    if (f(far) > 0.0) break;
  }
  if (!(f(far) > 0.0)) return kNaN;
  return Toms748(f, std::min(far, slice.omega_min), std::max(far, slice.omega_min));
}

// A point of the trace before folds and segments are assigned.
struct RawPoint {
  double a = 0.0;
  double omega = 0.0;
  double a_base = 0.0;
  int side = 0;         // frequency: 2 * piece + (0 left, 1 right); amplitude: 0
  bool breaks = false;  // does not continue from the previous point
};

CurvePoint MakePoint(ModelForm form, const ParameterVector& p, double omega, double a_base,
                     double a) {
  const auto k = ResponseCoefficients<double>::FromParameters(form, p.data(), omega);
  CurvePoint point;
  point.omega_rad_s = omega;
  point.a_base = a_base;
  point.a = a;
  point.dG_da = k.dG(a);
  point.stable = point.dG_da > 0.0;
  point.phase_rad = std::atan2(k.P(a), k.Q(a));
  return point;
}

// An upper bound of the frequency response's amplitude over the range:
// P = Omega D(a) <= a_base with Omega >= control_low; with mu3 (model_form.h)
// both mu1 a and mu3 a^3 / 4 are at most eta_e a_base / Omega.
double FrequencyAmplitudeBound(ModelForm form, const ParameterVector& p, const CurveSpec& spec) {
  const double rhs = spec.a_base * p[kEtaE] / spec.control_low;
  if (form.cubic_damping()) {
    const double by_mu3 = p[kMu3] > 0.0 ? std::cbrt(4.0 * rhs / p[kMu3]) : kNaN;
    const double by_mu1 = p[kMu1] > 0.0 ? rhs / p[kMu1] : kNaN;
    return std::fmin(by_mu1, by_mu3);  // the finite one where one is NaN
  }
  const double k = 4.0 * p[kMu2] / (3.0 * kPi);
  if (k > 0.0) return (-p[kMu1] + std::sqrt(p[kMu1] * p[kMu1] + 4.0 * k * rhs)) / (2.0 * k);
  return rhs / p[kMu1];
}

// Samples of [lo, hi]: geometric (the off-resonance tails) and dense towards
// hi (the peak, where Omega(a) turns like a square root), ascending.
std::vector<double> PieceSamples(double lo, double hi, int n) {
  std::vector<double> samples;
  for (int i = 0; i <= n; ++i) {
    const double t = static_cast<double>(i) / n;
    samples.push_back(lo * std::pow(hi / lo, t));
    samples.push_back(hi - (hi - lo) * (1.0 - t) * (1.0 - t));
  }
  samples.front() = lo;
  std::sort(samples.begin(), samples.end());
  samples.erase(std::unique(samples.begin(), samples.end()), samples.end());
  samples.back() = hi;
  return samples;
}

// The intervals of a where the frequency quadratic has real roots, each end
// refined on the discriminant; `lo` and `hi` bound the search.
std::vector<std::pair<double, double>> RealPieces(ModelForm form, const ParameterVector& p,
                                                  double a_base, double lo, double hi) {
  constexpr int kScan = 4000;
  auto disc = [&](double a) {
    return form.second_order() ? MakeSecondOrderSlice(p, a_base, a).excess
                               : MakeQuadratic(form, p, a_base, a).disc;
  };
  std::vector<std::pair<double, double>> pieces;
  double previous = lo;
  bool inside = disc(lo) >= 0.0;
  double start = lo;
  for (int i = 1; i <= kScan; ++i) {
    const double a = lo * std::pow(hi / lo, static_cast<double>(i) / kScan);
    const bool now = disc(a) >= 0.0;
    if (now != inside) {
      const double edge = Toms748(disc, previous, a);
      if (inside) pieces.emplace_back(start, edge);
      start = edge;
      inside = now;
    }
    previous = a;
  }
  if (inside) pieces.emplace_back(start, hi);
  return pieces;
}

bool InRange(const CurveSpec& spec, double control) {
  const double slack = 1e-12 * std::abs(spec.control_high);
  return control >= spec.control_low - slack && control <= spec.control_high + slack;
}

// The swept control on `side` at amplitude a: Omega [rad/s] or a_base.
double SideControl(ModelForm form, const ParameterVector& p, const CurveSpec& spec, double a,
                   int side) {
  if (spec.kind == SweepKind::kFrequency) {
    return form.second_order() ? SecondOrderSideFrequency(p, spec.a_base, a, side % 2)
                               : SideFrequency(form, p, spec.a_base, a, side % 2);
  }
  const auto k = ResponseCoefficients<double>::FromParameters(form, p.data(), spec.omega_rad_s);
  return std::sqrt(k.G(a));
}

// Walks the samples of one side in tracing order, keeping those inside the
// swept range, and adds the exact point where the curve crosses an end of the
// range between two samples (so the curve spans the whole range).
class RangeWalker {
 public:
  RangeWalker(ModelForm form, const ParameterVector& p, const CurveSpec& spec, int side,
              std::vector<RawPoint>* trace)
      : form_(form), p_(p), spec_(spec), side_(side), trace_(trace) {}

  void Add(double a) {
    const double c = Control(a);
    const bool in = std::isfinite(c) && InRange(spec_, c);
    if (has_previous_ && in != previous_in_ && std::isfinite(c) && std::isfinite(previous_c_)) {
      const double outside = in ? previous_c_ : c;
      const double bound = outside < spec_.control_low ? spec_.control_low : spec_.control_high;
      const double crossing = Toms748([&](double x) { return Control(x) - bound; },
                                      std::min(previous_a_, a), std::max(previous_a_, a));
      if (std::isfinite(crossing)) {
        Push(crossing, Control(crossing), in);
        open_ = in;
      }
    }
    if (in) {
      Push(a, c, !open_);
      open_ = true;
    } else {
      open_ = false;
    }
    has_previous_ = true;
    previous_in_ = in;
    previous_a_ = a;
    previous_c_ = c;
  }

 private:
  void Push(double a, double control, bool breaks) {
    const bool frequency = spec_.kind == SweepKind::kFrequency;
    trace_->push_back({a, frequency ? control : spec_.omega_rad_s,
                       frequency ? spec_.a_base : control, side_, breaks});
  }

  double Control(double a) const { return SideControl(form_, p_, spec_, a, side_); }

  const ModelForm form_;
  const ParameterVector& p_;
  const CurveSpec& spec_;
  int side_;
  std::vector<RawPoint>* trace_;
  bool has_previous_ = false, previous_in_ = false, open_ = false;
  double previous_a_ = 0.0, previous_c_ = 0.0;
};

std::vector<RawPoint> FrequencyTrace(ModelForm form, const ParameterVector& p,
                                     const CurveSpec& spec) {
  const auto k_lo = ResponseCoefficients<double>::FromParameters(form, p.data(), spec.control_low);
  const auto k_hi = ResponseCoefficients<double>::FromParameters(form, p.data(), spec.control_high);
  const double a_start = 0.25 * spec.a_base / std::sqrt(std::max(k_lo.c2(), k_hi.c2()));
  // The bound is the first order's; P's k7 a^4 may lower P, so the second
  // order searches further.
  const double a_bound = (form.second_order() ? 1.5 : 1.0) * FrequencyAmplitudeBound(form, p, spec);
  std::vector<RawPoint> trace;
  if (!(a_start > 0.0) || !(a_bound > a_start)) return trace;
  const auto pieces = RealPieces(form, p, spec.a_base, a_start, a_bound);
  for (size_t piece = 0; piece < pieces.size(); ++piece) {
    const std::vector<double> samples =
        PieceSamples(pieces[piece].first, pieces[piece].second, spec.points_per_side);
    for (int side = 0; side < 2; ++side) {
      RangeWalker walker(form, p, spec, static_cast<int>(2 * piece + side), &trace);
      for (size_t i = 0; i < samples.size(); ++i)
        walker.Add(side == 0 ? samples[i] : samples[samples.size() - 1 - i]);
    }
  }
  // The right side continues the left one over the peak.
  for (size_t i = 1; i < trace.size(); ++i) {
    const RawPoint& before = trace[i - 1];
    if (trace[i].breaks && trace[i].side == before.side + 1 && trace[i].side % 2 == 1 &&
        trace[i].a == before.a) {
      trace[i].breaks = false;
    }
  }
  return trace;
}

std::vector<RawPoint> AmplitudeTrace(ModelForm form, const ParameterVector& p,
                                     const CurveSpec& spec) {
  const auto k = ResponseCoefficients<double>::FromParameters(form, p.data(), spec.omega_rad_s);
  const TurningPoints tp = FindTurningPoints(k);
  const double target = spec.control_high * spec.control_high;
  const double seed =
      std::max(spec.control_high / std::sqrt(k.c2()), tp.exist ? 2.0 * tp.a_upper_end : 0.0);
  const double a_hi = internal::ExpandUntil(seed, [&](double a) { return k.G(a) > target; });
  std::vector<RawPoint> trace;
  if (!std::isfinite(a_hi)) return trace;
  const int n = 2 * spec.points_per_side;
  RangeWalker walker(form, p, spec, 0, &trace);
  for (int i = 0; i <= n; ++i) walker.Add(a_hi * i / n);
  return trace;
}

CurvePoint PointAt(ModelForm form, const ParameterVector& p, const CurveSpec& spec, double a,
                   int side) {
  const double control = SideControl(form, p, spec, a, side);
  const bool frequency = spec.kind == SweepKind::kFrequency;
  return MakePoint(form, p, frequency ? control : spec.omega_rad_s,
                   frequency ? spec.a_base : control, a);
}

// The fold between two points of one side whose stability differs: the root
// of dG/da(a, Omega(a)) on [a0, a1]; false when it cannot be bracketed.
bool FindFold(ModelForm form, const ParameterVector& p, const CurveSpec& spec, double a0, double a1,
              int side, CurvePoint* fold) {
  auto dg = [&](double a) { return PointAt(form, p, spec, a, side).dG_da; };
  const double a = Toms748(dg, std::min(a0, a1), std::max(a0, a1));
  if (!std::isfinite(a)) return false;
  *fold = PointAt(form, p, spec, a, side);
  const auto k = ResponseCoefficients<double>::FromParameters(form, p.data(), fold->omega_rad_s);
  fold->fold = true;
  fold->fold_kind = k.d2G(a) < 0.0 ? JumpKind::kJumpUp : JumpKind::kJumpDown;
  return std::isfinite(fold->omega_rad_s) && std::isfinite(fold->a_base);
}

// The backbone's a^2 at a fixed Omega: Q / a = k3 + k4 a^2 (+ k6 a^4) = 0, the
// second order's root the one nearest the first order's -k3 / k4.
double BackboneAmplitudeSquared(const ResponseCoefficients<double>& k) {
  const double first = k.k4 != 0.0 ? -k.k3 / k.k4 : kNaN;
  if (!k.higher_order || k.k6 == 0.0) return first;
  const double disc = k.k4 * k.k4 - 4.0 * k.k6 * k.k3;
  if (!(disc >= 0.0)) return kNaN;
  const double big = -0.5 * (k.k4 + std::copysign(std::sqrt(disc), k.k4));
  const double y1 = big / k.k6;
  const double y2 = big != 0.0 ? k.k3 / big : y1;
  return std::abs(y1 - first) < std::abs(y2 - first) ? y1 : y2;
}

// The backbone's Omega [rad/s] at amplitude a: the first order's sqrt(B / C),
// the second order's the root of Q(a; Omega) = 0 within 20 % of it.
double BackboneFrequency(ModelForm form, const ParameterVector& p, double a_base, double a) {
  const double x = MakeQuadratic(form, p, a_base, a).backbone_x;
  if (!(x > 0.0)) return kNaN;
  if (!form.second_order()) return std::sqrt(x);
  auto q = [&](double omega) {
    return ResponseCoefficients<double>::FromParameters(form, p.data(), omega).Q(a);
  };
  return Toms748(q, 0.8 * std::sqrt(x), 1.2 * std::sqrt(x));
}

void AddBackbone(ModelForm form, const ParameterVector& p, const std::vector<RawPoint>& trace,
                 ResponseCurve* curve) {
  const CurveSpec& spec = curve->spec;
  if (spec.kind == SweepKind::kAmplitude) {
    const auto k = ResponseCoefficients<double>::FromParameters(form, p.data(), spec.omega_rad_s);
    const double a2 = BackboneAmplitudeSquared(k);
    if (a2 > 0.0) {
      const double a = std::sqrt(a2);
      curve->backbone.push_back({spec.omega_rad_s, a, std::abs(k.P(a))});
    }
    return;
  }
  for (const RawPoint& raw : trace) {
    if (raw.side % 2 != 0) continue;
    const double omega = BackboneFrequency(form, p, spec.a_base, raw.a);
    if (!(omega > 0.0) || !InRange(spec, omega)) continue;
    const auto k = ResponseCoefficients<double>::FromParameters(form, p.data(), omega);
    curve->backbone.push_back({omega, raw.a, std::abs(k.P(raw.a))});
  }
}

}  // namespace

bool CurveSpec::IsValid(std::string* why) const {
  auto fail = [why](const std::string& text) {
    *why = text;
    return false;
  };
  if (kind == SweepKind::kFrequency && !(a_base > 0.0 && std::isfinite(a_base)))
    return fail(StringPrintf("a frequency curve needs a base level a_base > 0 (got %g)", a_base));
  if (kind == SweepKind::kAmplitude && !(omega_rad_s > 0.0 && std::isfinite(omega_rad_s)))
    return fail("an amplitude curve needs a drive frequency > 0");
  const double min_low = kind == SweepKind::kFrequency ? 0.0 : -1.0;
  if (!(control_low > min_low && control_high > control_low && std::isfinite(control_high)))
    return fail(StringPrintf("the swept range [%g, %g] must be finite, positive and increasing",
                             control_low, control_high));
  if (points_per_side < 10 || points_per_side > 1000000)
    return fail(StringPrintf("points_per_side %d is outside [10, 1000000]", points_per_side));
  return true;
}

ResponseCurve TraceResponseCurve(ModelForm form, const ParameterVector& p, const CurveSpec& spec) {
  std::string why;
  if (!spec.IsValid(&why)) throw InputError(spec.name, 0, "curve", why);
  if (!(p[kEtaE] > 0.0) || !(p[kMu1] >= 0.0) || !(p[kMu2] >= 0.0) || !(p[kMu1] + p[kMu2] > 0.0)) {
    const std::string mu = ParameterName(form, kMu2);
    throw InputError(spec.name, 0, "curve",
                     "the parameters make no response curve: it needs eta_e > 0, mu1 >= 0, " + mu +
                         " >= 0 and some damping (mu1 + " + mu + " > 0); give physical parameters");
  }
  const std::vector<RawPoint> trace = spec.kind == SweepKind::kFrequency
                                          ? FrequencyTrace(form, p, spec)
                                          : AmplitudeTrace(form, p, spec);
  ResponseCurve curve;
  curve.spec = spec;
  int segment = 0;
  for (size_t i = 0; i < trace.size(); ++i) {
    CurvePoint point = MakePoint(form, p, trace[i].omega, trace[i].a_base, trace[i].a);
    point.side = trace[i].side;
    point.continues = i > 0 && !trace[i].breaks;
    if (i > 0 && !point.continues) ++segment;
    const CurvePoint* previous = i > 0 ? &curve.points.back() : nullptr;
    if (point.continues && previous->stable != point.stable) {
      CurvePoint fold;
      if (previous->side == point.side &&
          FindFold(form, p, spec, previous->a, point.a, point.side, &fold)) {
        fold.side = point.side;
        fold.continues = true;
        fold.stable = previous->stable;
        fold.segment = segment;
        curve.points.push_back(fold);
        curve.folds.push_back({fold.fold_kind, curve.Control(fold), fold.a});
        fold.stable = point.stable;
        fold.segment = ++segment;
        curve.points.push_back(fold);
      } else {
        ++segment;
      }
    }
    point.segment = segment;
    curve.points.push_back(point);
  }
  AddBackbone(form, p, trace, &curve);
  return curve;
}

std::vector<CurveRoot> CurveAmplitudesAt(ModelForm form, const ParameterVector& p,
                                         const ResponseCurve& curve, double control) {
  const CurveSpec& spec = curve.spec;
  std::vector<CurveRoot> roots;
  for (size_t i = 1; i < curve.points.size(); ++i) {
    const CurvePoint& a0 = curve.points[i - 1];
    const CurvePoint& a1 = curve.points[i];
    if (!a1.continues || a0.side != a1.side || a0.a == a1.a) continue;
    const double c0 = curve.Control(a0) - control;
    const double c1 = curve.Control(a1) - control;
    const double omega = spec.kind == SweepKind::kFrequency ? control : spec.omega_rad_s;
    // A point of the trace at the control (to rounding: the exact ends of
    // the range) is a root itself.
    bool at_point = false;
    for (const CurvePoint* point : {&a0, &a1}) {
      if (std::abs(curve.Control(*point) - control) <= 1e-13 * std::abs(control)) {
        roots.push_back({point->a, DgDa(form, p, omega, point->a) > 0.0});
        at_point = true;
      }
    }
    if (at_point || c0 * c1 > 0.0) continue;
    const int side = a1.side;
    auto f = [&](double a) { return SideControl(form, p, spec, a, side) - control; };
    const double a = Toms748(f, std::min(a0.a, a1.a), std::max(a0.a, a1.a));
    if (!std::isfinite(a)) continue;
    roots.push_back({a, DgDa(form, p, omega, a) > 0.0});
  }
  std::sort(roots.begin(), roots.end(),
            [](const CurveRoot& x, const CurveRoot& y) { return x.a < y.a; });
  // One of each group of roots equal to rounding (the trace's points at the control).
  roots.erase(std::unique(roots.begin(), roots.end(),
                          [](const CurveRoot& kept, const CurveRoot& root) {
                            return std::abs(root.a - kept.a) <= 1e-12 * root.a;
                          }),
              roots.end());
  return roots;
}

double CurveAmplitudeOnBranch(const std::vector<CurveRoot>& roots, Branch branch, double a_guess) {
  double best = kNaN;
  for (const CurveRoot& root : roots) {
    if (!root.stable) continue;
    if (branch == Branch::kLower) return root.a;
    if (branch == Branch::kUpper || !std::isfinite(best) ||
        std::abs(root.a - a_guess) < std::abs(best - a_guess)) {
      best = root.a;
    }
  }
  return best;
}

}  // namespace dwellfit
