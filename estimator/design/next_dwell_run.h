// `next_dwell` as configured: the identify config's fit (resolved_run.h),
// its linearised covariance as the design basis, the recommendation
// (next_dwell.h), and what the tool prints and writes: the ranked candidates
// with the expected 95 % intervals after each, next_dwell.csv and a gnuplot
// figure of the gain per second over frequency and level.
#ifndef DWELLFIT_ESTIMATOR_DESIGN_NEXT_DWELL_RUN_H_
#define DWELLFIT_ESTIMATOR_DESIGN_NEXT_DWELL_RUN_H_

#include <ostream>
#include <string>
#include <vector>

#include "dwellfit/config/identify_config.h"
#include "dwellfit/estimator/curves/figures.h"
#include "dwellfit/estimator/data/sweep.h"
#include "dwellfit/estimator/design/next_dwell.h"
#include "dwellfit/estimator/fit/identification.h"

namespace dwellfit {

inline constexpr char kNextDwellCsvName[] = "next_dwell.csv";
inline constexpr char kNextDwellFigureStem[] = "figure_next_dwell";

// "f_hz=41.5,level=0.01,branch=upper" (branch: upper, lower or only).
// Throws InputError naming `flag` and the key.
RigState ParseRigState(const std::string& text, const std::string& flag);

// The sweeps' own span: frequencies and levels from their smallest to
// largest, the whole span as the largest step, and as the smallest the
// smallest step between consecutive dwells of the frequency sweeps (of the
// amplitude sweeps for the level; a tenth of the smallest level, a hundredth
// of the lowest frequency, without such sweeps).
RigLimits LimitsFromSweeps(const std::vector<const Sweep*>& sweeps);

// `limits` with the keys of "f_min_hz=38,f_max_hz=46,f_step_min_hz=0.1,
// f_step_max_hz=2,level_min=0.002,level_max=0.05,level_step_min=0.001,
// level_step_max=0.01" set (any subset). Throws InputError naming `flag`.
RigLimits OverrideLimits(RigLimits limits, const std::string& text, const std::string& flag);

// The basis of a finished fit of `fitted`: its linearised data-only
// covariance (EstimateUncertainty, IntervalMethod::kDataOnly). False, with
// the reason in `why`, when the fit gives no covariance (the data cannot tell
// the free parameters apart).
bool DesignBasisFromFit(const std::vector<const Sweep*>& fitted,
                        const IdentificationOptions& options, const ParameterVector& estimate,
                        double omega_ref_rad_s, DesignBasis* basis, std::string* why);

struct NextDwellRequest {
  RigState state;
  std::string limits_text;  // OverrideLimits' keys over LimitsFromSweeps
  DesignOptions options;
  bool render_figures = true;
};

struct NextDwellOutcome {
  IdentificationResult fit;
  DesignBasis basis;
  RigLimits limits;
  Recommendation recommendation;
  std::vector<NamedFile> files;  // next_dwell.csv, next_dwell.gp, the figure's images
};

// Fits the config's sweeps, ranks the next dwells and prints the top ones to
// `out`. Throws InputError on bad input. A fit that failed is returned with
// its status and no candidates; one without a covariance likewise, with
// status kUnidentifiable and the reason as its message.
// The request from its texts, over `options`' numbers: `state` as
// ParseRigState reads it, `limits` as OverrideLimits does and `target` as
// ParseDesignTarget does; the options validated here, once. Messages name
// `prefix` + "state", "target" (e.g. prefix "--" for the tool's flags).
// Throws InputError.
NextDwellRequest MakeNextDwellRequest(const std::string& state, const std::string& limits,
                                      const std::string& target, DesignOptions options,
                                      const std::string& prefix);

NextDwellOutcome ComputeNextDwell(const IdentifyConfig& config, const NextDwellRequest& request,
                                  std::ostream& out);

// The printed table: the top candidates, then every free parameter's (and
// the target's) 95 % interval now and after each of them.
void PrintRecommendation(const Recommendation& recommendation, int top, std::ostream& out);

// next_dwell.csv: one row per candidate, ranked.
std::string NextDwellCsv(const Recommendation& recommendation);

// The gnuplot script drawing the gain per second over frequency and level
// from next_dwell.csv, the present state and the best candidate marked.
std::string NextDwellGnuplot(const RigState& state, const Recommendation& recommendation);

}  // namespace dwellfit

#endif  // DWELLFIT_ESTIMATOR_DESIGN_NEXT_DWELL_RUN_H_
