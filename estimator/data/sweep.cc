#include "dwellfit/estimator/data/sweep.h"

#include <cmath>

namespace dwellfit {

const char* SweepDirectionName(SweepDirection direction) {
  return direction == SweepDirection::kUp ? "up" : "down";
}

bool SweepDirectionFromName(const std::string& name, SweepDirection* direction) {
  if (name == "up") {
    *direction = SweepDirection::kUp;
    return true;
  }
  if (name == "down") {
    *direction = SweepDirection::kDown;
    return true;
  }
  return false;
}

double JumpBracket::half_width() const { return 0.5 * std::abs(control_after - control_before); }

std::string Sweep::Name() const { return id + "/" + SweepDirectionName(direction); }

}  // namespace dwellfit
