#include "dwellfit/estimator/curves/sweep_curves.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "dwellfit/estimator/data/sweep_csv_writer.h"

namespace dwellfit {
namespace {

double Median(std::vector<double> values) {
  std::sort(values.begin(), values.end());
  const size_t n = values.size();
  return n % 2 == 1 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
}

void WriteRow(const ResponseCurve& curve, const char* role, int segment, double omega,
              double a_base, double a, const std::string& stable, const std::string& fold,
              double phase_rad, std::ostringstream* csv) {
  *csv << curve.spec.name << ',' << SweepKindName(curve.spec.kind) << ',' << role << ',' << segment
       << ',' << FormatRoundTrip(RadPerSecondToHz(omega)) << ',' << FormatRoundTrip(a_base) << ','
       << FormatRoundTrip(a) << ',' << stable << ',' << fold << ','
       << (std::isfinite(phase_rad) ? FormatRoundTrip(phase_rad * 180.0 / kPi) : "") << '\n';
}

}  // namespace

std::vector<CurveSpec> CurveSpecsForSweeps(const std::vector<const Sweep*>& sweeps,
                                           int points_per_side) {
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
    spec.points_per_side = points_per_side;
    specs.push_back(spec);
  }
  return specs;
}

std::vector<ResponseCurve> TraceCurves(const ParameterVector& parameters,
                                       const std::vector<CurveSpec>& specs) {
  std::vector<ResponseCurve> curves;
  for (const CurveSpec& spec : specs) curves.push_back(TraceResponseCurve(parameters, spec));
  return curves;
}

std::string CurvesToCsv(const std::vector<ResponseCurve>& curves) {
  std::ostringstream csv;
  csv << "sweep,kind,curve,segment,freq_hz,a_base,a,stable,fold,phase_deg\n";
  for (const ResponseCurve& curve : curves) {
    for (const CurvePoint& p : curve.points) {
      WriteRow(curve, "response", p.segment, p.omega_rad_s, p.a_base, p.a, p.stable ? "1" : "0",
               p.fold ? JumpKindName(p.fold_kind) : "", p.phase_rad, &csv);
    }
    for (const BackbonePoint& p : curve.backbone) {
      WriteRow(curve, "backbone", -1, p.omega_rad_s, p.a_base, p.a, "", "", kPi / 2.0, &csv);
    }
  }
  return csv.str();
}

}  // namespace dwellfit
