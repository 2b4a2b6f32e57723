// Coverage study: do the 95 % intervals of EstimateUncertainty cover the
// truth 95 % of the time?
//
// Each replica r = 0..R-1 simulates the dwell plan with multiplicative noise
// a *= 1 + sigma_rel N(0, 1) (seed first_seed + r) and takes the path of a
// measured run (resolved_run.h): branches labelled by jump detection on the
// noisy sweeps and the config's `jumps:`, the config's sweeps selected, the
// initial guesses it leaves out found from the replica's data, the fit
// (multi-start when configured), and the uncertainty at the estimate. For every free parameter and
// for alpha_e = alpha - (2/3) delta Omega_ref^2 it counts the replicas whose 95 % interval contains
// the plan's truth, and compares the mean standard error with the empirical standard deviation of
// the estimates over the replicas (the two agree when the linearised covariance is right).
// The intervals are those identify reports (IntervalMethod::kProfile: the profile likelihood of
// the fitted cost, the fit made a minimum first, EstimateUncertaintyAtMinimum), or a linearised
// kind for comparison; docs/uncertainty.md has the measured table.
#ifndef DWELLFIT_ESTIMATOR_STUDIES_COVERAGE_STUDY_H_
#define DWELLFIT_ESTIMATOR_STUDIES_COVERAGE_STUDY_H_

#include <cstdint>
#include <ostream>
#include <string>
#include <vector>

#include "dwellfit/config/identify_config.h"
#include "dwellfit/estimator/analysis/parameter_uncertainty.h"
#include "dwellfit/estimator/simulation/dwell_simulator.h"

namespace dwellfit {

struct CoverageStudyOptions {
  int replicas = 200;
  double relative_noise = 0.01;  // sigma_rel of DwellNoise
  std::uint64_t first_seed = 1;  // replica r uses seed first_seed + r
  // How the intervals treat the bifurcation-range penalty
  // (parameter_uncertainty.h); identify uses the default.
  IntervalMethod method = IntervalMethod::kProfile;
};

// A fit that leaves this many fitted dwells past the end of their branch
// (ParameterUncertainty::dwells_past_branch_end) sits at a kink of the cost.
inline constexpr int kKinkedFitDwells = 2;

// One row of the table: a free parameter or the effective nonlinearity.
struct CoverageRow {
  std::string name;  // parameter name, or "alpha_e"
  double truth = 0.0;
  int covered = 0;   // replicas whose interval contains the truth
  int replicas = 0;  // all replicas; one without an interval counts as a miss
  double mean_estimate = 0.0;
  double empirical_std = 0.0;        // sample standard deviation of the estimates
  double mean_standard_error = 0.0;  // over replicas with an interval
  int on_bound = 0;  // replicas whose estimate sits on its bound 0 (eta_e, mu1, mu2)
  // The same count over the replicas whose fit left fewer than
  // kKinkedFitDwells dwells past their branch end (a smooth minimum).
  int smooth_covered = 0;
  int smooth_replicas = 0;

  double SmoothCoverage() const {
    return smooth_replicas > 0 ? static_cast<double>(smooth_covered) / smooth_replicas : 0.0;
  }

  double Coverage() const { return replicas > 0 ? static_cast<double>(covered) / replicas : 0.0; }
};

struct CoverageStudy {
  int replicas = 0;
  int converged = 0;  // fits whose last stage converged
  int available = 0;  // replicas with a covariance
  IntervalMethod method = IntervalMethod::kProfile;
  bool penalty = false;        // the bifurcation-range penalty was on
  int with_penalty_terms = 0;  // replicas with the penalty's curvature in their intervals
  int refitted = 0;            // replicas fitted again from a lower point their profile found
  int kinked = 0;              // replicas with a fitted dwell past its branch end
  double omega_ref_rad_s = 0.0;
  double mean_noise_sigma = 0.0;      // mean estimated residual sigma
  int degrees_of_freedom = 0;         // of the first replica
  std::vector<CoverageRow> rows;      // free parameters in index order, then alpha_e
  std::vector<std::string> messages;  // distinct unavailability messages, if any
  // Whether some initial guess came from each replica's data.
  bool start_from_data = false;
  // Replica 0's fitted sweeps with their jumps (DescribeJumps).
  std::vector<std::string> first_replica_jumps;
  double seconds = 0.0;  // wall time of all replicas
};

// Runs the study on the config's fitted sweeps of `plan` (its noise is
// replaced by options'). Omega_ref: the config's effective-nonlinearity
// reference, else the truth's omega. Throws InputError when the plan, the
// selection or a `jumps:` entry does not fit the simulated sweeps, or when no
// start can be found from a replica's data.
CoverageStudy RunCoverageStudy(const IdentifyConfig& config, const DwellPlan& plan,
                               const CoverageStudyOptions& options);

// The table: parameter, truth, coverage %, mean standard error, empirical std,
// their ratio, bias / empirical std, replicas on the bound, and the coverage
// over the replicas whose fit is smooth at its minimum.
void PrintCoverageStudy(const CoverageStudy& study, std::ostream& out);

}  // namespace dwellfit

#endif  // DWELLFIT_ESTIMATOR_STUDIES_COVERAGE_STUDY_H_
