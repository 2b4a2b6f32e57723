#include "dwellfit/estimator/fit/fit_description.h"

#include <algorithm>
#include <cmath>
#include <functional>

#include "dwellfit/estimator/common/string_printf.h"
#include "glog/logging.h"

namespace dwellfit {

ParameterMap IdentityMap(double* parameters) {
  ParameterMap map;
  for (int i = 0; i < kNumParameters; ++i) map[i] = {parameters, i};
  return map;
}

namespace {

std::string Quoted(const std::string& name) { return "'" + name + "'"; }

// A per-entry vector of `block` given with the wrong length.
bool CheckLength(const FitBlock& block, size_t length, const char* field, std::string* error) {
  if (length == 0 || length == static_cast<size_t>(block.size)) return true;
  *error = "block " + Quoted(block.name) + ": " + field + " has " + std::to_string(length) +
           " entries, the block " + std::to_string(block.size) + " (give one per entry, or none)";
  return false;
}

bool BlockIsValid(const FitDescription& fit, int b, std::string* error) {
  const FitBlock& block = fit.blocks[b];
  const std::string name = "block " + Quoted(block.name);
  if (block.values == nullptr) {
    *error = name + ": values is null (point it at the caller's storage)";
    return false;
  }
  if (block.size < 1) {
    *error = name + ": size must be at least 1, got " + std::to_string(block.size);
    return false;
  }
  if (!CheckLength(block, block.entry_names.size(), "entry_names", error) ||
      !CheckLength(block, block.fixed.size(), "fixed", error) ||
      !CheckLength(block, block.scale.size(), "scale", error)) {
    return false;
  }
  for (int i = 0; i < block.size; ++i) {
    if (!std::isfinite(block.values[i])) {
      *error = name + ": " + fit.EntryName(fit.Offset(b) + i) + " is " +
               StringPrintf("%g", block.values[i]) + "; every value must be a finite number";
      return false;
    }
    const bool free = block.fixed.empty() || !block.fixed[i];
    if (free && !block.scale.empty() && !(block.scale[i] > 0.0 && std::isfinite(block.scale[i]))) {
      *error = name + ": scale of " + fit.EntryName(fit.Offset(b) + i) +
               " must be positive and finite (> 0), got " + StringPrintf("%g", block.scale[i]);
      return false;
    }
  }
  // Two blocks on the same storage would be one parameter block to Ceres.
  const std::less<const double*> before;
  for (int c = 0; c < b; ++c) {
    const FitBlock& other = fit.blocks[c];
    if (other.values == nullptr || other.size < 1) continue;
    if (before(block.values, other.values + other.size) &&
        before(other.values, block.values + block.size)) {
      *error = "blocks " + Quoted(other.name) + " and " + Quoted(block.name) +
               " overlap in memory: each block needs storage of its own";
      return false;
    }
  }
  return true;
}

// The value of parameter `i` of `dataset`, in `slot`, is inside the model's
// range.
bool IsInModelRange(const FitDescription& fit, const FitDataset& dataset, int i,
                    const ParameterSlot& slot, std::string* error) {
  const double value = slot.block[slot.index];
  const bool positive = i == kEtaE || i == kNaturalFrequency;
  const bool non_negative = i == kMu1 || i == kMu2;
  if ((positive && value > 0.0) || (non_negative && value >= 0.0) || !(positive || non_negative)) {
    return true;
  }
  *error = "dataset " + Quoted(dataset.name) + ": " + ParameterName(i) + " (" +
           fit.EntryName(fit.AmbientIndex(slot)) + ") must be " +
           (positive ? "positive (> 0)" : "non-negative (>= 0: it is bounded below by 0)") +
           ", got " + StringPrintf("%g", value);
  return false;
}

bool DatasetIsValid(const FitDescription& fit, const FitDataset& dataset, std::string* error) {
  const std::string name = "dataset " + Quoted(dataset.name);
  int dwells = 0;
  for (const Sweep* sweep : dataset.sweeps) {
    if (sweep == nullptr) {
      *error = name + ": a sweep pointer is null";
      return false;
    }
    dwells += static_cast<int>(sweep->points.size());
  }
  if (dwells == 0) {
    *error = name + ": no dwell points to fit (its sweeps are empty)";
    return false;
  }
  for (int i = 0; i < kNumParameters; ++i) {
    const ParameterSlot& slot = dataset.parameters[i];
    const int b = fit.BlockOf(slot.block);
    if (b < 0) {
      *error = name + ": " + ParameterName(i) +
               " is mapped to a block that is not in FitDescription::blocks";
      return false;
    }
    if (slot.index < 0 || slot.index >= fit.blocks[b].size) {
      *error = name + ": " + ParameterName(i) + " is mapped to entry " +
               std::to_string(slot.index) + " of block " + Quoted(fit.blocks[b].name) +
               ", which has entries 0 to " + std::to_string(fit.blocks[b].size - 1);
      return false;
    }
    if (!IsInModelRange(fit, dataset, i, slot, error)) return false;
  }
  return true;
}

}  // namespace

bool FitDescription::IsValid(std::string* error) const {
  if (blocks.empty()) {
    *error = "FitDescription::blocks is empty: describe at least one parameter block";
    return false;
  }
  if (datasets.empty()) {
    *error = "FitDescription::datasets is empty: describe at least one dataset";
    return false;
  }
  for (int b = 0; b < static_cast<int>(blocks.size()); ++b) {
    if (!BlockIsValid(*this, b, error)) return false;
  }
  for (const FitDataset& dataset : datasets) {
    if (!DatasetIsValid(*this, dataset, error)) return false;
  }
  return true;
}

int FitDescription::NumEntries() const { return Offset(static_cast<int>(blocks.size())); }

int FitDescription::Offset(int block) const {
  int offset = 0;
  for (int b = 0; b < block; ++b) offset += blocks[b].size;
  return offset;
}

int FitDescription::BlockOf(const double* values) const {
  for (int b = 0; b < static_cast<int>(blocks.size()); ++b) {
    if (blocks[b].values == values) return b;
  }
  return -1;
}

int FitDescription::AmbientIndex(const ParameterSlot& slot) const {
  const int b = BlockOf(slot.block);
  if (b < 0 || slot.index < 0 || slot.index >= blocks[b].size) return -1;
  return Offset(b) + slot.index;
}

std::string FitDescription::EntryName(int ambient) const {
  int b = 0;
  while (ambient >= blocks[b].size) ambient -= blocks[b++].size;
  const FitBlock& block = blocks[b];
  if (!block.entry_names.empty()) return block.entry_names[ambient];
  return block.size == 1 ? block.name : block.name + "[" + std::to_string(ambient) + "]";
}

std::vector<double> FitDescription::Values() const {
  std::vector<double> values;
  for (const FitBlock& block : blocks)
    values.insert(values.end(), block.values, block.values + block.size);
  return values;
}

void FitDescription::SetValues(const std::vector<double>& values) const {
  CHECK_EQ(static_cast<int>(values.size()), NumEntries());
  auto next = values.begin();
  for (const FitBlock& block : blocks) {
    std::copy(next, next + block.size, block.values);
    next += block.size;
  }
}

std::vector<bool> FitDescription::FixedEntries() const {
  std::vector<bool> fixed;
  for (const FitBlock& block : blocks) {
    for (int i = 0; i < block.size; ++i) fixed.push_back(!block.fixed.empty() && block.fixed[i]);
  }
  return fixed;
}

std::vector<bool> FitDescription::EntriesHolding(std::initializer_list<int> parameters) const {
  std::vector<bool> holding(NumEntries(), false);
  for (const FitDataset& dataset : datasets) {
    for (int parameter : parameters) {
      const int entry = AmbientIndex(dataset.parameters[parameter]);
      if (entry >= 0) holding[entry] = true;
    }
  }
  return holding;
}

int FitDescription::NumDwells() const {
  int dwells = 0;
  for (const FitDataset& dataset : datasets) {
    for (const Sweep* sweep : dataset.sweeps) dwells += static_cast<int>(sweep->points.size());
  }
  return dwells;
}

FitDescription SingleBlockFit(const std::vector<const Sweep*>& sweeps,
                              const std::array<bool, kNumParameters>& fixed,
                              ParameterVector* parameters, ModelForm form) {
  FitDescription fit;
  fit.blocks = {{parameters->data(), kNumParameters, "parameters"}};
  const auto names = ParameterNames(form);
  fit.blocks[0].entry_names.assign(names.begin(), names.end());
  fit.blocks[0].fixed.assign(fixed.begin(), fixed.end());
  fit.datasets = {{"fit", sweeps, IdentityMap(parameters->data())}};
  return fit;
}

bool ParameterLayout::IsIdentity() const {
  if (blocks.size() != 1 || sizes[0] != kNumParameters) return false;
  for (int i = 0; i < kNumParameters; ++i) {
    if (index[i] != i) return false;
  }
  return true;
}

ParameterVector ParameterLayout::Values() const {
  ParameterVector p;
  for (int i = 0; i < kNumParameters; ++i) p[i] = blocks[block[i]][index[i]];
  return p;
}

ParameterLayout LayoutOf(const FitDescription& fit, const ParameterMap& map) {
  ParameterLayout layout;
  for (int i = 0; i < kNumParameters; ++i) {
    const auto found = std::find(layout.blocks.begin(), layout.blocks.end(), map[i].block);
    const int position = static_cast<int>(found - layout.blocks.begin());
    if (found == layout.blocks.end()) {
      const int b = fit.BlockOf(map[i].block);
      CHECK_GE(b, 0) << ParameterName(i) << " is mapped to a block the description lacks";
      layout.blocks.push_back(map[i].block);
      layout.sizes.push_back(fit.blocks[b].size);
    }
    layout.block[i] = position;
    layout.index[i] = map[i].index;
  }
  return layout;
}

}  // namespace dwellfit
