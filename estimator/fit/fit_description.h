// FitDescription: what a staged solve (staged_solve.h) optimises.
//
// The caller owns the parameter blocks. Each dataset (sweeps of one beam
// mode) reads its six model parameters from entries of those blocks through
// a ParameterMap: two datasets sharing eta_e map it to the same entry. The
// caller's own residual blocks (priors, other measurements) join every
// problem the solve assembles through `add_residuals`.
//
//   double shared[1] = {90.0};             // eta_e of both datasets
//   double beam_a[5] = {...}, beam_b[5] = {...};  // mu1, mu2, delta, alpha, w
//   FitDescription fit;
//   fit.blocks = {{shared, 1, "eta_e"}, {beam_a, 5, "A"}, {beam_b, 5, "B"}};
//   ParameterMap a = {{{shared, 0}, {beam_a, 0}, {beam_a, 1}, {beam_a, 2}, {beam_a, 3},
//                      {beam_a, 4}}};
//   fit.datasets = {{"A", sweeps_a, a}, {"B", sweeps_b, ...}};
//
// Per entry (ambient order: the blocks in order, each entry in order):
// - fixed entries keep their value;
// - free entries are stepped in units of their scale (ScaledSubsetManifold),
//   by default the magnitude of the entry's value when the solve starts;
// - an entry holding eta_e of some dataset is bounded below by 0, one holding
//   mu1 or mu2 too (except on the algebraic stage, see staged_solve.h).
#ifndef DWELLFIT_ESTIMATOR_FIT_FIT_DESCRIPTION_H_
#define DWELLFIT_ESTIMATOR_FIT_FIT_DESCRIPTION_H_

#include <array>
#include <functional>
#include <initializer_list>
#include <string>
#include <vector>

#include "ceres/problem.h"
#include "dwellfit/estimator/data/sweep.h"
#include "dwellfit/residuals/model/model_form.h"
#include "dwellfit/residuals/model/model_parameters.h"

namespace dwellfit {

// Where one model parameter lives: entry `index` of the block `block`.
struct ParameterSlot {
  double* block = nullptr;  // the `values` of one of FitDescription::blocks
  int index = 0;
};

// The slot of each model parameter of one dataset, in ParameterIndex order.
using ParameterMap = std::array<ParameterSlot, kNumParameters>;

// Parameter i in entry i of the one 6-double block `parameters`.
ParameterMap IdentityMap(double* parameters);

struct FitBlock {
  double* values = nullptr;  // `size` doubles; must outlive every solve on it
  int size = 0;
  std::string name;  // in messages
  // Optional, one per entry when given (empty: the default).
  std::vector<std::string> entry_names;  // default "name[i]" ("name" for a 1-block)
  std::vector<bool> fixed;               // default: every entry free
  std::vector<double> scale;             // step unit; default |value at the start|, 1 for 0
};

// One dataset: its sweeps (as DetectJumps leaves them) and where its six
// parameters live.
struct FitDataset {
  std::string name;  // in messages
  std::vector<const Sweep*> sweeps;
  ParameterMap parameters;
};

struct FitDescription {
  std::vector<FitBlock> blocks;
  std::vector<FitDataset> datasets;
  // Adds the caller's own residual blocks each time a problem is assembled
  // (every solve and the covariance), after the dwells and penalties; the
  // problem owns the cost functions created inside. They may also read
  // blocks of the caller's own (free, unscaled, constant in the covariance).
  std::function<void(ceres::Problem*)> add_residuals;

  // False, with a message naming the dataset, block or entry, when the
  // description cannot be solved (no dwell, a slot outside the blocks,
  // overlapping blocks, wrong lengths, bad scales or values).
  bool IsValid(std::string* error) const;

  int NumEntries() const;                             // over all blocks (the ambient size)
  int Offset(int block) const;                        // ambient index of the block's entry 0
  int BlockOf(const double* values) const;            // or -1
  int AmbientIndex(const ParameterSlot& slot) const;  // or -1 when not described
  // For messages: entry_names[index] or "name[index]" ("name" for a 1-block).
  std::string EntryName(int ambient) const;
  std::vector<double> Values() const;  // ambient order
  void SetValues(const std::vector<double>& values) const;
  std::vector<bool> FixedEntries() const;  // per ambient entry
  // Per ambient entry: whether some dataset maps one of `parameters` there.
  std::vector<bool> EntriesHolding(std::initializer_list<int> parameters) const;
  int NumDwells() const;
};

// The single-dataset fit: one 6-double block `parameters` with `fixed`, its
// entries named after `form`'s member.
FitDescription SingleBlockFit(const std::vector<const Sweep*>& sweeps,
                              const std::array<bool, kNumParameters>& fixed,
                              ParameterVector* parameters, ModelForm form = ModelForm{});

// The distinct blocks a dataset's six parameters live in, in order of first
// use, and the position and entry of each parameter among them.
struct ParameterLayout {
  std::vector<double*> blocks;
  std::vector<int> sizes;
  std::array<int, kNumParameters> block{};  // position in `blocks`
  std::array<int, kNumParameters> index{};  // entry in that block
  // One block of six whose entry i holds parameter i.
  bool IsIdentity() const;
  ParameterVector Values() const;  // the six parameters at the blocks' values
};

// The layout of `map` over the blocks of `fit` (every slot described).
ParameterLayout LayoutOf(const FitDescription& fit, const ParameterMap& map);

}  // namespace dwellfit

#endif  // DWELLFIT_ESTIMATOR_FIT_FIT_DESCRIPTION_H_
