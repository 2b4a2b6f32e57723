// How a residual measures the vertical error of a dwell (vertical_error_residual.h):
// a small header of its own, so that the options that choose it
// (identification_options.h) need not include the functors.
#ifndef DWELLFIT_RESIDUALS_FUNCTORS_ERROR_MEASURE_H_
#define DWELLFIT_RESIDUALS_FUNCTORS_ERROR_MEASURE_H_

namespace dwellfit {

// How the vertical error is measured.
enum class ErrorMeasure {
  kAbsolute,  // a_i - a_model (the data's length unit)
  kRelative,  // ln(a_i + f) - ln(a_model + f), f the amplitude floor
};

}  // namespace dwellfit

#endif  // DWELLFIT_RESIDUALS_FUNCTORS_ERROR_MEASURE_H_
