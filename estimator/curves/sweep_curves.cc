#include "dwellfit/estimator/curves/sweep_curves.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>

#include "dwellfit/estimator/data/csv_text.h"

namespace dwellfit {
namespace {

double Median(std::vector<double> values) {
  std::sort(values.begin(), values.end());
  const size_t n = values.size();
  return n % 2 == 1 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
}

// One curves.csv row appended to `csv`; a phase that is not finite is left
// empty.
void AppendRow(const ResponseCurve& curve, const char* role, int segment, double omega,
               double a_base, double a, const char* stable, const char* fold, double phase_rad,
               CsvText* csv) {
  csv->Text(curve.spec.name);
  csv->Text(SweepKindName(curve.spec.kind));
  csv->Text(role);
  csv->Integer(segment);
  csv->Number(RadPerSecondToHz(omega));
  csv->Number(a_base);
  csv->Number(a);
  csv->Text(stable);
  csv->Text(fold);
  if (std::isfinite(phase_rad)) {
    csv->Number(phase_rad * 180.0 / kPi);
  } else {
    csv->Empty();
  }
  csv->EndRow();
}

// About the length of one curves.csv row, to reserve the text at once.
constexpr size_t kCurveRowBytes = 112;

}  // namespace

std::vector<CurveSpec> CurveSpecsForSweeps(const std::vector<const Sweep*>& sweeps) {
  std::vector<CurveSpec> specs;
  for (const Sweep* first : sweeps) {
    if (std::any_of(specs.begin(), specs.end(),
                    [first](const CurveSpec& s) { return s.name == first->id; })) {
      continue;
    }
    std::vector<double> held, controls;
    for (const Sweep* sweep : sweeps) {
      if (sweep->id != first->id) continue;
      for (const DwellPoint& point : sweep->points) {
        controls.push_back(sweep->Control(point));
        held.push_back(sweep->kind == SweepKind::kFrequency ? point.a_base
                                                            : point.drive_frequency_rad_s);
      }
      for (const MissingDwell& row : sweep->missing) controls.push_back(sweep->Control(row));
    }
    if (controls.empty()) continue;
    CurveSpec spec;
    spec.name = first->id;
    spec.kind = first->kind;
    (spec.kind == SweepKind::kFrequency ? spec.a_base : spec.omega_rad_s) = Median(held);
    spec.control_low = *std::min_element(controls.begin(), controls.end());
    spec.control_high = *std::max_element(controls.begin(), controls.end());
    specs.push_back(spec);
  }
  return specs;
}

std::vector<ResponseCurve> TraceCurves(ModelForm form, const ParameterVector& parameters,
                                       const std::vector<CurveSpec>& specs) {
  std::vector<ResponseCurve> curves;
  for (const CurveSpec& spec : specs) curves.push_back(TraceResponseCurve(form, parameters, spec));
  return curves;
}

std::string CurvesToCsv(const std::vector<ResponseCurve>& curves) {
  size_t rows = 1;
  for (const ResponseCurve& curve : curves) rows += curve.points.size() + curve.backbone.size();
  CsvText csv("sweep,kind,curve,segment,freq_hz,a_base,a,stable,fold,phase_deg",
              rows * kCurveRowBytes);
  for (const ResponseCurve& curve : curves) {
    for (const CurvePoint& p : curve.points) {
      AppendRow(curve, "response", p.segment, p.omega_rad_s, p.a_base, p.a, p.stable ? "1" : "0",
                p.fold ? JumpKindName(p.fold_kind) : "", p.phase_rad, &csv);
    }
    for (const BackbonePoint& p : curve.backbone) {
      AppendRow(curve, "backbone", -1, p.omega_rad_s, p.a_base, p.a, "", "", kPi / 2.0, &csv);
    }
  }
  return std::move(csv).Release();
}

}  // namespace dwellfit
