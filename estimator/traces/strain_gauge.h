// From strain-gauge voltage to modal displacement (eqs. 3.4-3.7), and back.
//
//   e   = 4 V_out / (V_excite G K_g)            (3.4) strain
//   s11 = E e                                   (3.5) stress
//   M   = s11 I / c                             (3.6) bending moment (the beam
//         relation s11 = M c / I; the printed (3.6) has c and I swapped)
//   M   = E I u phi'' / [1 + (u phi')^2]^(3/2)  (3.7) fully nonlinear moment
//
// E and I cancel, leaving e(u) = c u phi'' / [1 + (u phi')^2]^(3/2), with c
// half the thickness and phi', phi'' the slope and curvature of the mode
// shape at the gauge. u is the modal coordinate: the displacement at the
// point where |phi| is largest (the tip of a cantilever, the middle of a
// clamped-clamped beam's first mode), in the unit of the beam's lengths.
// e(u) rises monotonically for |u phi'| < 1/sqrt(2); (3.7) is solved for u
// there, sample by sample, by Newton's method (Boost.Math).
#ifndef DWELLFIT_ESTIMATOR_TRACES_STRAIN_GAUGE_H_
#define DWELLFIT_ESTIMATOR_TRACES_STRAIN_GAUGE_H_

#include <string>

namespace dwellfit {

enum class BeamBoundary { kCantilever, kClampedClamped };

// The beam, its mode and the gauge's bridge.
struct StrainGaugeOptions {
  BeamBoundary boundary = BeamBoundary::kCantilever;
  int mode = 1;                      // 1, 2 or 3
  double length_m = 0.8382;          // span (33 in)
  double thickness_m = 7.9375e-4;    // 1/32 in; c = thickness / 2
  double gauge_position_m = 0.0254;  // arc length from the (first) clamp
  double excitation_v = 5.0;         // V_excite
  double gain = 1000.0;              // G of the signal conditioner
  double gauge_factor = 2.1;         // K_g

  bool IsValid(std::string* error) const;
};

// Slope and curvature of the mode shape, normalised to max |phi| = 1.
struct ModeShapeAtGauge {
  double slope_per_m = 0.0;       // phi'
  double curvature_per_m2 = 0.0;  // phi''
};

// The classical Euler-Bernoulli mode (beta_n L from the characteristic
// equation, cosh/cos form). `options` must be valid.
ModeShapeAtGauge ModeShapeAt(const StrainGaugeOptions& options);

class StrainGauge {
 public:
  // `options` must be valid (checked by the caller).
  explicit StrainGauge(const StrainGaugeOptions& options);

  // V_out for a modal displacement u [m].
  double VoltageFromDisplacement(double u_m) const;
  // u [m] from V_out; false when |V| exceeds the largest voltage the relation
  // can give (|u phi'| = 1/sqrt(2)).
  bool DisplacementFromVoltage(double volts, double* u_m) const;
  // Volts per metre at small u: c phi'' V_excite G K_g / 4.
  double SmallSignalVoltsPerMetre() const {
    return volts_per_strain_ * c_ * shape_.curvature_per_m2;
  }

 private:
  double StrainFromDisplacement(double u_m) const;

  ModeShapeAtGauge shape_;
  double c_;                 // half thickness [m]
  double volts_per_strain_;  // V_excite G K_g / 4
};

}  // namespace dwellfit

#endif  // DWELLFIT_ESTIMATOR_TRACES_STRAIN_GAUGE_H_
