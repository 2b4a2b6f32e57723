// Two beams on one shaker fixture, fitted jointly with an installed dwellfit.
//
// The beams are cut from one bar and driven through one fixture: they share
// the forcing effectiveness eta_e and the material's damping and
// nonlinearity (mu1, mu2, delta, alpha), while their natural frequencies w
// differ (40 and 43 Hz). Each is measured with a frequency sweep around its
// resonance and an amplitude sweep 1.5 Hz above it, up and down, with 1 %
// noise (simulated here with dwellfit's dwell simulator). A ring-down test
// gave mu1 = 0.2 +/- 0.02 1/s, a Gaussian prior the caller adds as a residual
// block of its own.
//
// The caller owns four parameter blocks: eta_e {eta_e}, material {mu1, mu2,
// delta, alpha}, and one w per beam. Each beam's six model parameters are
// mapped onto them (dwellfit::ParameterMap), the staged solve fits both beams
// at once, and the covariance of the blocks gives 95 % intervals. Each beam is
// also fitted alone (with the same prior). The program prints the intervals
// and exits non-zero unless every fit is usable, the joint fit's intervals
// hold the truth, and the joint eta_e interval is narrower than either
// beam's alone.
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

#include "ceres/normal_prior.h"
#include "dwellfit/estimator/analysis/block_covariance.h"
#include "dwellfit/estimator/data/jump_detection.h"
#include "dwellfit/estimator/fit/fit_description.h"
#include "dwellfit/estimator/fit/initial_guess.h"
#include "dwellfit/estimator/fit/staged_solve.h"
#include "dwellfit/estimator/simulation/dwell_simulator.h"

namespace {

using dwellfit::ParameterVector;

constexpr double kPriorMu1 = 0.2;          // 1/s, from the ring-down test
constexpr double kPriorMu1Sigma = 0.02;    // 1/s
constexpr double kNaturalFrequencyA = 40;  // Hz
constexpr double kNaturalFrequencyB = 43;  // Hz

// The truth of one beam: the chapter's numerical case (Table 3.1) at `hz`.
ParameterVector Truth(double hz) {
  return {100.0, 0.2, 300.0, 1e4, 9e8, dwellfit::HzToRadPerSecond(hz)};
}

// One beam's dwells: a frequency sweep at a_base 0.01 from f0 - 2 to f0 + 6
// Hz and an amplitude sweep at f0 + 1.5 Hz, up and down, 1 % noise, branches
// labelled from the data as for a measured beam.
std::vector<dwellfit::Sweep> Measure(const ParameterVector& truth, std::uint64_t seed) {
  const double f0 = dwellfit::RadPerSecondToHz(truth[dwellfit::kNaturalFrequency]);
  dwellfit::SweepPlan frequency;
  frequency.id = "F";
  frequency.kind = dwellfit::SweepKind::kFrequency;
  frequency.held_a_base = 0.01;
  frequency.from = f0 - 2.0;
  frequency.to = f0 + 6.0;
  frequency.step = 0.1;
  dwellfit::SweepPlan amplitude;
  amplitude.id = "A";
  amplitude.kind = dwellfit::SweepKind::kAmplitude;
  amplitude.held_frequency_hz = f0 + 1.5;
  amplitude.from = 0.002;
  amplitude.to = 0.05;
  amplitude.step = 0.001;
  dwellfit::DwellPlan plan;
  plan.truth = truth;
  plan.sweeps = {frequency, amplitude};
  plan.noise = {0.01, seed};
  std::vector<dwellfit::Sweep> sweeps = dwellfit::SimulateDwells(plan);
  dwellfit::DetectJumps(dwellfit::JumpDetectionOptions{}, &sweeps);
  return sweeps;
}

struct Beam {
  std::string name;
  ParameterVector truth;
  std::vector<dwellfit::Sweep> sweeps;
  ParameterVector guess;  // from its data alone (AutomaticInitialGuess)

  std::vector<const dwellfit::Sweep*> Pointers() const {
    std::vector<const dwellfit::Sweep*> pointers;
    for (const dwellfit::Sweep& sweep : sweeps) pointers.push_back(&sweep);
    return pointers;
  }
};

// The caller's blocks for the beams fitted together, started from the
// mean of their guesses (each w from its own).
struct Blocks {
  double eta_e[1];
  double material[4];  // mu1, mu2, delta, alpha
  std::vector<double> w;

  explicit Blocks(const std::vector<const Beam*>& beams) : eta_e{0.0}, material{0, 0, 0, 0} {
    const double n = static_cast<double>(beams.size());
    for (const Beam* beam : beams) {
      eta_e[0] += beam->guess[dwellfit::kEtaE] / n;
      for (int i = 0; i < 4; ++i) material[i] += beam->guess[dwellfit::kMu1 + i] / n;
      w.push_back(beam->guess[dwellfit::kNaturalFrequency]);
    }
  }

