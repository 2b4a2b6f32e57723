// The test as run: what drives the structure (`excitation:`) and which
// quantity is measured (`response:`), and the exact map between the measured
// sweeps and the model's form, a displacement response to a base
// acceleration (docs/model.md, "The test as run").
//
// With p the response's power and q the excitation's (below), a dwell at
// drive frequency Omega [rad/s] maps as
//   a      = y / Omega^p           (y the measured first-harmonic amplitude)
//   sigma  = sigma_y / Omega^p
//   a_base = level * Omega^q       (level the file's a_base column)
//   gamma  = gamma_measured - offset + p pi/2
// where gamma is the lag of the displacement behind the forcing: a velocity
// leads the displacement by 90 deg, an acceleration by 180 deg.
#ifndef DWELLFIT_ESTIMATOR_DATA_MEASURED_QUANTITY_H_
#define DWELLFIT_ESTIMATOR_DATA_MEASURED_QUANTITY_H_

#include <optional>
#include <string>
#include <vector>

#include "dwellfit/estimator/data/sweep.h"

namespace dwellfit {

enum class Excitation {
  kBaseAcceleration,  // a_base is the base acceleration (q = 0; the chapter's form)
  kBaseDisplacement,  // a_base is the base displacement; the model's level is Omega^2 a_base (q =
                      // 2)
  kForce,             // a_base is a force; eta_e = 1/(2 m) per force unit (q = 0)
};
enum class Response {
  kDisplacement,  // p = 0
  kVelocity,      // p = 1
  kAcceleration,  // p = 2
};

const char* ExcitationName(Excitation excitation);
bool ExcitationFromName(const std::string& name, Excitation* excitation);
const char* ResponseName(Response response);
bool ResponseFromName(const std::string& name, Response* response);

struct TestQuantities {
  Excitation excitation = Excitation::kBaseAcceleration;
  Response response = Response::kDisplacement;
  // The phase column's offset [rad]: the column holds gamma_measured + offset
  // where gamma_measured is the measured quantity's lag behind the forcing.
  double phase_offset_rad = 0.0;
  // `phase: {offset: estimate}`: the offset is estimated from the sweeps'
  // peaks (EstimatePhaseOffset) instead of stated.
  bool estimate_phase_offset = false;

  // p: the measured amplitude is Omega^p times the displacement amplitude.
  int ResponsePower() const;
  // q: the model's forcing level is Omega^q times the file's level.
  int LevelPower() const;
  // True for the model's own form (the defaults): mapping changes nothing.
  bool IsModelForm() const {
    return excitation != Excitation::kBaseDisplacement && response == Response::kDisplacement &&
           phase_offset_rad == 0.0 && !estimate_phase_offset;
  }
};

// The offset [rad] of the sweeps' phase columns, estimated on the
// assumption that the largest displacement of each frequency sweep id (both
// directions) lies on the backbone, where the displacement lags the forcing
// by 90 deg: the median over the ids of gamma_column - (pi/2 - p pi/2),
// wrapped into [-pi, pi]. Near the top of a lightly damped response the
// phase changes fast, so the estimate is as good as the dwells near the peak
// are dense (an up-sweep of a hardening mode ends its upper branch there).
// None when no frequency sweep has a phase at its peak.
std::optional<double> EstimatePhaseOffset(const TestQuantities& test,
                                          const std::vector<const Sweep*>& sweeps);

// Maps a measured sweep (its jumps and missing rows too) into the model's
// form, in place, with `phase_offset_rad` as the offset (the stated or the
// estimated one). Throws InputError for a frequency sweep driven by base
// displacement (its base acceleration Omega^2 a_base changes along the
// sweep, and the model's curves and folds hold the level fixed).
void ToModelForm(const TestQuantities& test, double phase_offset_rad, Sweep* sweep);

// One direction of the map: into the model's form (`to_model`) or back into
// the measured quantities (for outputs).
class QuantityMap {
 public:
  QuantityMap(const TestQuantities& test, double phase_offset_rad, bool to_model);

  double Amplitude(double value, double omega_rad_s) const;
  double Level(double value, double omega_rad_s) const;
  double Phase(double rad) const;
  // A jump of a sweep of `kind` (an amplitude sweep's frequency `held_omega`).
  void Apply(SweepKind kind, double held_omega_rad_s, JumpBracket* jump) const;
  // The points, missing rows and jumps of `sweep`.
  void Apply(Sweep* sweep) const;

 private:
  int p_ = 0, q_ = 0;
  bool to_model_ = true;
  double phase_shift_rad_ = 0.0;
};

// The factor Omega^power (power 0, 1 or 2).
inline double OmegaPower(double omega_rad_s, int power) {
  return power == 0 ? 1.0 : power == 1 ? omega_rad_s : omega_rad_s * omega_rad_s;
}

}  // namespace dwellfit

#endif  // DWELLFIT_ESTIMATOR_DATA_MEASURED_QUANTITY_H_
