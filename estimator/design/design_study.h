// The closed loop on the virtual rig beside the standard protocol
// (docs/design-study.md): per noise seed, two arms run on VirtualRig
// (estimator/rig/rig_simulator.h), each dwell's traces processed into a dwell
// point (ProcessTraces) and fitted by the identify config's fit with every
// parameter free, from the last estimate that gave intervals (a warm start):
//
//   standard    the plan's sweeps (every sweep, each direction as planned,
//               each sweep from rest, as SimulateRig runs them), refitted at
//               the end of every sweep direction (or every `refit_dwells`
//               dwells); after the last sweep the plan runs again, until the
//               target or the budget;
//   closed loop a start of the fitted sweeps' up directions at
//               `start_step_factor` times their step (and the down directions
//               when the start's fit gives no covariance), then: the quantity
//               farthest from its target (largest half-width / target) ->
//               RecommendNextDwell for it -> its best candidate that is
//               single-valued or within `hysteresis_steps` smallest steps of
//               the present dwell -> that one dwell on the rig -> refit ...,
//               until the target or the budget.
//
// The precision target is judged after every fit by its linearised 95 %
// intervals (the data-only covariance, DesignBasisFromFit), simultaneous for
// the four quantities unless the target says otherwise: the half-width
// relative to |estimate| of alpha_e, eta_e, w and mu1 each within its bound.
// Coverage is judged on the same intervals.
// Test time is what the rig reports: every dwell's settling and recording
// seconds (RigDwell), summed.
#ifndef DWELLFIT_ESTIMATOR_DESIGN_DESIGN_STUDY_H_
#define DWELLFIT_ESTIMATOR_DESIGN_DESIGN_STUDY_H_

#include <array>
#include <cstdint>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include "dwellfit/config/identify_config.h"
#include "dwellfit/estimator/curves/figures.h"
#include "dwellfit/estimator/data/sweep.h"
#include "dwellfit/estimator/design/next_dwell.h"
#include "dwellfit/estimator/fit/staged_solve.h"
#include "dwellfit/estimator/rig/rig_simulator.h"
#include "dwellfit/estimator/simulation/dwell_simulator.h"
#include "dwellfit/estimator/traces/trace_processing.h"

