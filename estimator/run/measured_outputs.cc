#include "dwellfit/estimator/run/measured_outputs.h"

#include <algorithm>

#include "dwellfit/estimator/data/jump_detection.h"

namespace dwellfit {
namespace {

void MapCurve(const QuantityMap& map, ResponseCurve* curve) {
  CurveSpec& spec = curve->spec;
  if (spec.kind == SweepKind::kAmplitude) {
    spec.control_low = map.Level(spec.control_low, spec.omega_rad_s);
    spec.control_high = map.Level(spec.control_high, spec.omega_rad_s);
  } else {
    // A frequency curve holds its level; ToModelForm refused a level that
    // moves with Omega, so the map of the level is Omega-free here.
    spec.a_base = map.Level(spec.a_base, 1.0);
  }
  for (CurvePoint& point : curve->points) {
    point.a = map.Amplitude(point.a, point.omega_rad_s);
    point.a_base = map.Level(point.a_base, point.omega_rad_s);
    point.phase_rad = map.Phase(point.phase_rad);
  }
  for (CurveFold& fold : curve->folds) {
    const double omega = spec.kind == SweepKind::kFrequency ? fold.control : spec.omega_rad_s;
    fold.a = map.Amplitude(fold.a, omega);
    if (spec.kind == SweepKind::kAmplitude) fold.control = map.Level(fold.control, omega);
  }
  for (BackbonePoint& point : curve->backbone) {
    point.a = map.Amplitude(point.a, point.omega_rad_s);
    point.a_base = map.Level(point.a_base, point.omega_rad_s);
  }
}

}  // namespace

void MapOutputsToMeasured(const TestQuantities& test, double phase_offset_rad,
                          std::vector<Sweep>* sweeps, IdentificationReport* report,
                          std::vector<ResponseCurve>* curves) {
  if (test.IsModelForm() && phase_offset_rad == 0.0) return;
  const QuantityMap map(test, phase_offset_rad, /*to_model=*/false);
  for (Sweep& sweep : *sweeps) {  // the predicted ones: those in the model's form
    const auto predicted = [&sweep](const SweepPrediction& p) { return p.sweep == &sweep; };
    if (std::any_of(report->predictions.begin(), report->predictions.end(), predicted)) {
      map.Apply(&sweep);
    }
  }
  for (SweepPrediction& prediction : report->predictions) {
    const Sweep& sweep = *prediction.sweep;
    for (std::size_t i = 0; i < sweep.points.size(); ++i) {
      prediction.model[i].a =
          map.Amplitude(prediction.model[i].a, sweep.points[i].drive_frequency_rad_s);
    }
    const double held_omega =
        sweep.points.empty() ? 0.0 : sweep.points.front().drive_frequency_rad_s;
    for (PredictedJump& jump : prediction.jumps) {
      map.Apply(sweep.kind, held_omega, &jump.bracket);
      if (sweep.kind == SweepKind::kAmplitude) jump.control = map.Level(jump.control, held_omega);
    }
    ScoreSweepPrediction(&prediction);
  }
  for (ResponseCurve& curve : *curves) MapCurve(map, &curve);
}

std::string DescribeMeasuredJumps(const TestQuantities& test, double phase_offset_rad,
                                  const Sweep& sweep) {
  if (test.IsModelForm()) return DescribeJumps(sweep);
  Sweep measured = sweep;
  QuantityMap(test, phase_offset_rad, /*to_model=*/false).Apply(&measured);
  return DescribeJumps(measured);
}

}  // namespace dwellfit
