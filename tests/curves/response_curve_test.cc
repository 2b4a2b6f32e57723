#include "dwellfit/estimator/curves/response_curve.h"

#include <cmath>
#include <string>

#include "dwellfit/config/identify_config.h"
#include "dwellfit/estimator/common/input_error.h"
#include "dwellfit/estimator/curves/sweep_curves.h"
#include "dwellfit/estimator/run/resolved_run.h"
#include "dwellfit/residuals/model/fold_point.h"
#include "gtest/gtest.h"

namespace dwellfit {
namespace {

const std::string kDatasets = std::string(DWELLFIT_SOURCE_DIR) + "/datasets/";

// Table 3.1.
ParameterVector Thesis() { return {100.0, 0.2, 300.0, 1e4, 9e8, HzToRadPerSecond(40.0)}; }

// Every dwell of every sweep of `run`: the curve's amplitude on the dwell's
// branch at its control equals the estimator's stable root to 1e-9 relative.
// A dwell past the end of its labelled branch (the estimator then returns
// the branch's end at that control, which is no root) is compared on the
// stable root the model has there instead (Branch::kOnly: the nearer one).
// Returns the number of dwells on their branch; *past_end counts the others.
int CompareAtEveryDwell(const ParameterVector& p, const ResolvedRun& run, int* dwells,
                        int* past_end = nullptr) {
  std::vector<const Sweep*> sweeps;
  for (const Sweep& sweep : run.sweeps) sweeps.push_back(&sweep);
  const std::vector<CurveSpec> specs = CurveSpecsForSweeps(sweeps);
  int compared = 0;
  for (const Sweep& sweep : run.sweeps) {
    const CurveSpec* spec = nullptr;
    for (const CurveSpec& s : specs) {
      if (s.name == sweep.id) spec = &s;
    }
    if (spec == nullptr) {
      ADD_FAILURE() << "no curve for " << sweep.Name();
      continue;
    }
    const ResponseCurve curve = TraceResponseCurve(kFirstOrderForm, p, *spec);
    for (const DwellPoint& point : sweep.points) {
      ++*dwells;
      const double held =
          sweep.kind == SweepKind::kFrequency ? point.a_base : point.drive_frequency_rad_s;
      EXPECT_EQ(held, sweep.kind == SweepKind::kFrequency ? spec->a_base : spec->omega_rad_s);
      StableRoot root = ModelAmplitude(kFirstOrderForm, p, point.drive_frequency_rad_s,
                                       point.a_base, point.branch, point.amplitude);
      Branch branch = point.branch;
      if (root.status == RootStatus::kBranchEnd) {
        branch = Branch::kOnly;
        root = ModelAmplitude(kFirstOrderForm, p, point.drive_frequency_rad_s, point.a_base, branch,
                              point.amplitude);
        EXPECT_EQ(root.status, RootStatus::kOnBranch) << sweep.Name() << " " << point.source_line;
        if (past_end != nullptr) ++*past_end;
      }
      const std::vector<CurveRoot> roots =
          CurveAmplitudesAt(kFirstOrderForm, p, curve, sweep.Control(point));
      const double a = CurveAmplitudeOnBranch(roots, branch, point.amplitude);
      EXPECT_NEAR(a, root.a, 1e-9 * root.a)
          << sweep.Name() << " line " << point.source_line << " branch " << BranchName(branch);
      if (branch == point.branch) ++compared;
    }
  }
  return compared;
}

TEST(ResponseCurve, AgreesWithTheRootSolverAtEveryThesisDwell) {
  const IdentifyConfig config = LoadIdentifyConfig(kDatasets + "thesis-numerical/beam.yaml", {});
  const ResolvedRun run = ResolveRun(config);
  int dwells = 0;
  const int compared = CompareAtEveryDwell(Thesis(), run, &dwells);
  EXPECT_GT(dwells, 300);
  EXPECT_EQ(compared, dwells);  // the truth has every simulated dwell on its branch
}

TEST(ResponseCurve, AgreesWithTheRootSolverAtEveryClampedBeamDwell) {
  const IdentifyConfig config = LoadIdentifyConfig(kDatasets + "clamped-beam-27C/beam.yaml", {});
  const ResolvedRun run = ResolveRun(config);
  const ParameterVector p = FitRun(run).best.parameters;
  int dwells = 0;
  int past_end = 0;
  const int compared = CompareAtEveryDwell(p, run, &dwells, &past_end);
  EXPECT_GT(dwells, 4000);
  // Dwells past their branch's end at the fit (measured jumps the model puts
  // elsewhere) are compared on the stable root the model has there.
  EXPECT_EQ(compared + past_end, dwells);
  EXPECT_GT(compared, 0.9 * dwells);
}

// The curve's folds of each kind are where the fold solver puts them.
void ExpectFoldsAsFoldSolver(const ParameterVector& p, const CurveSpec& spec) {
  const ResponseCurve curve = TraceResponseCurve(kFirstOrderForm, p, spec);
  for (const CurveFold& fold : curve.folds) {
    const FoldPoint solved =
        spec.kind == SweepKind::kFrequency
            ? SolveFrequencyFold(kFirstOrderForm, p.data(), spec.a_base, fold.kind, fold.control,
                                 1e-4 * fold.control)
            : SolveAmplitudeFold(kFirstOrderForm, p.data(), spec.omega_rad_s, fold.kind);
    ASSERT_TRUE(solved.exists) << spec.name;
    EXPECT_NEAR(fold.control, solved.control, 1e-9 * solved.control) << spec.name;
    EXPECT_NEAR(fold.a, solved.a, 1e-6 * solved.a) << spec.name;
  }
}

TEST(ResponseCurve, FoldsOfTheThesisSweepsAreTheFoldSolvers) {
  const ParameterVector p = Thesis();
  CurveSpec frequency;
  frequency.name = "F0.01";
  frequency.a_base = 0.01;
  frequency.control_low = HzToRadPerSecond(38.0);
  frequency.control_high = HzToRadPerSecond(46.0);
  const ResponseCurve curve = TraceResponseCurve(kFirstOrderForm, p, frequency);
  ASSERT_EQ(curve.folds.size(), 2u);
  // Traced from low frequencies: up the left side over the peak, the
  // jump-down fold, then back along the unstable branch to the jump-up fold.
  EXPECT_EQ(curve.folds[0].kind, JumpKind::kJumpDown);
  EXPECT_NEAR(RadPerSecondToHz(curve.folds[0].control), 42.2150, 1e-4);
  EXPECT_NEAR(curve.folds[0].a, 4.709e-3, 1e-6);
  EXPECT_EQ(curve.folds[1].kind, JumpKind::kJumpUp);
  EXPECT_NEAR(RadPerSecondToHz(curve.folds[1].control), 40.6588, 1e-4);
  ExpectFoldsAsFoldSolver(p, frequency);

  CurveSpec amplitude;
  amplitude.name = "A41.5";
  amplitude.kind = SweepKind::kAmplitude;
  amplitude.omega_rad_s = HzToRadPerSecond(41.5);
  amplitude.control_low = 0.002;
  amplitude.control_high = 0.05;
  const ResponseCurve a_curve = TraceResponseCurve(kFirstOrderForm, p, amplitude);
  ASSERT_EQ(a_curve.folds.size(), 2u);
  EXPECT_EQ(a_curve.folds[0].kind, JumpKind::kJumpUp);
  EXPECT_NEAR(a_curve.folds[0].control, 0.035358, 1e-6);
  EXPECT_EQ(a_curve.folds[1].kind, JumpKind::kJumpDown);
  EXPECT_NEAR(a_curve.folds[1].control, 0.006748, 1e-6);
  ExpectFoldsAsFoldSolver(p, amplitude);
}

TEST(ResponseCurve, FoldsOfTheClampedBeamSweepsAreTheFoldSolvers) {
  const IdentifyConfig config = LoadIdentifyConfig(kDatasets + "clamped-beam-27C/beam.yaml", {});
  const ResolvedRun run = ResolveRun(config);
  const ParameterVector p = FitRun(run).best.parameters;
  std::vector<const Sweep*> sweeps;
  for (const Sweep& sweep : run.sweeps) sweeps.push_back(&sweep);
  int folds = 0;
  for (const CurveSpec& spec : CurveSpecsForSweeps(sweeps)) {
    folds += static_cast<int>(TraceResponseCurve(kFirstOrderForm, p, spec).folds.size());
    ExpectFoldsAsFoldSolver(p, spec);
  }
  EXPECT_GT(folds, 0);
}

TEST(ResponseCurve, StabilityFollowsTheSignOfDgDaAndFoldsSplitSegments) {
  CurveSpec spec;
  spec.name = "F0.01";
  spec.a_base = 0.01;
  spec.control_low = HzToRadPerSecond(38.0);
  spec.control_high = HzToRadPerSecond(46.0);
  const ResponseCurve curve = TraceResponseCurve(kFirstOrderForm, Thesis(), spec);
  int unstable = 0;
  for (size_t i = 0; i < curve.points.size(); ++i) {
    const CurvePoint& point = curve.points[i];
    const auto k = ResponseCoefficients<double>::FromParameters(kFirstOrderForm, Thesis().data(),
                                                                point.omega_rad_s);
    // Every point lies on G(a; Omega) = a_base^2.
    EXPECT_NEAR(k.G(point.a), 1e-4, 1e-12) << i;
    if (!point.fold) EXPECT_EQ(point.stable, k.dG(point.a) > 0.0) << i;
    unstable += !point.stable;
  }
  EXPECT_GT(unstable, 20);
  EXPECT_EQ(curve.points.back().segment, 2);  // stable, unstable, stable
  // The backbone lies where Q = 0.
  ASSERT_FALSE(curve.backbone.empty());
  for (const BackbonePoint& b : curve.backbone) {
    const auto k = ResponseCoefficients<double>::FromParameters(kFirstOrderForm, Thesis().data(),
                                                                b.omega_rad_s);
    EXPECT_NEAR(k.Q(b.a), 0.0, 1e-12 * std::abs(k.k3 * b.a));
  }
}

TEST(ResponseCurve, RejectsAnInvalidSpecAndParametersWithoutACurve) {
  CurveSpec spec;
  spec.name = "x";
  spec.a_base = 0.01;
  spec.control_low = 2.0;
  spec.control_high = 1.0;
  std::string why;
  EXPECT_FALSE(spec.IsValid(&why));
  EXPECT_THROW(TraceResponseCurve(kFirstOrderForm, Thesis(), spec), InputError);
  spec.control_high = 300.0;
  ParameterVector p = Thesis();
  p[kMu1] = p[kMu2] = 0.0;
  EXPECT_THROW(TraceResponseCurve(kFirstOrderForm, p, spec), InputError);
}

}  // namespace
}  // namespace dwellfit