namespace dwellfit {

// The quantities the target bounds, in this order.
inline constexpr int kStudyQuantities = 4;
enum StudyQuantity { kStudyAlphaE = 0, kStudyEtaE = 1, kStudyOmega = 2, kStudyMu1 = 3 };
const char* StudyQuantityName(int quantity);  // "alpha_e", "eta_e", "w", "mu1"

// Bounds on the 95 % half-width relative to |estimate| (0.01 = 1 %).
struct PrecisionTarget {
  std::array<double, kStudyQuantities> relative_half_width = {0.01, 0.005, 0.0005, 0.10};
  // Whether the half-widths are of simultaneous 95 % intervals of the four
  // quantities (each at 0.95^(1/4), SimultaneousIntervalQuantile: all four
  // hold together in at least 95 % of tests) or each quantity's own 95 %
  // interval (then all four hold together in about 0.95^4 = 81 %).
  bool simultaneous = true;
  bool IsValid(std::string* error) const;
};

struct DesignStudyOptions {
  PrecisionTarget target;
  int seeds = 10;  // >= 1; the rig's noise seeds first_seed, first_seed + 1, ...
  std::uint64_t first_seed = 1;
  double time_budget_seconds = 7200;  // simulated test time per arm and seed (> 0)
  int refit_dwells = 0;               // standard: refit every k dwells too (0: per sweep direction)
  int start_step_factor = 5;          // closed loop: the start's step in plan steps (>= 1)
  // Closed loop: the largest step between dwells [Hz] and of the base level;
  // 0: the plan's whole span (a shaker can go anywhere in one step; the
  // settling cost grows with the step).
  double frequency_step_max_hz = 0.0;  // >= 0
  double level_step_max = 0.0;         // >= 0
  double settle_time_constants = 5.0;  // next_dwell's cost model (>= 0)
  // Closed loop: a dwell in the hysteresis range (two stable roots) is taken
  // only within this many smallest steps of the present one on each axis, so
  // that the quasi-static landing rule holds (a large step into that range
  // often ends on the other attractor); the best such candidate is taken.
  int hysteresis_steps = 2;           // >= 1
  int max_closed_loop_dwells = 2000;  // a guard besides the budget (>= 1)
  // The fits' model (both arms, and next_dwell's); unset: the config's.
  std::optional<Averaging> averaging;
  bool IsValid(std::string* error) const;
};

// The case: the fit's settings (initial guess, residual, Omega_ref of
// alpha_e), the truth and the standard sweeps, the rig and its processing.
struct DesignStudyCase {
  std::string name;
  IdentifyConfig config;
  DwellPlan plan;  // noise zero: the rig adds its own
  RigOptions rig;  // noise_seed is set per seed
  TraceProcessingOptions processing;
};

// One dwell as the rig took it.
struct StudyDwell {
  std::string sweep;
  double frequency_hz = 0.0, level = 0.0;
  double settle_seconds = 0.0, record_seconds = 0.0;  // as the rig reported them
  // Closed loop: the branch next_dwell expected it to land on, and the one
  // the measured amplitude is nearer at the refitted estimate ("" otherwise).
  std::string expected_branch, landed_branch;
};

// One fit and what its intervals say.
struct StudyFit {
  int dwells = 0;                // dwells fitted
  double elapsed_seconds = 0.0;  // the rig's test time when it was made
  FitStatus status = FitStatus::kFailure;
  bool has_intervals = false;
  std::array<double, kStudyQuantities> value{}, half_width{};  // 95 %, absolute
  double interval_quantile = 0.0;  // q of the half-widths q se (PrecisionTarget::simultaneous)
  double worst_ratio = 0.0;        // largest half-width / (bound |value|); met at <= 1
  bool met = false;
};

struct ArmRun {
  std::string arm;  // "standard" or "closed_loop"
  std::uint64_t seed = 0;
  std::vector<StudyDwell> dwells;
  std::vector<StudyFit> fits;
  bool reached = false;
  double time_to_target_seconds = 0.0;  // the rig's time at the first fit that met the target
  int dwells_to_target = 0;
  double elapsed_seconds = 0.0;  // the rig's time at the end
  // Whether the last fit's 95 % intervals hold the truth (false without intervals).
  std::array<bool, kStudyQuantities> covers{};
  bool covers_all = false;
  std::string end;  // why the arm stopped
};

// Reads the case: the identify config (fit settings), the dwell plan (truth
// and standard sweeps, without noise) and the rig config (rig and processing).
// Throws InputError naming the file and the field.
DesignStudyCase LoadDesignStudyCase(const std::string& name, const std::string& config_path,
                                    const std::string& plan_path, const std::string& rig_path);

// The truth's values of the study's quantities.
std::array<double, kStudyQuantities> StudyTruth(const DesignStudyCase& study);

// The arms for one seed. Throw InputError on a case that cannot run.
ArmRun RunStandardProtocol(const DesignStudyCase& study, const DesignStudyOptions& options,
                           std::uint64_t seed);
ArmRun RunClosedLoop(const DesignStudyCase& study, const DesignStudyOptions& options,
                     std::uint64_t seed);

struct DesignStudyResult {
  std::string case_name;
  std::vector<ArmRun> standard, closed_loop;  // one per seed
};

// Both arms over the options' seeds; `progress` gets one line per arm run.
DesignStudyResult RunDesignStudy(const DesignStudyCase& study, const DesignStudyOptions& options,
                                 std::ostream* progress);

// Median of the values (the mean of the middle two for an even count); NaN
// for none.
double Median(std::vector<double> values);

// The per-seed table, the medians, the ratio of the medians and the coverage.
void PrintDesignStudy(const DesignStudyResult& result, const DesignStudyOptions& options,
                      std::ostream& out);
// design_study.csv: case,arm,seed,reached,time_to_target_s,dwells_to_target,
// elapsed_s,dwells,fits,covers_all, then per quantity value, half-width in %
// and covers.
std::string DesignStudyCsv(const std::vector<DesignStudyResult>& results);
// design_study_fits.csv: every fit of every arm (the figure's data).
std::string DesignStudyFitsCsv(const std::vector<DesignStudyResult>& results);
// design_study_dwells.csv: every dwell of every arm as the rig took it.
std::string DesignStudyDwellsCsv(const std::vector<DesignStudyResult>& results);
// The gnuplot script: per case, the largest half-width / target ratio over
// the simulated test time, every seed of both arms.
std::string DesignStudyGnuplot(const std::vector<DesignStudyResult>& results,
                               const DesignStudyOptions& options);

inline constexpr char kDesignStudyCsvName[] = "design_study.csv";
inline constexpr char kDesignStudyFitsCsvName[] = "design_study_fits.csv";

// design_study.csv, design_study_fits.csv, design_study.gp and, when
// `render`, the figure's images (or a warning line in `warning`).
std::vector<NamedFile> DesignStudyFiles(const std::vector<DesignStudyResult>& results,
                                        const DesignStudyOptions& options, bool render,
                                        std::string* warning);

}  // namespace dwellfit

#endif  // DWELLFIT_ESTIMATOR_DESIGN_DESIGN_STUDY_H_
