#include "dwellfit/estimator/data/sweep.h"

namespace dwellfit {

const char* SweepDirectionName(SweepDirection direction) {
  return direction == SweepDirection::kUp ? "up" : "down";
}

bool SweepDirectionFromName(const std::string& name, SweepDirection* direction) {
  if (name != "up" && name != "down") return false;
  *direction = name == "up" ? SweepDirection::kUp : SweepDirection::kDown;
  return true;
}

std::string Sweep::Name() const { return id + "/" + SweepDirectionName(direction); }

}  // namespace dwellfit
