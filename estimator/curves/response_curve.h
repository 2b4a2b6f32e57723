// The model's whole response curve for one sweep: every branch with its
// stability, the folds and the backbone, traced exactly with the response
// amplitude a as the independent variable (docs/model.md, "Fixed points" and
// "Stability and folds"; docs/outputs.md, curves.csv).
//
// Amplitude sweep at a fixed drive frequency Omega: a_base(a) = sqrt(G(a)) of
// eq. (3.11) is explicit; the folds are the turning points of G.
//
// Frequency sweep at a fixed base level A: with x = Omega^2, eqs. (3.1)-(3.3)
// give P = Omega D(a) and Q = B(a) - C(a) x, where
//   D = (mu1 + 4 mu2 a / (3 pi)) a / eta_e,
//   B = a (4 w^2 + 3 alpha a^2) / (8 eta_e),   C = a (4 + 2 delta a^2) / (8 eta_e),
// so G(a; Omega) = A^2 is the quadratic in x (the first order; ModelForm,
// model_form.h)
//   C^2 x^2 + (D^2 - 2 B C) x + (B^2 - A^2) = 0,
// with discriminant D^2 (D^2 - 4 B C) + 4 C^2 A^2 (written so, it does not
// cancel). Each amplitude has zero, one or two drive frequencies: the left
// root (x-) and the right root (x+) meet at the peak of the curve, where the
// discriminant vanishes. The curve is traced up the left side and down the
// right side. A point is stable iff dG/da > 0; the folds are where dG/da
// changes sign along the curve (a local extremum of Omega(a)), refined by
// Boost's TOMS 748 on dG/da(a, Omega(a)). The backbone is Q = 0:
// Omega_bb^2 = B / C = (4 w^2 + 3 alpha a^2) / (4 + 2 delta a^2).
//
// The second order's k6 and k7 hold 1/D, D = 9 Omega^2 - w^2, so G = A^2 is no
// quadratic in Omega^2: at each amplitude the minimum of G(a; Omega) over
// Omega (Brent) parts the left root from the right one, each solved on
// G(a; Omega) = A^2 by TOMS 748; the pieces are where that minimum is below
// A^2. Stability, folds (dG/da = 0) and the backbone (Q = 0) are the full
// model's. Amplitude curves are explicit in either form.
#ifndef DWELLFIT_ESTIMATOR_CURVES_RESPONSE_CURVE_H_
#define DWELLFIT_ESTIMATOR_CURVES_RESPONSE_CURVE_H_

#include <string>
#include <vector>

#include "dwellfit/residuals/model/model_parameters.h"
#include "dwellfit/residuals/model/stable_root.h"
#include "dwellfit/residuals/model/sweep_vocabulary.h"

namespace dwellfit {

// Which curve to trace: the held control and the range of the swept one.
struct CurveSpec {
  std::string name;  // names the curve in the CSV (a sweep id)
  SweepKind kind = SweepKind::kFrequency;
  double a_base = 0.0;       // frequency sweep: the held base level (data's unit)
  double omega_rad_s = 0.0;  // amplitude sweep: the held drive frequency [rad/s]
  double control_low = 0.0;  // swept range: Omega [rad/s] or a_base
  double control_high = 0.0;
  int points_per_side = 400;  // samples per side of the curve (before folds are added)

  // Checks the spec; on failure says what is wrong in `why`.
  bool IsValid(std::string* why) const;
};

struct CurvePoint {
  double omega_rad_s = 0.0;
  double a_base = 0.0;
  double a = 0.0;
  double dG_da = 0.0;  // its sign is the stability
  bool stable = false;
  int segment = 0;    // runs of equal stability along the curve; a fold starts a new one
  bool fold = false;  // the exact fold (it ends one segment and starts the next)
  JumpKind fold_kind = JumpKind::kJumpDown;
  double phase_rad = 0.0;  // lag gamma = atan2(P, Q)
  int side = 0;            // frequency: 2 * piece + (0 left root, 1 right root); amplitude: 0
  bool continues = false;  // joined to the previous point by the curve
};

struct CurveFold {
  JumpKind kind = JumpKind::kJumpDown;  // jump-up: the lower branch ends; jump-down: the upper
  double control = 0.0;                 // Omega [rad/s] or a_base
  double a = 0.0;
};

struct BackbonePoint {
  double omega_rad_s = 0.0;
  double a = 0.0;
  double a_base = 0.0;  // P(a) there: the base level whose peak sits on the backbone
};

struct ResponseCurve {
  CurveSpec spec;
  std::vector<CurvePoint> points;  // in tracing order
  std::vector<CurveFold> folds;    // in tracing order
  std::vector<BackbonePoint> backbone;
  double Control(const CurvePoint& p) const {
    return spec.kind == SweepKind::kFrequency ? p.omega_rad_s : p.a_base;
  }
};

// One amplitude of the model at a control value, with its stability.
struct CurveRoot {
  double a = 0.0;
  bool stable = false;
};

// Traces the curve of `spec` at `parameters` (omega in rad/s). Throws
// InputError (field `curve`) for an invalid spec, or when the parameters
// make no curve (eta_e = 0, no damping so the frequency response has no peak).
// `form`: the response model's (model_form.h).
ResponseCurve TraceResponseCurve(ModelForm form, const ParameterVector& parameters,
                                 const CurveSpec& spec);

// Every amplitude of the traced curve at one control value (Omega [rad/s] or
// a_base) inside the curve's range, ascending: each bracketed between two
// consecutive points of the trace and solved on the exact curve (TOMS 748 in a).
std::vector<CurveRoot> CurveAmplitudesAt(ModelForm form, const ParameterVector& parameters,
                                         const ResponseCurve& curve, double control);

// The curve's amplitude on `branch` at `control`: the smallest stable root
// (kLower), the largest (kUpper), or the stable root nearest `a_guess`
// (kOnly). NaN when the curve has no stable root there.
double CurveAmplitudeOnBranch(const std::vector<CurveRoot>& roots, Branch branch, double a_guess);

}  // namespace dwellfit

#endif  // DWELLFIT_ESTIMATOR_CURVES_RESPONSE_CURVE_H_
