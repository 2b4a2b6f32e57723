// The covariance of mapped blocks on the scaled problem: the same as the one
// block's when the mapping is the identity, available where ceres::Covariance
// fails on the unscaled problem, narrower for eta_e when two datasets share
// it, and narrower still where the caller adds a prior. The Jacobian
// streamed in chunks into its R factor gives what the whole dense Jacobian
// gives, for any chunk size. The intervals' quantiles, marginal and
// simultaneous, are Student's t and the normal's.
#include "dwellfit/estimator/analysis/block_covariance.h"

#include <array>
#include <cmath>
#include <vector>

#include "Eigen/SVD"
#include "ceres/covariance.h"
#include "ceres/crs_matrix.h"
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

// What EstimateBlockCovariance computes, directly from the whole dense
// Jacobian: every dwell of `fit` in a problem of its own (one residual block
// per dwell, no manifolds), J in the ambient entries, and the caller's rows
// `prior` (standardised, ambient columns; none: 0 rows). With s^2 = 2 F_d /
// (n - k), A = [J_d / s; prior] in tangent units |value| and normalised
// columns A_n = A D^-1: collinearity from the SVD A_n = U S V^T, cosines
// A_n^T A_n, and C = U_s V S^-2 V^T U_s, U_s the unit per normalised
// coordinate (|value| / column norm).
struct DenseResult {
  double data_cost = 0.0;
  double noise_sigma = 0.0;
  double collinearity = 0.0;
  Eigen::MatrixXd cosines;
  Eigen::MatrixXd covariance;  // ambient x ambient
};

DenseResult DenseCovariance(const FitDescription& fit, const ResidualOptions& residual,
                            const Eigen::MatrixXd& prior) {
  ceres::Problem problem;
  ProblemBuilderOptions builder_options;
  builder_options.residual_options = residual;
  const ProblemBuilder builder(builder_options);
  for (const FitDataset& dataset : fit.datasets) {
    for (const Sweep* sweep : dataset.sweeps) {
      builder.AddSweep(*sweep, LayoutOf(fit, dataset.parameters), &problem);
    }
  }
  ceres::Problem::EvaluateOptions options;
  for (const FitBlock& block : fit.blocks) options.parameter_blocks.push_back(block.values);
  DenseResult result;
  ceres::CRSMatrix crs;
  EXPECT_TRUE(problem.Evaluate(options, &result.data_cost, nullptr, nullptr, &crs));
  Eigen::MatrixXd jacobian = Eigen::MatrixXd::Zero(crs.num_rows, crs.num_cols);
  for (int row = 0; row < crs.num_rows; ++row) {
    for (int i = crs.rows[row]; i < crs.rows[row + 1]; ++i) {
      jacobian(row, crs.cols[i]) = crs.values[i];
    }
  }
  const std::vector<bool> fixed = fit.FixedEntries();
  const std::vector<double> values = fit.Values();
  std::vector<int> free;
  for (size_t i = 0; i < fixed.size(); ++i) {
    if (!fixed[i]) free.push_back(static_cast<int>(i));
  }
  const int k = static_cast<int>(free.size());
  result.noise_sigma = std::sqrt(2.0 * result.data_cost / (crs.num_rows - k));
  Eigen::MatrixXd a(crs.num_rows + prior.rows(), k);
  Eigen::VectorXd unit(k);
  for (int j = 0; j < k; ++j) {
    const double scale = std::abs(values[free[j]]);
    a.col(j) << jacobian.col(free[j]) * (scale / result.noise_sigma), prior.col(free[j]) * scale;
    const double norm = a.col(j).norm();
    a.col(j) /= norm;
    unit[j] = scale / norm;
  }
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(a, Eigen::ComputeThinV);
  const Eigen::VectorXd& singular = svd.singularValues();
  result.collinearity = singular[0] / singular[k - 1];
  result.cosines = a.transpose() * a;
  const Eigen::MatrixXd tangent = svd.matrixV() *
                                  singular.array().square().inverse().matrix().asDiagonal() *
                                  svd.matrixV().transpose();
  result.covariance = Eigen::MatrixXd::Zero(fixed.size(), fixed.size());
  for (int i = 0; i < k; ++i) {
    for (int j = 0; j < k; ++j) {
      result.covariance(free[i], free[j]) = unit[i] * unit[j] * tangent(i, j);
    }
  }
  return result;
}

// Every covariance entry of `c` within `relative` of `dense`'s, relative to
// sqrt(C_ii C_jj); fixed entries' rows and columns zero.
void ExpectCovarianceNear(const BlockCovariance& c, const DenseResult& dense, double relative) {
  ASSERT_EQ(c.covariance.rows(), dense.covariance.rows());
  for (int i = 0; i < c.covariance.rows(); ++i) {
    for (int j = 0; j < c.covariance.cols(); ++j) {
      const double scale = std::sqrt(dense.covariance(i, i) * dense.covariance(j, j));
      EXPECT_NEAR(c.covariance(i, j), dense.covariance(i, j), relative * scale) << i << ", " << j;
    }
  }
}