  // eta_e, material, then one w per beam; each beam's six parameters mapped
  // onto them; the prior on mu1.
  dwellfit::FitDescription Describe(const std::vector<const Beam*>& beams) {
    dwellfit::FitDescription fit;
    fit.blocks = {{eta_e, 1, "eta_e"}, {material, 4, "material", {"mu1", "mu2", "delta", "alpha"}}};
    for (size_t b = 0; b < beams.size(); ++b) {
      fit.blocks.push_back({&w[b], 1, "w_" + beams[b]->name});
      const dwellfit::ParameterMap map = {
          {{eta_e, 0}, {material, 0}, {material, 1}, {material, 2}, {material, 3}, {&w[b], 0}}};
      fit.datasets.push_back({beams[b]->name, beams[b]->Pointers(), map});
    }
    fit.add_residuals = [this](ceres::Problem* problem) {
      ceres::Matrix inverse_sigma = ceres::Matrix::Zero(1, 4);
      inverse_sigma(0, 0) = 1.0 / kPriorMu1Sigma;
      ceres::Vector mean = Eigen::Map<const ceres::Vector>(material, 4);
      mean[0] = kPriorMu1;
      problem->AddResidualBlock(new ceres::NormalPrior(inverse_sigma, mean), nullptr, material);
    };
    return fit;
  }
};

// One fit's estimate and 95 % interval of each beam parameter.
struct FitResult {
  bool usable = false;
  std::string message;
  std::vector<double> value, low, high;  // eta_e, mu1, mu2, delta, alpha, w per beam
};

FitResult FitTogether(const std::vector<const Beam*>& beams) {
  Blocks blocks(beams);
  const dwellfit::FitDescription fit = blocks.Describe(beams);
  dwellfit::StagedSolveOptions options;
  options.residual.error = dwellfit::ErrorMeasure::kRelative;  // multiplicative noise
  const dwellfit::FitSummary summary = dwellfit::SolveStaged(fit, options);
  FitResult result;
  result.message = summary.message;
  if (!summary.IsSolutionUsable()) return result;
  const dwellfit::BlockCovariance covariance =
      dwellfit::EstimateBlockCovariance(fit, options.residual);
  result.message = covariance.message;
  if (!covariance.available) return result;
  result.usable = true;
  result.value = covariance.values;
  result.low = covariance.ci95_low;
  result.high = covariance.ci95_high;
  return result;
}

// "[low, high]" of entry i, or blanks when the fit has no such entry.
std::string Interval(const FitResult& fit, int i) {
  if (i < 0 || i >= static_cast<int>(fit.value.size())) return std::string(27, ' ');
  char text[64];
  std::snprintf(text, sizeof(text), "[%11.6g, %11.6g]", fit.low[i], fit.high[i]);
  return text;
}

// Prints the intervals; returns whether every joint interval holds the truth.
bool PrintIntervals(const std::vector<const Beam*>& beams, const FitResult& joint,
                    const std::vector<FitResult>& alone) {
  std::printf("%-9s %11s  %-27s  %-27s  %-27s\n", "parameter", "truth", "joint 95 %",
              (beams[0]->name + " alone").c_str(), (beams[1]->name + " alone").c_str());
  const char* names[] = {"eta_e", "mu1", "mu2", "delta", "alpha"};
  bool covered = true;
  for (int i = 0; i < 7; ++i) {
    // Entries: eta_e, mu1, mu2, delta, alpha, then w of each beam; alone
    // fits have one w, at entry 5.
    const bool is_w = i >= 5;
    const Beam& beam = *beams[is_w ? i - 5 : 0];
    const double truth = is_w ? beam.truth[dwellfit::kNaturalFrequency] : beam.truth[i];
    const std::string name = is_w ? "w_" + beam.name + " rad/s" : names[i];
    covered = covered && joint.low[i] <= truth && truth <= joint.high[i];
    std::printf("%-9s %11.6g  %s  %s  %s\n", name.c_str(), truth, Interval(joint, i).c_str(),
                Interval(alone[0], is_w && i != 5 ? -1 : i).c_str(),
                Interval(alone[1], is_w ? (i == 6 ? 5 : -1) : i).c_str());
  }
  return covered;
}

}  // namespace

int main() {
  std::vector<Beam> beams = {{"A", Truth(kNaturalFrequencyA), {}, {}},
                             {"B", Truth(kNaturalFrequencyB), {}, {}}};
  std::uint64_t seed = 2026;
  for (Beam& beam : beams) {
    beam.sweeps = Measure(beam.truth, seed++);
    beam.guess =
        dwellfit::AutomaticInitialGuess(beam.Pointers(), dwellfit::KnownParameters{}).guess;
  }
  const FitResult joint = FitTogether({&beams[0], &beams[1]});
  const std::vector<FitResult> alone = {FitTogether({&beams[0]}), FitTogether({&beams[1]})};
  std::printf("prior: mu1 = %g +/- %g 1/s; 1 %% noise on every dwell\n", kPriorMu1, kPriorMu1Sigma);
  std::printf("joint:   %s\nA alone: %s\nB alone: %s\n\n", joint.message.c_str(),
              alone[0].message.c_str(), alone[1].message.c_str());
  if (!joint.usable || !alone[0].usable || !alone[1].usable) {
    std::printf("FAILED: a fit or its covariance is not usable\n");
    return 1;
  }
  const bool covered = PrintIntervals({&beams[0], &beams[1]}, joint, alone);
  const double joint_width = joint.high[0] - joint.low[0];
  const bool narrower = joint_width < alone[0].high[0] - alone[0].low[0] &&
                        joint_width < alone[1].high[0] - alone[1].low[0];
  std::printf("\njoint eta_e interval %s than either beam's alone; truth %s the joint intervals\n",
              narrower ? "narrower" : "NOT narrower", covered ? "inside" : "NOT inside all of");
  if (!narrower || !covered) {
    std::printf("FAILED\n");
    return 1;
  }
  std::printf("OK\n");
  return 0;
}
