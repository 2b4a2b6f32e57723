#include "dwellfit/estimator/data/sweep.h"

#include "dwellfit/estimator/common/name_table.h"

namespace dwellfit {
namespace {

constexpr const char* kSweepDirectionNames[] = {"up", "down"};  // in enumerator order

}  // namespace

const char* SweepDirectionName(SweepDirection direction) {
  return NameOf(kSweepDirectionNames, direction);
}

bool SweepDirectionFromName(const std::string& name, SweepDirection* direction) {
  return FromName(name, kSweepDirectionNames, direction);
}

std::string Sweep::Name() const { return id + "/" + SweepDirectionName(direction); }

}  // namespace dwellfit