// Chunks of one residual block (32 dwells), of two (50 rows: 64, then what a
// sweep's last, partial batch leaves), and the whole Jacobian at once.
const int kChunkRows[] = {1, 50, BlockCovarianceOptions{}.chunk_rows};

// The streamed R gives the dense Jacobian's noise, collinearity, cosines and
// covariance for every chunk size, on three blocks with a fixed entry in one
// of them (omega, entry 2 of 'rest').
TEST_F(NoisyDatasets, StreamedFactorGivesTheDenseJacobiansCovariance) {
  ThreeBlocks blocks(kThesisTruth);
  const FitDescription fit = blocks.Describe(Pointers(*a_), true);
  const ResidualOptions residual = RelativeError().residual;
  // Several chunks, 50 rows not dividing them.
  ASSERT_GT(fit.NumDwells(), 2 * static_cast<int>(ProblemBuilder::kDwellsPerBatch));
  ASSERT_NE(fit.NumDwells() % 50, 0);
  const DenseResult dense = DenseCovariance(fit, residual, Eigen::MatrixXd::Zero(0, 6));
  for (int chunk_rows : kChunkRows) {
    SCOPED_TRACE(chunk_rows);
    BlockCovarianceOptions options;
    options.chunk_rows = chunk_rows;
    const BlockCovariance c = EstimateBlockCovariance(fit, residual, options);
    ASSERT_TRUE(c.available) << c.message;
    EXPECT_EQ(c.num_points, fit.NumDwells());
    EXPECT_NEAR(c.data_cost, dense.data_cost, 1e-12 * dense.data_cost);
    EXPECT_NEAR(c.noise_sigma, dense.noise_sigma, 1e-12 * dense.noise_sigma);
    EXPECT_NEAR(c.collinearity, dense.collinearity, 1e-9 * dense.collinearity);
    EXPECT_TRUE(c.column_cosines.isApprox(dense.cosines, 1e-12)) << c.column_cosines;
    ExpectCovarianceNear(c, dense, 1e-9);
    EXPECT_TRUE(c.covariance.row(5).isZero(0.0));  // omega, fixed
    EXPECT_TRUE(c.covariance.col(5).isZero(0.0));
  }
}

// Entries the data cannot tell apart (delta and alpha on amplitude sweeps at
// one drive frequency) are named whatever the chunk size, with the cosine of
// their columns (+-1) the dense Jacobian gives.
TEST_F(NoisyDatasets, CollinearEntriesAreNamedForEveryChunkSize) {
  std::vector<const Sweep*> amplitude;
  for (const Sweep& sweep : *a_) {
    if (sweep.kind == SweepKind::kAmplitude) amplitude.push_back(&sweep);
  }
  ASSERT_EQ(amplitude.size(), 2u);
  ParameterVector p = kThesisTruth;
  std::array<bool, kNumParameters> fixed{};
  fixed[kNaturalFrequency] = true;
  const FitDescription fit = SingleBlockFit(amplitude, fixed, &p);
  const DenseResult dense =
      DenseCovariance(fit, RelativeError().residual, Eigen::MatrixXd::Zero(0, 6));
  for (int chunk_rows : kChunkRows) {
    SCOPED_TRACE(chunk_rows);
    BlockCovarianceOptions options;
    options.chunk_rows = chunk_rows;
    const BlockCovariance c = EstimateBlockCovariance(fit, RelativeError().residual, options);
    EXPECT_FALSE(c.available);
    EXPECT_THAT(c.message, HasSubstr("delta, alpha cannot be told apart by these data: 1 "
                                     "combination(s) of them are not determined"));
    EXPECT_GT(c.collinearity, kMaxCollinearity);
    ASSERT_EQ(c.null_space.cols(), 1);
    EXPECT_NEAR(std::abs(c.column_cosines(kDelta, kAlpha)), 1.0, 1e-12);
    EXPECT_TRUE(c.column_cosines.isApprox(dense.cosines, 1e-12)) << c.column_cosines;
    EXPECT_TRUE(c.covariance.isZero(0.0));
  }
}

TEST(BlockCovariance, ChunkOfNoRowsIsReportedInWords) {
  const std::vector<Sweep> sweeps = SimulateDataset(kThesisTruth, 0.0, 0);
  ThreeBlocks blocks(kThesisTruth);
  BlockCovarianceOptions options;
  options.chunk_rows = 0;
  const BlockCovariance c =
      EstimateBlockCovariance(blocks.Describe(Pointers(sweeps), true), ResidualOptions{}, options);
  EXPECT_FALSE(c.available);
  EXPECT_THAT(c.message, HasSubstr("chunk_rows is 0: it must be at least 1"));
}

