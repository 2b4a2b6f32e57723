// The covariance of mapped blocks on the scaled problem: the same as the one
// block's when the mapping is the identity, available where ceres::Covariance
// fails on the unscaled problem, narrower for eta_e when two datasets share
// it, and narrower still where the caller adds a prior.
#include "dwellfit/estimator/analysis/block_covariance.h"

#include <cmath>
#include <vector>

#include "ceres/covariance.h"
#include "ceres/normal_prior.h"
#include "dwellfit/estimator/analysis/parameter_uncertainty.h"
#include "dwellfit/estimator/fit/identification.h"
#include "dwellfit/estimator/fit/problem_builder.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "tests/fit_test_support.h"

namespace dwellfit {
namespace {

using ::testing::HasSubstr;

StagedSolveOptions RelativeError() {
  StagedSolveOptions options;
  options.residual.error = ErrorMeasure::kRelative;
  return options;
}

// Two datasets with 1 % noise, the second at w = 2 pi 43 rad/s.
class NoisyDatasets : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    truth_b_ = kThesisTruth;
    truth_b_[kNaturalFrequency] = HzToRadPerSecond(43.0);
    a_ = new std::vector<Sweep>(SimulateDataset(kThesisTruth, 0.01, 11));
    b_ = new std::vector<Sweep>(SimulateDataset(truth_b_, 0.01, 12));
  }
  static void TearDownTestSuite() {
    delete a_;
    delete b_;
  }
  static ParameterVector truth_b_;
  static std::vector<Sweep>* a_;
  static std::vector<Sweep>* b_;
};

ParameterVector NoisyDatasets::truth_b_;
std::vector<Sweep>* NoisyDatasets::a_ = nullptr;
std::vector<Sweep>* NoisyDatasets::b_ = nullptr;

// Three blocks mapped as the identity give the one block's covariance.
TEST_F(NoisyDatasets, IdentityMappedBlocksGiveTheOneBlocksCovariance) {
  IdentificationOptions options;
  options.initial = ThesisStart(kThesisTruth);
  options.fixed[kNaturalFrequency] = true;
  options.residual.error = ErrorMeasure::kRelative;
  const IdentificationResult fit = Identify(Pointers(*a_), options);
  ASSERT_TRUE(fit.IsSolutionUsable()) << fit.message;
  const ParameterUncertainty single =
      EstimateUncertainty(Pointers(*a_), options, fit.parameters, 0.0);
  ASSERT_TRUE(single.available) << single.message;

  ThreeBlocks blocks(fit.parameters);
  const BlockCovariance mapped =
      EstimateBlockCovariance(blocks.Describe(Pointers(*a_), true), options.residual);
  ASSERT_TRUE(mapped.available) << mapped.message;
  EXPECT_EQ(mapped.num_free, 5);
  EXPECT_EQ(mapped.degrees_of_freedom, single.degrees_of_freedom);
  for (int i = 0; i < kNumParameters; ++i) {
    for (int j = 0; j < kNumParameters; ++j) {
      const double scale = std::sqrt(single.covariance(i, i) * single.covariance(j, j));
      EXPECT_NEAR(mapped.covariance(i, j), single.covariance(i, j), 1e-8 * scale + 1e-300)
          << ParameterName(i) << ", " << ParameterName(j);
    }
  }
  EXPECT_EQ(mapped.standard_error[kNaturalFrequency], 0.0);  // fixed
}

