#include "dwellfit/estimator/fit/forcing_calibration.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "ceres/problem.h"
#include "dwellfit/estimator/common/name_table.h"
#include "dwellfit/estimator/common/string_printf.h"
#include "dwellfit/estimator/fit/fit_description.h"
#include "dwellfit/estimator/fit/staged_solve.h"

namespace dwellfit {

bool ForcingCalibrationOptions::IsValid(std::string* error) const {
  if (!(prior_sigma > 0.0 && prior_sigma <= 1.0)) {
    *error =
        StringPrintf("forcing_calibration.prior_sigma must lie in (0, 1], got %g", prior_sigma);
    return false;
  }
  return true;
}

ForcingScalePrior::ForcingScalePrior(int size, int index, double weight,
                                     ParameterIndex shared_index)
    : index_(index), weight_(weight), shared_index_(shared_index) {
  set_num_residuals(1);
  *mutable_parameter_block_sizes() = {kNumParameters, size};
}

bool ForcingScalePrior::Evaluate(double const* const* parameters, double* residuals,
                                 double** jacobians) const {
  const double eta_e = parameters[0][shared_index_];
  const double eta_k = parameters[1][index_];
  if (!(eta_e > 0.0)) return false;
  residuals[0] = weight_ * (eta_k / eta_e - 1.0);
  if (jacobians == nullptr) return true;
  if (jacobians[0] != nullptr) {
    std::fill(jacobians[0], jacobians[0] + kNumParameters, 0.0);
    jacobians[0][shared_index_] = -weight_ * eta_k / (eta_e * eta_e);
  }
  if (jacobians[1] != nullptr) {
    std::fill(jacobians[1], jacobians[1] + parameter_block_sizes()[1], 0.0);
    jacobians[1][index_] = weight_ / eta_e;
  }
  return true;
}

double DataSigma(const IdentificationResult& uncalibrated, int free_parameters) {
  const int spare = uncalibrated.residual_blocks - free_parameters;
  if (uncalibrated.stages.empty() || spare < 1) return 0.0;
  return std::sqrt(2.0 * uncalibrated.stages.back().final_data_cost / spare);
}

namespace {

// Adds one ForcingScalePrior per entry of the `size` eta_k's.
std::function<void(ceres::Problem*)> Priors(double* shared, double* etas, int size, double weight,
                                            ParameterIndex index) {
  return [=](ceres::Problem* problem) {
    for (int k = 0; k < size; ++k) {
      problem->AddResidualBlock(new ForcingScalePrior(size, k, weight, index), nullptr, shared,
                                etas);
    }
  };
}

bool CheckInputs(const IdentificationOptions& options, const ForcingCalibrationOptions& calibration,
                 double data_sigma, std::string* error) {
  if (!calibration.IsValid(error) || !options.InitialIsValid(error)) return false;
  if (!(data_sigma > 0.0 && std::isfinite(data_sigma))) {
    *error = StringPrintf(
        "forcing calibration: the data's sigma must be positive, got %g "
        "(a fit without calibration with dwells to spare gives it)",
        data_sigma);
    return false;
  }
  return true;
}

}  // namespace

CalibratedIdentification IdentifyWithForcingCalibration(
    const std::vector<const Sweep*>& fitted, const IdentificationOptions& options,
    const ForcingCalibrationOptions& calibration, double data_sigma) {
  CalibratedIdentification out;
  out.data_sigma = data_sigma;
  out.fit.parameters = options.initial;
  std::string error;
  if (!CheckInputs(options, calibration, data_sigma, &error)) {
    out.fit.status = FitStatus::kInvalidInput;
    out.fit.message = error;
    return out;
  }
  const int size = static_cast<int>(fitted.size());
  const ParameterIndex index = CalibratedIndex(calibration.parameter);
  const std::string name = ParameterName(index);
  std::vector<double> etas(size, options.initial[index]);
  FitDescription fit =
      SingleBlockFit(fitted, options.fixed, &out.fit.parameters, options.solve.residual.form);
  fit.blocks.push_back({etas.data(), size, name + " per sweep"});
  fit.datasets.clear();
  for (int k = 0; k < size; ++k) {
    fit.blocks.back().entry_names.push_back(name + "[" + fitted[k]->Name() + "]");
    ParameterMap map = IdentityMap(out.fit.parameters.data());
    map[index] = {etas.data(), k};
    fit.datasets.push_back({fitted[k]->Name(), {fitted[k]}, map});
  }
  fit.add_residuals = Priors(out.fit.parameters.data(), etas.data(), size,
                             data_sigma / calibration.prior_sigma, index);
  static_cast<FitSummary&>(out.fit) = SolveStaged(fit, options.solve);
  for (double eta : etas) out.scales.push_back(eta / out.fit.parameters[index]);
  return out;
}

// In enumerator order.
constexpr const char* kHeldOutDwellsNames[] = {"before_jump", "below_half_peak"};

const char* HeldOutDwellsName(HeldOutDwells dwells) { return NameOf(kHeldOutDwellsNames, dwells); }

bool HeldOutDwellsFromName(const std::string& name, HeldOutDwells* dwells) {
  return FromName(name, kHeldOutDwellsNames, dwells);
}

// In enumerator order.
constexpr const char* kCalibratedParameterNames[] = {"eta_e", "omega"};

const char* CalibratedParameterName(CalibratedParameter parameter) {
  return NameOf(kCalibratedParameterNames, parameter);
}

bool CalibratedParameterFromName(const std::string& name, CalibratedParameter* parameter) {
  return FromName(name, kCalibratedParameterNames, parameter);
}

ParameterIndex CalibratedIndex(CalibratedParameter parameter) {
  return parameter == CalibratedParameter::kForcing ? kEtaE : kNaturalFrequency;
}

Sweep CalibrationDwells(const Sweep& sweep, HeldOutDwells dwells) {
  Sweep before = sweep;
  if (!sweep.jumps.empty()) {
    int first = static_cast<int>(sweep.points.size()) - 1;
    for (const JumpBracket& jump : sweep.jumps) first = std::min(first, jump.index_before);
    before.points.resize(static_cast<size_t>(first) + 1);
  }
  if (dwells == HeldOutDwells::kBelowHalfPeak) {
    double peak = 0.0;
    for (const DwellPoint& point : before.points) peak = std::max(peak, point.amplitude);
    std::vector<DwellPoint> low;
    for (const DwellPoint& point : before.points) {
      if (point.amplitude < 0.5 * peak) low.push_back(point);
    }
    before.points = low;
  }
  before.jumps.clear();
  before.missing.clear();
  return before;
}

double CalibrateHeldOutScale(const Sweep& sweep, const ParameterVector& parameters,
                             const IdentificationOptions& options,
                             const ForcingCalibrationOptions& calibration, double data_sigma,
                             std::string* why) {
  constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
  if (!CheckInputs(options, calibration, data_sigma, why)) return kNaN;
  const Sweep before = CalibrationDwells(sweep, calibration.held_out_dwells);
  if (before.points.size() < 2) {
    *why = sweep.Name() + ": fewer than two dwells (" +
           HeldOutDwellsName(calibration.held_out_dwells) + ") to calibrate on";
    return kNaN;
  }
  const ParameterIndex index = CalibratedIndex(calibration.parameter);
  ParameterVector shared = parameters;
  double eta = parameters[index];
  FitDescription fit;
  fit.blocks = {{shared.data(), kNumParameters, "parameters"},
                {&eta, 1, std::string(ParameterName(index)) + "[" + sweep.Name() + "]"}};
  fit.blocks[0].fixed.assign(kNumParameters, true);
  ParameterMap map = IdentityMap(shared.data());
  map[index] = {&eta, 0};
  fit.datasets = {{sweep.Name(), {&before}, map}};
  fit.add_residuals = Priors(shared.data(), &eta, 1, data_sigma / calibration.prior_sigma, index);
  StagedSolveOptions solve = options.solve;
  solve.stages = {ResidualKind::kVertical};
  solve.algebraic_start_candidate = false;
  solve.penalties = PenaltyOptions();
  const FitSummary summary = SolveStaged(fit, solve);
  if (!summary.IsSolutionUsable()) {
    *why = sweep.Name() + ": the calibration did not solve: " + summary.message;
    return kNaN;
  }
  return eta / parameters[index];
}

}  // namespace dwellfit