// The quantiles against scipy.stats (norm.ppf, t.ppf at (1 + 0.95^(1/m)) / 2),
// and the simultaneous one against its definition: for m independent normal
// estimates all m intervals hold with probability (2 Phi(q) - 1)^m = 0.95.
TEST(IntervalQuantile, MarginalAndSimultaneousQuantilesAreStudentsAndNormals) {
  EXPECT_NEAR(IntervalQuantile(true, 0), 1.959963984540054, 1e-12);
  EXPECT_NEAR(IntervalQuantile(false, 31), 2.0395134463964077, 1e-12);
  EXPECT_NEAR(IntervalQuantile(true, 0, 0.99), 2.5758293035489004, 1e-12);
  EXPECT_NEAR(SimultaneousIntervalQuantile(true, 0, 4), 2.4909151310191397, 1e-12);
  EXPECT_NEAR(SimultaneousIntervalQuantile(false, 31, 4), 2.6439464799762593, 1e-12);
  EXPECT_DOUBLE_EQ(SimultaneousIntervalQuantile(false, 31, 1), IntervalQuantile(false, 31));
  const double q = SimultaneousIntervalQuantile(true, 0, 4);
  EXPECT_NEAR(std::pow(std::erf(q / std::sqrt(2.0)), 4), 0.95, 1e-12);
}

// Three blocks mapped as the identity give the one block's covariance.
TEST_F(NoisyDatasets, IdentityMappedBlocksGiveTheOneBlocksCovariance) {
  IdentificationOptions options;
  options.initial = ThesisStart(kThesisTruth);
  options.fixed[kNaturalFrequency] = true;
  options.solve.residual.error = ErrorMeasure::kRelative;
  const IdentificationResult fit = Identify(Pointers(*a_), options);
  ASSERT_TRUE(fit.IsSolutionUsable()) << fit.message;
  const ParameterUncertainty single =
      EstimateUncertainty(Pointers(*a_), options, fit.parameters, 0.0);
  ASSERT_TRUE(single.available) << single.message;

  ThreeBlocks blocks(fit.parameters);
  const BlockCovariance mapped =
      EstimateBlockCovariance(blocks.Describe(Pointers(*a_), true), options.solve.residual);
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
    alone[kNaturalFrequency] =
        data == a_ ? start[kNaturalFrequency] : truth_b_[kNaturalFrequency] * 0.995;
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
  options.solve.residual.error = ErrorMeasure::kRelative;
  ParameterVector p = Identify(Pointers(*a_), options).parameters;
  FitDescription fit = SingleBlockFit(Pointers(*a_), options.fixed, &p);
  const BlockCovariance data = EstimateBlockCovariance(fit, options.solve.residual);
  ASSERT_TRUE(data.available) << data.message;
  const double prior_sigma = data.standard_error[kMu1];  // as good as the data
  fit.add_residuals = [&](ceres::Problem* problem) {
    ceres::Matrix inverse_sigma = ceres::Matrix::Zero(1, kNumParameters);
    inverse_sigma(0, kMu1) = 1.0 / prior_sigma;
    ceres::Vector mean(kNumParameters);
    for (int i = 0; i < kNumParameters; ++i) mean[i] = p[i];
    problem->AddResidualBlock(new ceres::NormalPrior(inverse_sigma, mean), nullptr, p.data());
  };
  const BlockCovariance with_prior = EstimateBlockCovariance(fit, options.solve.residual);
  ASSERT_TRUE(with_prior.available) << with_prior.message;
  EXPECT_EQ(with_prior.caller_residuals, 1);
  EXPECT_THAT(with_prior.message, HasSubstr("1 residual(s) of the caller's"));
  EXPECT_LT(with_prior.standard_error[kMu1], 0.99 * prior_sigma);
  EXPECT_GT(with_prior.standard_error[kMu1], 0.5 * prior_sigma);  // two equal sources: 1/sqrt(2)
  EXPECT_EQ(with_prior.noise_sigma, data.noise_sigma);

  // The dwells weighted by 1/s and the prior's row, streamed in chunks of
  // any size: the dense Jacobian's covariance.
  Eigen::MatrixXd prior_row = Eigen::MatrixXd::Zero(1, kNumParameters);
  prior_row(0, kMu1) = 1.0 / prior_sigma;
  const DenseResult dense = DenseCovariance(fit, options.solve.residual, prior_row);
  for (int chunk_rows : kChunkRows) {
    SCOPED_TRACE(chunk_rows);
    BlockCovarianceOptions chunked;
    chunked.chunk_rows = chunk_rows;
    const BlockCovariance c = EstimateBlockCovariance(fit, options.solve.residual, chunked);
    ASSERT_TRUE(c.available) << c.message;
    EXPECT_EQ(c.caller_residuals, 1);
    EXPECT_NEAR(c.collinearity, dense.collinearity, 1e-9 * dense.collinearity);
    EXPECT_TRUE(c.column_cosines.isApprox(dense.cosines, 1e-12)) << c.column_cosines;
    ExpectCovarianceNear(c, dense, 1e-9);
  }
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
