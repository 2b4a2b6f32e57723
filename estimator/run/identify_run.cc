#include "dwellfit/estimator/run/identify_run.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <utility>

#include "dwellfit/estimator/analysis/parameter_uncertainty.h"
#include "dwellfit/estimator/common/input_error.h"
#include "dwellfit/estimator/common/memory_policy.h"
#include "dwellfit/estimator/curves/sweep_curves.h"
#include "dwellfit/estimator/data/jump_detection.h"
#include "dwellfit/estimator/fit/parallel_residual_evaluator.h"
#include "dwellfit/estimator/matfile/result_mat.h"
#include "dwellfit/estimator/run/html_report.h"
#include "dwellfit/estimator/run/measured_outputs.h"
#include "dwellfit/estimator/run/output_files.h"
#include "dwellfit/estimator/run/run_figures.h"
#include "glog/logging.h"
#include "tbb/task_arena.h"
#include "tbb/task_group.h"

namespace dwellfit {

namespace {

// Throws when the best start is no estimate at all: a stage could not
// evaluate its cost (every start failed), or the estimate is not finite.
void CheckUsable(const IdentifyConfig& config, const MultiStartResult& multi_start) {
  const IdentificationResult& result = multi_start.best;
  if (result.status == FitStatus::kInvalidInput || result.evaluation_failed) {
    throw InputError(
        config.config_path, 0, "initial_guess",
        "the fit cannot proceed: " + result.message +
            (multi_start.starts.size() > 1 ? " (and every other start failed too)" : "") +
            "; give initial guesses closer to the data (initial_guess, config/README.md), or "
            "check the dwells named");
  }
  if (multi_start.failed > 0) {
    LOG(WARNING) << multi_start.failed << " of " << multi_start.starts.size()
                 << " starts failed (their cost could not be evaluated); the best of the others "
                    "is kept";
  }
  for (double value : result.parameters) {
    if (!std::isfinite(value)) {
      throw InputError(config.config_path, 0, "initial_guess",
                       "the solver returned no usable solution; start closer to the data "
                       "(see config/README.md, initial_guess)");
    }
  }
}

// A converged fit whose free parameters the data cannot tell apart (no
// covariance) is unidentifiable: the estimate is one of many. (A fit that
// did not converge keeps that status: its covariance says little.)
void MarkUnidentifiable(IdentificationReport* report) {
  IdentificationResult& result = report->result;
  const bool any_free =
      std::count(report->options.fixed.begin(), report->options.fixed.end(), false) > 0;
  if (!any_free || report->uncertainty.available || result.status != FitStatus::kConverged) return;
  result.status = FitStatus::kUnidentifiable;
  result.converged = false;
  result.message =
      "the data cannot tell the free parameters apart: " + report->uncertainty.message + "; " +
      result.message;
}

// Below this many dwells the parts after the fit run on the calling thread:
// starting the thread pool (0.6 ms) costs more than it saves (the thesis
// case, 456 dwells, is no faster on two threads; the beam's 24,576 gain).
constexpr std::size_t kMinDwellsForThreadsAfterFit = 2048;
// From this many dwells on the run keeps its memory down: the fit's freed
// memory goes back to the kernel (ReturnFreedMemory) and the parts after it
// run one after the other (each holds ~180 bytes per dwell at its peak). On
// a million dwells the peak fell from 631 MB to 336 MB.
constexpr std::size_t kLargeRunDwells = 100000;

// The predictions of every sweep (report->predictions, `predictions_csv`)
// and the response curves (`curves`), side by side on the run's threads
// between the two limits above; each part writes only its own outputs.
void ComputeAfterFit(const ResolvedRun& run, const IdentificationResult& result,
                     IdentificationReport* report, std::string* predictions_csv,
                     RunCurves* curves) {
  std::vector<const Sweep*> sweeps = run.fitted;
  sweeps.insert(sweeps.end(), run.validation.begin(), run.validation.end());
  std::size_t dwells = 0;
  for (const Sweep* sweep : sweeps) dwells += sweep->points.size();
  const ModelForm form = run.options.solve.residual.form;
  const auto trace_curves = [&] { *curves = TraceRunCurves(form, result.parameters, sweeps); };
  const auto predict = [&] {
    report->predictions = PredictSweeps(form, result.parameters, run.fitted, run.validation);
    *predictions_csv = ReportToPredictionsCsv(*report);
  };
  const int threads = std::min(ResolveThreadCount(run.options.solve.solver.num_threads), 2);
  const bool large = dwells >= kLargeRunDwells;
  if (large) ReturnFreedMemory();
  if (threads == 1 || dwells < kMinDwellsForThreadsAfterFit || large) {
    trace_curves();
    predict();
  } else {
    tbb::task_arena arena(threads);
    arena.execute([&] {
      tbb::task_group group;
      group.run(trace_curves);
      predict();
      group.wait();
    });
  }
}

// omega(a) and zeta(a) over the fitted dwells' amplitudes, with bands from
// the fit's covariance when it has one.
ModalProperties FitModalProperties(ModelForm form, const std::vector<const Sweep*>& fitted,
                                   const IdentificationReport& report) {
  double a_min = std::numeric_limits<double>::infinity(), a_max = 0.0;
  for (const Sweep* sweep : fitted) {
    for (const DwellPoint& point : sweep->points) {
      a_min = std::min(a_min, point.amplitude);
      a_max = std::max(a_max, point.amplitude);
    }
  }
  const ParameterUncertainty& u = report.uncertainty;
  return ComputeModalProperties(form, report.result.parameters,
                                u.available ? &u.covariance : nullptr, a_min, a_max);
}

// result.mat from result.yaml and the CSVs among `files` (docs/matlab.md).
void AppendResultMat(std::vector<NamedFile>* files) {
  std::string result_yaml;
  std::vector<NamedFile> csv_files;
  for (const NamedFile& file : *files) {
    const std::string& name = file.first;
    if (name == "result.yaml") result_yaml = file.second;
    if (name.size() > 4 && name.compare(name.size() - 4, 4, ".csv") == 0) csv_files.push_back(file);
  }
  files->emplace_back("result.mat", ResultMatBytes(result_yaml, csv_files));
}

}  // namespace

int ExitStatusFor(FitStatus status, bool accept_no_convergence) {
  switch (status) {
    case FitStatus::kConverged:
      return kExitConverged;
    case FitStatus::kNoConvergence:
      return accept_no_convergence ? kExitConverged : kExitNoConvergence;
    case FitStatus::kFailure:
      return kExitFailure;
    case FitStatus::kUnidentifiable:
      return kExitUnidentifiable;
    case FitStatus::kInvalidInput:
      return kExitInputError;
  }
  return kExitFailure;
}

std::unique_ptr<IdentifyOutcome> ComputeIdentify(const IdentifyConfig& config, std::ostream& out,
                                                 const IdentifyRunOptions& run_options) {
  out << "# config in effect\n" << ConfigToYaml(config) << "\n";
  auto outcome = std::make_unique<IdentifyOutcome>();
  outcome->run = ResolveRun(config);
  const ResolvedRun& run = outcome->run;
  for (const Sweep* sweep : run.fitted)
    out << "fit      " << DescribeMeasuredJumps(config.test, run.phase_offset_rad, *sweep) << "\n";
  for (const Sweep* sweep : run.validation)
    out << "validate " << DescribeMeasuredJumps(config.test, run.phase_offset_rad, *sweep) << "\n";
  out << "\n";
  const auto print_steps = [&out](bool print, const char* title, const auto& steps) {
    if (!print) return;
    out << title << ":\n";
    for (const std::string& step : steps) out << "  " << step << "\n";
    out << "\n";
  };
  if (!run.phase_note.empty()) {
    out << run.phase_note << "\n\n";
    if (config.test.estimate_phase_offset) LOG(WARNING) << run.phase_note;
  }
  if (config.forcing_calibration.has_value())
    out << "note: forcing_calibration is run by the forcing_calibration tool; identify fits one "
           "eta_e for every sweep\n\n";
  print_steps(run.guessed_from_data, "automatic initial guess", run.initial_guess_steps);
  print_steps(!run.automatic_start_steps.empty(), "automatic start of the multi-start",
              run.automatic_start_steps);

  MultiStartResult multi_start = FitRun(run);
  CheckUsable(config, multi_start);
  // The profile intervals; where a profile finds a lower cost the fit goes
  // on from there, so the best result may change here.
  IdentificationResult& result = multi_start.best;
  const double omega_ref_rad_s =
      config.omega_ref_rad_s.value_or(result.parameters[kNaturalFrequency]);
  ParameterUncertainty uncertainty =
      EstimateUncertaintyAtMinimum(run.fitted, run.options, omega_ref_rad_s, &result,
                                   ResolveThreadCount(run.options.solve.solver.num_threads));
  IdentificationReport& report = outcome->report;
  report.config_path = config.config_path;
  report.options = run.options;
  report.options.initial = multi_start.starts[multi_start.best_start];  // the best fit's start
  report.result = result;
  report.omega_ref_rad_s = config.omega_ref_rad_s.value_or(result.parameters[kNaturalFrequency]);
  report.initial_guess_steps = run.initial_guess_steps;
  report.multi_start = multi_start;
  report.uncertainty = std::move(uncertainty);
  // An estimated phase offset is an error source the intervals do not hold.
  if (config.test.estimate_phase_offset) report.uncertainty.warnings.push_back(run.phase_note);
  const std::string range = SecondOrderRangeProblem(run, result.parameters[kNaturalFrequency]);
  if (!range.empty()) report.uncertainty.warnings.push_back("at the estimate, " + range);
  std::string predictions_csv;
  RunCurves curves;
  ComputeAfterFit(run, result, &report, &predictions_csv, &curves);
  AddModelError(run.fitted, run.validation,
                ResolveThreadCount(run.options.solve.solver.num_threads), &report);
  report.config_in_effect = ConfigToYaml(config, ConfigKeys::kAffectingTheResult);
  MarkUnidentifiable(&report);
  report.modal = FitModalProperties(run.options.solve.residual.form, run.fitted, report);
  if (!config.test.IsModelForm()) {
    MapOutputsToMeasured(config.test, run.phase_offset_rad, &outcome->run.sweeps, &report,
                         &curves.curves);
    predictions_csv = ReportToPredictionsCsv(report);
    curves.csv = CurvesToCsv(curves.curves);
  }
  PrintReport(report, out);
  std::vector<NamedFile> files = {{"result.yaml", ReportToYaml(report)},
                                  {"predictions.csv", std::move(predictions_csv)},
                                  {"modal_properties.csv", ModalPropertiesCsv(report.modal)}};
  const std::string figures_note = AppendCurvesAndFigures(report, config, std::move(curves), &files,
                                                          out, run_options.render_figures);
  if (run_options.write_mat || config.write_mat) AppendResultMat(&files);
  files.emplace_back(kHtmlReportName, ReportToHtml(report, files, figures_note,
                                                   ModelFormUnits(config.units, config.test)));
  outcome->files = std::move(files);
  return outcome;
}

std::unique_ptr<IdentifyOutcome> RunIdentify(const IdentifyConfig& config, std::ostream& out,
                                             const IdentifyRunOptions& run_options) {
  CheckOutputDirectory(config.output_dir, "output_dir");
  std::unique_ptr<IdentifyOutcome> outcome = ComputeIdentify(config, out, run_options);
  WriteFilesAtomically(config.output_dir, outcome->files);
  out << "\nwrote into " << config.output_dir << ":";
  for (const NamedFile& file : outcome->files) out << " " << file.first;
  out << " (listed in " << kManifestFileName << ")\n";
  return outcome;
}

}  // namespace dwellfit
