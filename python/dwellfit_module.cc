// The Python module's native part, `dwellfit._dwellfit` (pybind11): the
// library's own pipeline, called as the tools call it, with its results as
// plain Python objects and NumPy arrays. python/dwellfit/__init__.py is the
// interface users import; docs/python.md describes it.
//
// The GIL is released while the library computes (the fit, the curves, the
// simulation); InputError becomes dwellfit.InputError (a ValueError) with
// the library's message, which names the file or dict, the line and the field.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <functional>
#include <limits>
#include <map>
#include <memory>
#include <sstream>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "dwellfit/config/dwell_plan_reader.h"
#include "dwellfit/config/identify_config.h"
#include "dwellfit/estimator/common/input_error.h"
#include "dwellfit/estimator/common/version.h"
#include "dwellfit/estimator/curves/response_curve.h"
#include "dwellfit/estimator/data/sweep_csv.h"
#include "dwellfit/estimator/design/next_dwell_run.h"
#include "dwellfit/estimator/matfile/mat_sweeps.h"
#include "dwellfit/estimator/run/identify_run.h"
#include "dwellfit/estimator/simulation/dwell_simulator.h"

namespace py = pybind11;

namespace dwellfit {
namespace {

using Overrides = std::vector<std::pair<std::string, std::string>>;

std::vector<ConfigOverride> ToOverrides(const Overrides& pairs) {
  std::vector<ConfigOverride> overrides;
  for (const auto& [key, value] : pairs) overrides.push_back({key, value, "overrides"});
  return overrides;
}

// Keyed by the names of `form`'s member (model_form.h).
py::dict ByParameter(const ParameterVector& values, ModelForm form = ModelForm{}) {
  py::dict out;
  for (int i = 0; i < kNumParameters; ++i) out[ParameterName(form, i)] = values[i];
  return out;
}

// One result column: value(row) (a function or a member) for each of `rows`,
// as a NumPy array of numbers or flags, or a list when the values are names
// (const char*).
template <typename Row, typename Value>
py::object Column(const std::vector<Row>& rows, Value value) {
  using T = std::decay_t<std::invoke_result_t<Value, const Row&>>;
  if constexpr (std::is_same_v<T, const char*>) {
    std::vector<std::string> column;
    for (const Row& row : rows) column.emplace_back(std::invoke(value, row));
    return py::cast(column);
  } else {
    std::vector<T> column;
    for (const Row& row : rows) column.push_back(std::invoke(value, row));
    return py::array(py::cast(column));
  }
}

// The dwells of `sweeps` as columns: names as lists, numbers as arrays; the
// optional columns (sigma, a_base_sigma, phase_rad) NaN where a dwell has none.
py::dict SweepColumns(const std::vector<const Sweep*>& sweeps) {
  std::vector<std::string> id, direction, kind;
  std::vector<double> freq_hz, a_base, a, sigma, a_base_sigma, phase_rad;
  const auto or_nan = [](const std::optional<double>& value) {
    return value.value_or(std::numeric_limits<double>::quiet_NaN());
  };
  for (const Sweep* sweep : sweeps) {
    for (const DwellPoint& point : sweep->points) {
      id.push_back(sweep->id);
      direction.push_back(SweepDirectionName(sweep->direction));
      kind.push_back(SweepKindName(sweep->kind));
      freq_hz.push_back(RadPerSecondToHz(point.drive_frequency_rad_s));
      a_base.push_back(point.a_base);
      a.push_back(point.amplitude);
      sigma.push_back(or_nan(point.sigma));
      a_base_sigma.push_back(or_nan(point.a_base_sigma));
      phase_rad.push_back(or_nan(point.phase_rad));
    }
  }
  py::dict out;
  out["sweep"] = id;
  out["direction"] = direction;
  out["kind"] = kind;
  out["freq_hz"] = py::array(py::cast(freq_hz));
  out["a_base"] = py::array(py::cast(a_base));
  out["a"] = py::array(py::cast(a));
  out["sigma"] = py::array(py::cast(sigma));
  out["a_base_sigma"] = py::array(py::cast(a_base_sigma));
  out["phase_rad"] = py::array(py::cast(phase_rad));
  return out;
}

py::dict PredictionColumns(const IdentificationReport& report) {
  std::vector<const Sweep*> sweeps;
  std::vector<double> a_model;
  std::vector<std::string> role, branch;
  for (const SweepPrediction& prediction : report.predictions) {
    sweeps.push_back(prediction.sweep);
    for (size_t i = 0; i < prediction.model.size(); ++i) {
      a_model.push_back(prediction.model[i].a);
      role.push_back(prediction.fitted ? "fitted" : "validation");
      branch.push_back(BranchName(prediction.sweep->points[i].branch));
    }
  }
  py::dict out = SweepColumns(sweeps);
  out["role"] = role;
  out["branch"] = branch;
  out["a_model"] = py::array(py::cast(a_model));
  return out;
}

py::dict UncertaintyDict(const ParameterUncertainty& u) {
  py::dict out;
  out["available"] = u.available;
  out["message"] = u.message;
  out["interval_kind"] = u.interval_kind;
  out["standard_error"] = ByParameter(u.standard_error, u.form);
  out["ci95_low"] = ByParameter(u.ci95_low, u.form);
  out["ci95_high"] = ByParameter(u.ci95_high, u.form);
  out["warnings"] = u.warnings;
  out["effective_nonlinearity"] = u.effective_nonlinearity;
  out["effective_nonlinearity_ci95"] =
      py::make_tuple(u.effective_nonlinearity_ci95_low, u.effective_nonlinearity_ci95_high);
  return out;
}

// An identify run as a dict; `files` are the run's files (result.yaml, the
// CSVs, report.html and the figures) by name, as bytes.
py::dict OutcomeDict(const IdentifyOutcome& outcome, const std::string& printed) {
  const IdentificationReport& report = outcome.report;
  py::dict out;
  out["status"] = FitStatusName(report.result.status);
  out["message"] = report.result.message;
  out["parameters"] = ByParameter(report.result.parameters, report.options.solve.residual.form);
  out["fixed"] = std::vector<bool>(report.options.fixed.begin(), report.options.fixed.end());
  out["final_cost"] = report.result.final_cost;
  out["uncertainty"] = UncertaintyDict(report.uncertainty);
  out["predictions"] = PredictionColumns(report);
  out["printed"] = printed;
  py::dict files;
  for (const auto& [name, content] : outcome.files) files[py::str(name)] = py::bytes(content);
  out["files"] = files;
  return out;
}

IdentifyConfig LoadConfig(const std::string& path, const std::string& text,
                          const std::string& base_dir, const Overrides& overrides) {
  return text.empty() ? LoadIdentifyConfig(path, ToOverrides(overrides))
                      : ParseIdentifyConfig(path, text, base_dir, ToOverrides(overrides));
}

// identify on a config file (`text` empty) or on YAML text named `path`;
// writes into the config's output_dir when `write`.
py::dict PyIdentify(const std::string& path, const std::string& text, const std::string& base_dir,
                    const Overrides& overrides, bool write, bool figures) {
  std::unique_ptr<IdentifyOutcome> outcome;
  std::ostringstream printed;
  {
    py::gil_scoped_release release;
    const IdentifyConfig config = LoadConfig(path, text, base_dir, overrides);
    IdentifyRunOptions options;
    options.render_figures = figures;
    outcome =
        write ? RunIdentify(config, printed, options) : ComputeIdentify(config, printed, options);
  }
  return OutcomeDict(*outcome, printed.str());
}

py::dict PyLoadSweeps(const std::string& path) {
  LoadedSweeps loaded;
  {
    py::gil_scoped_release release;
    loaded = IsMatFileName(path) ? LoadSweepsMat(path) : LoadSweepsCsv(path);
  }
  std::vector<const Sweep*> sweeps;
  for (const Sweep& sweep : loaded.sweeps) sweeps.push_back(&sweep);
  return SweepColumns(sweeps);
}

// The model's response curve at `parameters` (omega in rad/s): a frequency
// sweep at base level `held` over [low_hz, high_hz], or an amplitude sweep at
// `held` Hz over base levels [low, high].
py::dict PyCurve(const std::map<std::string, double>& parameters, const std::string& kind,
                 double held, double low, double high, int points_per_side,
                 const std::string& averaging) {
  ModelForm form;
  if (!AveragingFromName(averaging, &form.averaging)) {
    throw InputError("averaging", 0, "averaging",
                     "give 'first_order' or 'second_order', not '" + averaging + "'");
  }
  // The member follows from the names (model_form.h): mu3 for mu2, alpha5
  // for delta.
  if (parameters.count("mu3")) form.damping = DampingTerm::kCubic;
  if (parameters.count("alpha5")) form.backbone = BackboneTerm::kQuintic;
  if (form.second_order() && form.family_terms()) {
    throw InputError("averaging", 0, "averaging",
                     "the second order is derived for the chapter's terms only; give "
                     "'first_order' with mu3 or alpha5");
  }
  ParameterVector p{};
  for (int i = 0; i < kNumParameters; ++i) {
    const std::string name = ParameterName(form, i);
    const auto it = parameters.find(name);
    if (it == parameters.end()) {
      throw InputError("parameters", 0, name,
                       "give every parameter (mu2 or mu3, delta or alpha5, and the others)");
    }
    p[i] = it->second;
  }
  if (parameters.size() != static_cast<std::size_t>(kNumParameters)) {
    throw InputError("parameters", 0, "parameters",
                     "give six parameters: mu2 and mu3 (or delta and alpha5) are alternatives");
  }
  CurveSpec spec;
  spec.name = "curve";
  if (kind != "frequency" && kind != "amplitude") {
    throw InputError("kind", 0, "kind", "give 'frequency' or 'amplitude', not '" + kind + "'");
  }
  spec.kind = kind == "frequency" ? SweepKind::kFrequency : SweepKind::kAmplitude;
  const bool frequency = spec.kind == SweepKind::kFrequency;
  spec.a_base = frequency ? held : 0.0;
  spec.omega_rad_s = frequency ? 0.0 : HzToRadPerSecond(held);
  spec.control_low = frequency ? HzToRadPerSecond(low) : low;
  spec.control_high = frequency ? HzToRadPerSecond(high) : high;
  spec.points_per_side = points_per_side;
  ResponseCurve curve;
  {
    py::gil_scoped_release release;
    curve = TraceResponseCurve(form, p, spec);
  }
  const std::vector<CurvePoint>& points = curve.points;
  py::dict out;
  out["freq_hz"] =
      Column(points, [](const CurvePoint& p) { return RadPerSecondToHz(p.omega_rad_s); });
  out["a_base"] = Column(points, &CurvePoint::a_base);
  out["a"] = Column(points, &CurvePoint::a);
  out["phase_rad"] = Column(points, &CurvePoint::phase_rad);
  out["stable"] = Column(points, &CurvePoint::stable);
  out["fold"] = Column(points, &CurvePoint::fold);
  return out;
}

// next_dwell on a config (as identify's): the fit of the dwells so far and
// the candidates ranked best first, as columns.
py::dict PyNextDwell(const std::string& path, const std::string& text, const std::string& base_dir,
                     const Overrides& overrides, const std::string& state,
                     const std::string& limits, const std::string& target, double noise_sigma,
                     int segment_dwells, double settle_time_constants, double recording_seconds) {
  DesignOptions options;
  options.noise_sigma = noise_sigma;
  options.segment_dwells = segment_dwells;
  options.settle_time_constants = settle_time_constants;
  options.recording_seconds = recording_seconds;
  NextDwellRequest request = MakeNextDwellRequest(state, limits, target, options, "");
  request.render_figures = false;
  std::unique_ptr<NextDwellOutcome> outcome;
  std::ostringstream printed;
  {
    py::gil_scoped_release release;
    const IdentifyConfig config = LoadConfig(path, text, base_dir, overrides);
    outcome = std::make_unique<NextDwellOutcome>(ComputeNextDwell(config, request, printed));
  }
  const std::vector<Candidate>& ranked = outcome->recommendation.ranked;
  py::dict candidates;
  candidates["freq_hz"] = Column(ranked, &Candidate::frequency_hz);
  candidates["level"] = Column(ranked, &Candidate::level);
  candidates["dwells"] = Column(ranked, &Candidate::dwells);
  candidates["branch"] = Column(ranked, [](const Candidate& c) { return BranchName(c.branch); });
  candidates["jumps"] = Column(ranked, &Candidate::jumps);
  candidates["a"] = Column(ranked, &Candidate::amplitude);
  candidates["settle_seconds"] = Column(ranked, &Candidate::settle_seconds);
  candidates["record_seconds"] = Column(ranked, &Candidate::record_seconds);
  candidates["gain"] = Column(ranked, &Candidate::gain);
  candidates["gain_per_second"] = Column(ranked, &Candidate::gain_per_second);
  py::dict out;
  out["status"] = FitStatusName(outcome->fit.status);
  out["message"] = outcome->fit.message;
  out["parameters"] = ByParameter(outcome->fit.parameters);
  out["target"] = outcome->recommendation.target.Name();
  out["candidates"] = candidates;
  out["printed"] = printed.str();
  return out;
}

// The dwells a plan (plan YAML text, or a file when `text` is empty) makes.
py::dict PySimulate(const std::string& path, const std::string& text) {
  std::vector<Sweep> sweeps;
  {
    py::gil_scoped_release release;
    sweeps = SimulateDwells(text.empty() ? ReadDwellPlan(path) : ParseDwellPlan(text, path));
  }
  std::vector<const Sweep*> pointers;
  for (const Sweep& sweep : sweeps) pointers.push_back(&sweep);
  return SweepColumns(pointers);
}

}  // namespace
}  // namespace dwellfit

