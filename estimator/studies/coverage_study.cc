#include "dwellfit/estimator/studies/coverage_study.h"

#include <algorithm>
#include <chrono>
#include <cmath>

#include "dwellfit/estimator/analysis/parameter_uncertainty.h"
#include "dwellfit/estimator/common/string_printf.h"
#include "dwellfit/estimator/data/jump_detection.h"
#include "dwellfit/estimator/fit/identification.h"
#include "dwellfit/estimator/fit/parallel_residual_evaluator.h"
#include "dwellfit/estimator/run/resolved_run.h"
#include "dwellfit/estimator/studies/replica_run.h"

namespace dwellfit {
namespace {

// Running sums of one row over the replicas.
struct RowSums {
  double sum = 0.0;
  double sum_squares = 0.0;
  double sum_standard_error = 0.0;
  int with_interval = 0;

  void Add(double estimate) {
    sum += estimate;
    sum_squares += estimate * estimate;
  }
};

void Finish(const RowSums& sums, CoverageRow* row) {
  const int n = row->replicas;
  if (n == 0) return;
  row->mean_estimate = sums.sum / n;
  if (n > 1) {
    const double variance =
        (sums.sum_squares - n * row->mean_estimate * row->mean_estimate) / (n - 1);
    row->empirical_std = std::sqrt(std::max(variance, 0.0));
  }
  if (sums.with_interval > 0)
    row->mean_standard_error = sums.sum_standard_error / sums.with_interval;
}

// Adds one replica's fit and uncertainty to the study; `rows` are the
// parameter indices of study->rows (kNumParameters: alpha_e).
void AddReplica(const IdentificationResult& result, const ParameterUncertainty& u,
                const std::vector<int>& rows, std::vector<RowSums>* sums, CoverageStudy* study) {
  study->converged += result.converged;
  study->with_penalty_terms += u.penalty_terms > 0;
  study->kinked += u.dwells_past_branch_end > 0;
  if (u.available) {
    ++study->available;
  } else if (std::find(study->messages.begin(), study->messages.end(), u.message) ==
             study->messages.end()) {
    study->messages.push_back(u.message);
  }
  for (size_t j = 0; j < rows.size(); ++j) {
    const bool effective = rows[j] == kNumParameters;
    const double estimate = effective ? u.effective_nonlinearity : result.parameters[rows[j]];
    const double low = effective ? u.effective_nonlinearity_ci95_low : u.ci95_low[rows[j]];
    const double high = effective ? u.effective_nonlinearity_ci95_high : u.ci95_high[rows[j]];
    const double standard_error =
        effective ? u.effective_nonlinearity_standard_error : u.standard_error[rows[j]];
    CoverageRow& row = study->rows[j];
    (*sums)[j].Add(estimate);
    const bool bounded = rows[j] == kEtaE || rows[j] == kMu1 || rows[j] == kMu2;
    row.on_bound += bounded && estimate <= 0.0;
    if (!u.available) continue;
    ++(*sums)[j].with_interval;
    (*sums)[j].sum_standard_error += standard_error;
    const bool covered = low <= row.truth && row.truth <= high;
    row.covered += covered;
    if (u.dwells_past_branch_end < kKinkedFitDwells) {
      ++row.smooth_replicas;
      row.smooth_covered += covered;
    }
  }
}

}  // namespace

CoverageStudy RunCoverageStudy(const IdentifyConfig& config, const DwellPlan& plan,
                               const CoverageStudyOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  CoverageStudy study;
  study.replicas = options.replicas;
  study.method = options.method;
  study.penalty = config.identification.solve.penalties.bifurcation_range.enabled;
  study.omega_ref_rad_s = config.omega_ref_rad_s.value_or(plan.truth[kNaturalFrequency]);

  std::vector<int> rows;  // the free parameters, then alpha_e (index kNumParameters)
  for (int i = 0; i < kNumParameters; ++i) {
    if (!config.identification.fixed[i]) rows.push_back(i);
  }
  rows.push_back(kNumParameters);
  std::vector<RowSums> sums(rows.size());
  for (int index : rows) {
    CoverageRow row;
    row.name = index < kNumParameters ? ParameterName(index) : "alpha_e";
    row.truth = index < kNumParameters ? plan.truth[index]
                                       : EffectiveNonlinearity(plan.truth, study.omega_ref_rad_s);
    row.replicas = options.replicas;
    study.rows.push_back(row);
  }

  double sum_noise_sigma = 0.0;
  for (int r = 0; r < options.replicas; ++r) {
    const ResolvedRun run = ResolveReplicaRun(config, plan, options.relative_noise,
                                              options.first_seed + static_cast<std::uint64_t>(r));
    IdentificationResult result = FitRun(run).best;
    const double fitted_cost = result.final_cost;
    const ParameterUncertainty u =
        options.method == IntervalMethod::kProfile
            ? EstimateUncertaintyAtMinimum(run.fitted, run.options, study.omega_ref_rad_s, &result,
                                           ResolveThreadCount(run.options.solve.solver.num_threads))
            : EstimateUncertainty(run.fitted, run.options, result.parameters, study.omega_ref_rad_s,
                                  &result, options.method);
    study.refitted += result.final_cost != fitted_cost;
    if (r == 0) {
      study.degrees_of_freedom = u.degrees_of_freedom;
      study.start_from_data = run.guessed_from_data;
      for (const Sweep* sweep : run.fitted)
        study.first_replica_jumps.push_back(DescribeJumps(*sweep));
    }
    if (u.available) sum_noise_sigma += u.noise_sigma;
    AddReplica(result, u, rows, &sums, &study);
  }
  for (size_t j = 0; j < rows.size(); ++j) Finish(sums[j], &study.rows[j]);
  if (study.available > 0) study.mean_noise_sigma = sum_noise_sigma / study.available;
  study.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return study;
}

void PrintCoverageStudy(const CoverageStudy& study, std::ostream& out) {
  out << StringPrintf(
      "%d replicas: %d converged, %d with a covariance; %d degrees of freedom; mean "
      "noise sigma %.4g; alpha_e at Omega_ref = 2 pi %.4g Hz; %.2f s\n",
      study.replicas, study.converged, study.available, study.degrees_of_freedom,
      study.mean_noise_sigma, RadPerSecondToHz(study.omega_ref_rad_s), study.seconds);
  out << StringPrintf(
      "bifurcation-range penalty %s; intervals: %s (%d replicas with the penalty's curvature in "
      "the linearisation, %d fitted again from a lower point their profile found); %d replicas "
      "with a fitted dwell past its branch end\n",
      study.penalty ? "on" : "off", IntervalMethodName(study.method), study.with_penalty_terms,
      study.refitted, study.kinked);
  out << "start: " << (study.start_from_data ? "found from each replica's data" : "the config's")
      << "; replica 0's fitted sweeps:\n";
  for (const std::string& jumps : study.first_replica_jumps) out << "  " << jumps << "\n";
  out << StringPrintf("%-9s %12s %10s %12s %12s %8s %9s %9s %17s\n", "parameter", "truth",
                      "coverage", "mean se", "empirical sd", "se/sd", "bias/sd", "on bound",
                      "smooth-fit cover");
  for (const CoverageRow& row : study.rows) {
    const double ratio =
        row.empirical_std > 0.0 ? row.mean_standard_error / row.empirical_std : 0.0;
    const double bias =
        row.empirical_std > 0.0 ? (row.mean_estimate - row.truth) / row.empirical_std : 0.0;
    out << StringPrintf("%-9s %12.5g %9.1f%% %12.4g %12.4g %8.3f %9.3f %9d %7.1f%% of %4d\n",
                        row.name.c_str(), row.truth, 100.0 * row.Coverage(),
                        row.mean_standard_error, row.empirical_std, ratio, bias, row.on_bound,
                        100.0 * row.SmoothCoverage(), row.smooth_replicas);
  }
  for (const std::string& message : study.messages) out << "no covariance: " << message << "\n";
}

}  // namespace dwellfit
