// ProblemBuilder: assembles the identification problem on a ceres::Problem and
// a parameter block that the caller owns, so a larger estimator can embed it.
//
// Mathematical formulation. With p = [eta_e, mu1, mu2, delta, alpha, omega]
// (model_parameters.h) and the dwell points i of the chosen sweeps,
//
//   minimise over the free entries of p   (1/2) sum_i r_i(p)^2
//   subject to                            eta_e, mu1, mu2 >= 0
//
// where r_i is either the algebraic residual of eq. (3.11)
// (residuals/functors/algebraic_residual.h) or the vertical error of section 3.2.4
// (residuals/functors/vertical_error_residual.h). Fixed parameters keep their value;
// the free ones are stepped in units of their scale (ScaledSubsetManifold).
#ifndef DWELLFIT_ESTIMATOR_FIT_PROBLEM_BUILDER_H_
#define DWELLFIT_ESTIMATOR_FIT_PROBLEM_BUILDER_H_

#include <array>
#include <optional>
#include <string>

#include "ceres/problem.h"
#include "dwellfit/estimator/fit/identification_options.h"
#include "dwellfit/estimator/fit/parallel_residual_evaluator.h"
#include "dwellfit/estimator/data/sweep.h"
#include "dwellfit/residuals/model/model_parameters.h"

namespace dwellfit {

struct ProblemBuilderOptions {
  ResidualKind residual = ResidualKind::kVertical;
  ResidualOptions residual_options;
  std::array<bool, kNumParameters> fixed = {false, false, false, false, false, false};
  // Typical magnitude of each parameter: one unit of solver step. Unset: the
  // magnitude of the parameter's value when ConfigureParameters is called
  // (1 where that value is 0).
  std::optional<ParameterVector> scale;
  // Bound mu1, mu2 >= 0 (eta_e is always bounded). The algebraic residual is
  // invariant under (mu1, mu2) -> -(mu1, mu2), so a stage on it may run
  // unbounded and reflect its result (ReflectDampingIntoPhysicalRange).
  bool bound_damping = true;
  // Soft constraints of eqs. (3.17) and (3.19); AddPenalties adds them.
  PenaltyOptions penalties;
  bool IsValid(std::string* error) const;
};

class ProblemBuilder {
 public:
  explicit ProblemBuilder(const ProblemBuilderOptions& options);

  // Adds one residual block per dwell of `sweep`, each reading the 6-double
  // block `parameters` (owned by the caller, must outlive `problem`).
  // Returns the number of residual blocks added. With an `evaluator` (the
  // problem's evaluation callback, reading `parameters`) the blocks are
  // evaluated through it, on its threads.
  int AddSweep(const Sweep& sweep, double* parameters, ceres::Problem* problem,
               ParallelResidualEvaluator* evaluator = nullptr) const;

  // Adds the enabled penalties for `sweep`: one BifurcationRangePenalty per
  // measured jump whose target is enforced, one BranchStabilityPenalty per
  // dwell labelled lower or upper. Returns the number of blocks added.
  int AddPenalties(const Sweep& sweep, double* parameters, ceres::Problem* problem,
                   ParallelResidualEvaluator* evaluator = nullptr) const;

  // Sets bounds (eta_e >= 0; mu1, mu2 >= 0 unless !bound_damping), fixed parameters and scaling on
  // the block. Call once, after the block has residuals in `problem`.
  void ConfigureParameters(double* parameters, ceres::Problem* problem) const;

  // The cost function of one dwell (owned by the caller; Ceres takes it).
  ceres::CostFunction* MakeResidual(const DwellPoint& point) const;

  const ProblemBuilderOptions& options() const { return options_; }

 private:
  ProblemBuilderOptions options_;
};

// G(a) of eq. (3.11) depends on mu1, mu2 only through k1^2, k2^2 and k1 k2,
// and on eta_e only through 1/eta_e^2. Maps a point fitted on G alone to its
// physical twin: eta_e -> |eta_e|, (mu1, mu2) -> -(mu1, mu2) when neither is
// positive; a damping left negative after that (mixed signs: no physical twin)
// is set to 0. Returns whether anything changed.
bool ReflectDampingIntoPhysicalRange(ParameterVector* parameters);

// Which enforceable target a measured jump of `sweep` is.
JumpTarget TargetOf(const Sweep& sweep, const JumpBracket& jump);

// The bifurcation-range penalty of one measured jump (eq. 3.17), owned by the
// caller; Ceres takes it.
ceres::CostFunction* MakeBifurcationRangePenalty(const Sweep& sweep, const JumpBracket& jump,
                                                 const BifurcationRangeOptions& options);

}  // namespace dwellfit

#endif  // DWELLFIT_ESTIMATOR_FIT_PROBLEM_BUILDER_H_