PYBIND11_MODULE(_dwellfit, m) {
  m.doc() = "dwellfit's native part; import dwellfit instead.";
  static py::exception<dwellfit::InputError> input_error(m, "InputError", PyExc_ValueError);
  py::register_exception_translator([](std::exception_ptr error) {
    try {
      if (error) std::rethrow_exception(error);
    } catch (const dwellfit::InputError& e) {
      input_error(e.what());
    }
  });
  m.def("identify", &dwellfit::PyIdentify, py::arg("path"), py::arg("text"), py::arg("base_dir"),
        py::arg("overrides"), py::arg("write"), py::arg("figures"));
  m.def("load_sweeps", &dwellfit::PyLoadSweeps, py::arg("path"));
  m.def("curve", &dwellfit::PyCurve, py::arg("parameters"), py::arg("kind"), py::arg("held"),
        py::arg("low"), py::arg("high"), py::arg("points_per_side"), py::arg("averaging"));
  m.def("next_dwell", &dwellfit::PyNextDwell, py::arg("path"), py::arg("text"), py::arg("base_dir"),
        py::arg("overrides"), py::arg("state"), py::arg("limits"), py::arg("target"),
        py::arg("noise_sigma"), py::arg("segment_dwells"), py::arg("settle_time_constants"),
        py::arg("recording_seconds"));
  m.def("simulate", &dwellfit::PySimulate, py::arg("path"), py::arg("text"));
  m.attr("__version__") = dwellfit::DwellfitVersion();
}
