// Response curves for measured sweeps, and their CSV (docs/outputs.md).
//
// One curve per sweep id: the up and down directions of a sweep share its
// held control (the median over their dwells) and the curve spans the
// controls measured in either direction.
//
// curves.csv: one row per point, in tracing order per sweep; its columns are
// documented in docs/outputs.md.
#ifndef DWELLFIT_ESTIMATOR_CURVES_SWEEP_CURVES_H_
#define DWELLFIT_ESTIMATOR_CURVES_SWEEP_CURVES_H_

#include <string>
#include <vector>

#include "dwellfit/estimator/curves/response_curve.h"
#include "dwellfit/estimator/data/sweep.h"

namespace dwellfit {

// The specs of the distinct sweep ids of `sweeps`, in first-seen order.
std::vector<CurveSpec> CurveSpecsForSweeps(const std::vector<const Sweep*>& sweeps,
                                           int points_per_side = 400);

// The traced curves of `specs` at `parameters`.
std::vector<ResponseCurve> TraceCurves(const ParameterVector& parameters,
                                       const std::vector<CurveSpec>& specs);

// curves.csv (above); numbers written to round-trip.
std::string CurvesToCsv(const std::vector<ResponseCurve>& curves);

}  // namespace dwellfit

#endif  // DWELLFIT_ESTIMATOR_CURVES_SWEEP_CURVES_H_
