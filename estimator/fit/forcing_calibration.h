// Per-sweep forcing calibration: the level control of a shaker is imperfect
// (datasets/clamped-beam-27C/README.md), so sweep k's forcing is s_k times
// its nominal level.
//
// The model sees the forcing only through the product eta_e a_base
// (response_model.h: every k_i carries 1/eta_e and a fixed point satisfies
// G(a) = a_base^2), so sweep k is fitted with an eta_e of its own,
// eta_k = s_k eta_e (one entry per fitted sweep; the other five parameters
// shared, eta_e itself read only by the prior), and each scale gets the prior
// residual (ForcingScalePrior)
//
//   r_k = sigma_data (s_k - 1) / sigma_prior,   s_k = eta_k / eta_e,
//
// a normal prior of standard deviation sigma_prior on s_k. The staged solve
// minimises (1/2) sum r^2 over the dwells' unstandardised residuals, so the
// prior is put in their unit: sigma_data = sqrt(2 F / (n - p)), the dwells'
// residual standard deviation in the fit without calibration (F its data
// cost, n dwells, p free parameters); the cost is then sigma_data^2 times the
// negative log posterior of data with that noise. Normal rather than
// log-normal: for sigma_prior of a few per cent the two differ by
// O(sigma_prior^2) in s_k.
//
// A held-out (validation) sweep v gets its scale from its own dwells up to
// its first measured jump (the branch before the jump) alone, every model
// parameter held at the calibrated fit, the vertical error and the same
// prior: its jump stays a prediction. Those dwells include an up-sweep's
// upper branch, whose amplitude is then fitted rather than predicted;
// HeldOutDwells::kBelowHalfPeak keeps only the dwells before the jump whose
// amplitude is below half the largest there (the off-resonance flank, where
// the response is nearly proportional to the forcing), disjoint from the
// upper-branch dwells (UpperBranchDwells), so both stay predictions.
#ifndef DWELLFIT_ESTIMATOR_FIT_FORCING_CALIBRATION_H_
#define DWELLFIT_ESTIMATOR_FIT_FORCING_CALIBRATION_H_

#include <string>
#include <vector>

#include "ceres/cost_function.h"
#include "dwellfit/estimator/data/sweep.h"
#include "dwellfit/estimator/fit/identification.h"
#include "dwellfit/estimator/fit/identification_options.h"

namespace dwellfit {

enum class HeldOutDwells { kBeforeJump, kBelowHalfPeak };
const char* HeldOutDwellsName(HeldOutDwells dwells);  // "before_jump", "below_half_peak"
bool HeldOutDwellsFromName(const std::string& name, HeldOutDwells* dwells);

// The parameter a sweep gets of its own: eta_e (its forcing, the default),
// or w (its natural frequency: a structure that drifts between sweeps, with
// temperature or between sessions). The scale s_k is then w_k / w and the
// prior is on it; everything below reads "eta" as the calibrated parameter.
enum class CalibratedParameter { kForcing, kNaturalFrequency };
const char* CalibratedParameterName(CalibratedParameter parameter);  // "eta_e", "omega"
bool CalibratedParameterFromName(const std::string& name, CalibratedParameter* parameter);
ParameterIndex CalibratedIndex(CalibratedParameter parameter);  // kEtaE, kNaturalFrequency
struct ForcingCalibrationOptions {
  double prior_sigma = 0.05;  // sigma_prior: the relative spread of a sweep's level, in (0, 1]
  HeldOutDwells held_out_dwells = HeldOutDwells::kBeforeJump;
  CalibratedParameter parameter = CalibratedParameter::kForcing;
  bool IsValid(std::string* error) const;
};

// r = weight (eta_k / eta_e - 1), weight = sigma_data / sigma_prior, on the
// parameter blocks (the shared 6-block, whose entry kEtaE is eta_e; a block
// of `size` per-sweep eta_e's, entry `index` being eta_k). Analytic
// derivatives: dr/d eta_e = -weight eta_k / eta_e^2, dr/d eta_k = weight / eta_e.
// With `shared_index` kNaturalFrequency the same with w and w_k.
class ForcingScalePrior : public ceres::CostFunction {
 public:
  ForcingScalePrior(int size, int index, double weight, ParameterIndex shared_index = kEtaE);
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

 private:
  int index_;
  double weight_;
  ParameterIndex shared_index_;
};

// sigma_data of a fit without calibration (above); 0 when it has no dwells
// to spare.
double DataSigma(const IdentificationResult& uncalibrated, int free_parameters);

struct CalibratedIdentification {
  IdentificationResult fit;    // the shared parameters; eta_e of the nominal levels
  std::vector<double> scales;  // s_k of each fitted sweep, in order
  double data_sigma = 0.0;
};

// The staged solve of options.solve with one eta_k per sweep of `fitted` and
// the prior, from options.initial (each s_k from 1). `data_sigma` > 0.
CalibratedIdentification IdentifyWithForcingCalibration(
    const std::vector<const Sweep*>& fitted, const IdentificationOptions& options,
    const ForcingCalibrationOptions& calibration, double data_sigma);

// The dwells of `sweep` up to the one before its first measured jump (all
// when it has none), without jumps; with kBelowHalfPeak only those below half
// the largest amplitude among them: what a held-out sweep is calibrated on.
Sweep CalibrationDwells(const Sweep& sweep, HeldOutDwells dwells);

// s_v of a held-out sweep at `parameters` (above); NaN with `why` when the
// sweep has fewer than two dwells before its jump or the solve fails.
double CalibrateHeldOutScale(const Sweep& sweep, const ParameterVector& parameters,
                             const IdentificationOptions& options,
                             const ForcingCalibrationOptions& calibration, double data_sigma,
                             std::string* why);

}  // namespace dwellfit

#endif  // DWELLFIT_ESTIMATOR_FIT_FORCING_CALIBRATION_H_
