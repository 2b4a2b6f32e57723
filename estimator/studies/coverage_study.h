// Coverage study: do the 95 % intervals cover the truth 95 % of the time?
//
// Replica r = 0..R-1 simulates the dwell plan with multiplicative noise
// a *= 1 + sigma_rel N(0, 1) (seed first_seed + r) and is fitted as a
// measured run (ResolveReplicaRun, FitRun). For every free parameter and
// alpha_e it counts the replicas whose interval contains the truth, and
// compares the mean standard error with the estimates' standard deviation
// (they agree when the linearised covariance is right). The intervals are
// identify's (kProfile, EstimateUncertaintyAtMinimum) or a linearised kind;
// docs/uncertainty.md has the measured table.
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
  double relative_noise = 0.01;                      // sigma_rel of DwellNoise
  std::uint64_t first_seed = 1;                      // replica r uses seed first_seed + r
  IntervalMethod method = IntervalMethod::kProfile;  // identify's
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
  // The same over the replicas with fewer than kKinkedFitDwells dwells past
  // their branch end (a smooth minimum).
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
  double mean_noise_sigma = 0.0;                 // mean estimated residual sigma
  int degrees_of_freedom = 0;                    // of the first replica
  std::vector<CoverageRow> rows;                 // free parameters in index order, then alpha_e
  std::vector<std::string> messages;             // distinct unavailability messages, if any
  bool start_from_data = false;                  // some initial guess from each replica's data
  std::vector<std::string> first_replica_jumps;  // replica 0's fitted sweeps (DescribeJumps)
  double seconds = 0.0;                          // wall time of all replicas
};

// Runs the study on the config's fitted sweeps of `plan` (its noise is
// replaced by options'); Omega_ref: the config's, else the truth's omega.
// Throws InputError as ResolveRun does on a replica.
CoverageStudy RunCoverageStudy(const IdentifyConfig& config, const DwellPlan& plan,
                               const CoverageStudyOptions& options);

// The table: parameter, truth, coverage %, mean standard error, empirical std,
// their ratio, bias / empirical std, replicas on the bound, and the coverage
// over the replicas whose fit is smooth at its minimum.
void PrintCoverageStudy(const CoverageStudy& study, std::ostream& out);

}  // namespace dwellfit

#endif  // DWELLFIT_ESTIMATOR_STUDIES_COVERAGE_STUDY_H_