// Joint fit: eta_e, mu1, mu2, delta, alpha shared, one w each. On the
// unscaled problem ceres::Covariance cannot invert J^T J (its reciprocal
// condition number is far below Ceres' 1e-14); on the scaled one it can, and
// the shared eta_e is known better than from either dataset alone.
TEST_F(NoisyDatasets, JointCovarianceSucceedsScaledAndNarrowsTheSharedEtaE) {
  ParameterVector start = ThesisStart(kThesisTruth);
  start[kNaturalFrequency] *= 1.005;
  SharedModel model(start, truth_b_[kNaturalFrequency] * 0.995);
  const FitDescription fit = model.Describe(Pointers(*a_), Pointers(*b_));
  const FitSummary summary = SolveStaged(fit, RelativeError());
  ASSERT_TRUE(summary.IsSolutionUsable()) << summary.message;

  ceres::Problem unscaled;
  ProblemBuilderOptions unscaled_options;
  unscaled_options.residual_options = RelativeError().residual;
  const ProblemBuilder builder(unscaled_options);
  for (const FitDataset& dataset : fit.datasets) {
    for (const Sweep* sweep : dataset.sweeps) {
      builder.AddSweep(*sweep, LayoutOf(fit, dataset.parameters), &unscaled);
    }
  }
  ceres::Covariance::Options dense;
  dense.algorithm_type = ceres::DENSE_SVD;
  ceres::Covariance raw(dense);
  EXPECT_FALSE(raw.Compute({model.shared, model.w_a, model.w_b}, &unscaled));

  const BlockCovariance joint = EstimateBlockCovariance(fit, RelativeError().residual);
  ASSERT_TRUE(joint.available) << joint.message;
  EXPECT_EQ(joint.num_free, 7);
  EXPECT_LT(joint.collinearity, kMaxCollinearity);
  const int eta_e = fit.AmbientIndex({model.shared, 0});
  const int w_b = fit.AmbientIndex({model.w_b, 0});
  EXPECT_GT(joint.standard_error[eta_e], 0.0);
  EXPECT_LT(std::abs(model.shared[0] - kThesisTruth[kEtaE]), 4.0 * joint.standard_error[eta_e]);
  EXPECT_LT(std::abs(model.w_b[0] - truth_b_[kNaturalFrequency]), 4.0 * joint.standard_error[w_b]);

  for (const std::vector<Sweep>* data : {a_, b_}) {
    ParameterVector alone = start;
    alone[kNaturalFrequency] = data == a_ ? start[kNaturalFrequency] : truth_b_[kNaturalFrequency] * 0.995;
    const FitDescription single = SingleBlockFit(Pointers(*data), {}, &alone);
    ASSERT_TRUE(SolveStaged(single, RelativeError()).IsSolutionUsable());
    const BlockCovariance c = EstimateBlockCovariance(single, RelativeError().residual);
    ASSERT_TRUE(c.available) << c.message;
    EXPECT_LT(joint.standard_error[eta_e], c.standard_error[kEtaE]);
  }
}

// A prior on mu1 (a caller's residual block, standardised) narrows mu1
// below both the data's and the prior's own standard deviation.
TEST_F(NoisyDatasets, APriorNarrowsItsEntryBelowTheDataAndThePrior) {
  IdentificationOptions options;
  options.initial = ThesisStart(kThesisTruth);
  options.fixed[kNaturalFrequency] = true;
  options.residual.error = ErrorMeasure::kRelative;
  ParameterVector p = Identify(Pointers(*a_), options).parameters;
  FitDescription fit = SingleBlockFit(Pointers(*a_), options.fixed, &p);
  const BlockCovariance data = EstimateBlockCovariance(fit, options.residual);
  ASSERT_TRUE(data.available) << data.message;
  const double prior_sigma = data.standard_error[kMu1];  // as good as the data
  fit.add_residuals = [&](ceres::Problem* problem) {
    ceres::Matrix inverse_sigma = ceres::Matrix::Zero(1, kNumParameters);
    inverse_sigma(0, kMu1) = 1.0 / prior_sigma;
    ceres::Vector mean(kNumParameters);
    for (int i = 0; i < kNumParameters; ++i) mean[i] = p[i];
    problem->AddResidualBlock(new ceres::NormalPrior(inverse_sigma, mean), nullptr, p.data());
  };
  const BlockCovariance with_prior = EstimateBlockCovariance(fit, options.residual);
  ASSERT_TRUE(with_prior.available) << with_prior.message;
  EXPECT_EQ(with_prior.caller_residuals, 1);
  EXPECT_THAT(with_prior.message, HasSubstr("1 residual(s) of the caller's"));
  EXPECT_LT(with_prior.standard_error[kMu1], 0.99 * prior_sigma);
  EXPECT_GT(with_prior.standard_error[kMu1], 0.5 * prior_sigma);  // two equal sources: 1/sqrt(2)
  EXPECT_EQ(with_prior.noise_sigma, data.noise_sigma);
}

TEST(BlockCovariance, InvalidDescriptionIsReportedInWords) {
  const std::vector<Sweep> sweeps = SimulateDataset(kThesisTruth, 0.0, 0);
  ThreeBlocks blocks(kThesisTruth);
  FitDescription fit = blocks.Describe(Pointers(sweeps), false);
  fit.datasets[0].parameters[kMu1].index = 5;
  const BlockCovariance c = EstimateBlockCovariance(fit, ResidualOptions{});
  EXPECT_FALSE(c.available);
  EXPECT_THAT(c.message, HasSubstr("mu1 is mapped to entry 5 of block 'damping'"));
}

}  // namespace
}  // namespace dwellfit
