// Response curves for measured sweeps, and their CSV (docs/outputs.md).
//
// One curve per sweep id: the up and down directions of a sweep share its
// held control (the median over their dwells) and the curve spans the
// controls measured in either direction.
//
// curves.csv columns (one row per point, in tracing order per sweep):
//   sweep      the sweep id
//   kind       frequency | amplitude
//   curve      response | backbone
//   segment    response: runs of equal stability along the curve, numbered
//              from 0 per sweep; a fold row ends one segment and starts the
//              next (it appears twice); backbone: -1
//   freq_hz    drive frequency [Hz]
//   a_base     base level (the data's unit)
//   a          response amplitude (the data's unit)
//   stable     1 stable (dG/da > 0), 0 unstable; empty on the backbone
//   fold       jump_up (the lower branch ends) | jump_down (the upper branch
//              ends) on a fold row, else empty
//   phase_deg  lag of the response behind the base, atan2(P, Q) [degrees]
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

// The CSV above; numbers written to round-trip.
std::string CurvesToCsv(const std::vector<ResponseCurve>& curves);

}  // namespace dwellfit

#endif  // DWELLFIT_ESTIMATOR_CURVES_SWEEP_CURVES_H_
