// A run's outputs in the quantities the test measured: the sweeps, the
// model's amplitudes and jumps beside them, and the response curves are
// computed in the model's form (a displacement response to a base
// acceleration) and mapped back here, once, before anything is written
// (measured_quantity.h; docs/model.md, "The test as run").
#ifndef DWELLFIT_ESTIMATOR_RUN_MEASURED_OUTPUTS_H_
#define DWELLFIT_ESTIMATOR_RUN_MEASURED_OUTPUTS_H_

#include <string>
#include <vector>

#include "dwellfit/estimator/analysis/identification_report.h"
#include "dwellfit/estimator/curves/response_curve.h"
#include "dwellfit/estimator/data/measured_quantity.h"

namespace dwellfit {

// Maps the sweeps of `sweeps` that `report`'s predictions point into, the predictions
// (model amplitudes, jumps, RMS errors) and `curves` from the model's form
// into the measured quantities. Nothing changes for the model's own form.
// The modal properties stay functions of the displacement amplitude.
void MapOutputsToMeasured(const TestQuantities& test, double phase_offset_rad,
                          std::vector<Sweep>* sweeps, IdentificationReport* report,
                          std::vector<ResponseCurve>* curves);

// The jumps of `sweep` (in the model's form, as a run holds it) as
// DescribeJumps words them, in the quantities the test measured.
std::string DescribeMeasuredJumps(const TestQuantities& test, double phase_offset_rad,
                                  const Sweep& sweep);

}  // namespace dwellfit

#endif  // DWELLFIT_ESTIMATOR_RUN_MEASURED_OUTPUTS_H_
