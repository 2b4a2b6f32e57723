// Owning handles of libmatio's file and variable objects.
#ifndef DWELLFIT_ESTIMATOR_MATFILE_MAT_HANDLES_H_
#define DWELLFIT_ESTIMATOR_MATFILE_MAT_HANDLES_H_

#include <matio.h>

#include <memory>

namespace dwellfit {

struct MatCloser {
  void operator()(mat_t* mat) const { Mat_Close(mat); }
};
struct MatVarFreer {
  void operator()(matvar_t* var) const { Mat_VarFree(var); }
};
using MatFile = std::unique_ptr<mat_t, MatCloser>;
using MatVar = std::unique_ptr<matvar_t, MatVarFreer>;

}  // namespace dwellfit

#endif  // DWELLFIT_ESTIMATOR_MATFILE_MAT_HANDLES_H_
