// Held-out errors with and without the per-sweep forcing calibration
// (fit/forcing_calibration.h) on one config: its fit as `identify` makes it,
// then the calibrated fit from there, each validation sweep's jump-down
// frequency and upper-branch amplitude predicted as `identify` predicts them
// (PredictHeldOut), with the calibration at the sweep's own scale from its
// dwells before the jump. build/tools/forcing_calibration writes it.
#ifndef DWELLFIT_ESTIMATOR_STUDIES_FORCING_CALIBRATION_STUDY_H_
#define DWELLFIT_ESTIMATOR_STUDIES_FORCING_CALIBRATION_STUDY_H_

#include <string>
#include <vector>

#include "dwellfit/config/identify_config.h"
#include "dwellfit/estimator/fit/forcing_calibration.h"

namespace dwellfit {

// One validation sweep's predictions: signed errors [%], NaN where the sweep
// measures no such quantity, 100 where it does and the model lacks it (no
// fold) or the fit is not usable.
struct HeldOutSweepErrors {
  std::string sweep;
  double scale = 1.0;  // s_v (1 without calibration; NaN when it failed)
  double jump_down_percent = 0.0;
  double upper_branch_percent = 0.0;
};

struct ForcingCalibrationComparison {
  std::string config;  // its path, for the report
  double prior_sigma = 0.0;
  HeldOutDwells held_out_dwells = HeldOutDwells::kBeforeJump;
  CalibratedParameter parameter = CalibratedParameter::kForcing;
  ModelForm form;  // the config's member, whose names the parameters take
  IdentificationResult without;
  CalibratedIdentification with;
  std::vector<std::string> fitted;  // the fitted sweeps' names, as `with.scales`
  std::vector<HeldOutSweepErrors> errors_without, errors_with;
  std::vector<std::string> notes;  // a held-out sweep without a scale, and why
};

// Throws InputError as ResolveRun does, or for invalid `calibration`.
ForcingCalibrationComparison CompareForcingCalibration(
    const IdentifyConfig& config, const ForcingCalibrationOptions& calibration);

// Median of |errors| of one quantity (NaN entries skipped; NaN when none).
double MedianAbsoluteError(const std::vector<HeldOutSweepErrors>& errors, bool jump_down);

// The comparison as Markdown: fits, fitted scales, per held-out sweep, medians.
std::string ForcingCalibrationMarkdown(const ForcingCalibrationComparison& comparison);

// Leave-one-level-out as select_model's `training: config` does it
// (docs/model-selection.md): each level (sweep id) of the config's fit and
// validate lists held out in turn, the config's fit sweeps fitted with a
// held-out one replaced by the nearest level not fitted (ConfigTraining), its
// sweeps predicted with and without the calibration as above.
struct LevelOutErrors {
  std::string level;  // the held-out sweep id
  std::vector<HeldOutSweepErrors> without, with;
  std::vector<std::string> notes;
};

// Throws InputError as CompareForcingCalibration does (a fold whose fit
// fails names its level).
std::vector<LevelOutErrors> LeaveOneLevelOut(const IdentifyConfig& config,
                                             const ForcingCalibrationOptions& calibration);

// The folds as Markdown: per level, then the medians over levels of each
// quantity's |error| (every held-out sweep's, pooled).
std::string LeaveOneLevelOutMarkdown(const IdentifyConfig& config,
                                     const ForcingCalibrationOptions& calibration,
                                     const std::vector<LevelOutErrors>& folds);

}  // namespace dwellfit

#endif  // DWELLFIT_ESTIMATOR_STUDIES_FORCING_CALIBRATION_STUDY_H_
