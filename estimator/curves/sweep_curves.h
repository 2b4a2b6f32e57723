// Response curves for measured sweeps, and their curves.csv (docs/outputs.md).
//
// One curve per sweep id: the up and down directions of a sweep share its
// held control (the median over their dwells) and the curve spans the
// controls measured in either direction.
#ifndef DWELLFIT_ESTIMATOR_CURVES_SWEEP_CURVES_H_
#define DWELLFIT_ESTIMATOR_CURVES_SWEEP_CURVES_H_

#include <string>
#include <vector>

#include "dwellfit/estimator/curves/response_curve.h"
#include "dwellfit/estimator/data/sweep.h"

namespace dwellfit {

// The specs of the distinct sweep ids of `sweeps`, in first-seen order.
std::vector<CurveSpec> CurveSpecsForSweeps(const std::vector<const Sweep*>& sweeps);

// The traced curves of `specs` at `parameters`.
std::vector<ResponseCurve> TraceCurves(ModelForm form, const ParameterVector& parameters,
                                       const std::vector<CurveSpec>& specs);

// curves.csv: one row per point, in tracing order; numbers round-trip.
std::string CurvesToCsv(const std::vector<ResponseCurve>& curves);

}  // namespace dwellfit

#endif  // DWELLFIT_ESTIMATOR_CURVES_SWEEP_CURVES_H_
