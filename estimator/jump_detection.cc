#include "estimator/jump_detection.h"

#include <glog/logging.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "residuals/model_parameters.h"

namespace dwellfit {
namespace {

// printf-style formatting into a std::string.
template <typename... Args>
std::string Format(const char* format, Args... args) {
  char buffer[64];
  std::snprintf(buffer, sizeof(buffer), format, args...);
  return buffer;
}

// "4.7e-3": one decimal of mantissa, exponent without padding zeros.
std::string ShortScientific(double value) {
  const std::string text = Format("%.1e", value);
  const size_t e = text.find('e');
  if (e == std::string::npos) return text;  // inf or nan
  const int exponent = std::atoi(text.c_str() + e + 1);
  return text.substr(0, e) + "e" + std::to_string(exponent);
}

// Formats both bracket ends with `format` (one precision argument), raising
// the precision from `precision` until the two ends print differently.
std::pair<std::string, std::string> DistinctPair(const char* format, int precision, double a,
                                                 double b) {
  std::string first, second;
  for (int p = precision; p <= 12; ++p) {
    first = Format(format, p, a);
    second = Format(format, p, b);
    if (first != second) break;
  }
  return {first, second};
}

std::string DescribeJump(const Sweep& sweep, const JumpBracket& jump) {
  std::string text = std::string(JumpKindName(jump.kind)) + " between ";
  if (sweep.kind == SweepKind::kFrequency) {
    const auto [before, after] = DistinctPair("%.*f", 2, RadPerSecondToHz(jump.control_before),
                                              RadPerSecondToHz(jump.control_after));
    text += before + " and " + after + " Hz";
  } else {
    const auto [before, after] = DistinctPair("%.*g", 3, jump.control_before, jump.control_after);
    text += "a_base " + before + " and " + after;
  }
  return text + " (a " + ShortScientific(jump.amplitude_before) + " -> " +
         ShortScientific(jump.amplitude_after) + ")";
}

}  // namespace

void DetectJumps(const JumpDetectionOptions& options, Sweep* sweep) {
  std::string error;
  CHECK(options.IsValid(&error)) << error;
  std::vector<DwellPoint>& points = sweep->points;
  sweep->jumps.clear();
  for (DwellPoint& point : points) point.branch = Branch::kOnly;

  double largest_amplitude = 0.0;
  for (const DwellPoint& point : points) {
    CHECK_GT(point.amplitude, 0.0) << "dwell amplitudes must be positive (loader drops a <= 0)";
    largest_amplitude = std::max(largest_amplitude, point.amplitude);
  }
  const double amplitude_floor = options.min_relative_amplitude * largest_amplitude;

  // The step with the largest |ln(a_{i+1} / a_i)| among those above the floor.
  int best = -1;
  double best_log_ratio = 0.0;
  for (int i = 0; i + 1 < static_cast<int>(points.size()); ++i) {
    const double a0 = points[i].amplitude;
    const double a1 = points[i + 1].amplitude;
    if (std::max(a0, a1) < amplitude_floor) continue;
    const double log_ratio = std::abs(std::log(a1 / a0));
    if (log_ratio > best_log_ratio) {
      best = i;
      best_log_ratio = log_ratio;
    }
  }
  if (best < 0 || !(best_log_ratio > std::log(options.min_ratio))) return;

  const DwellPoint& before = points[best];
  const DwellPoint& after = points[best + 1];
  JumpBracket jump;
  jump.kind = after.amplitude > before.amplitude ? JumpKind::kJumpUp : JumpKind::kJumpDown;
  jump.index_before = best;
  jump.control_before = sweep->Control(before);
  jump.control_after = sweep->Control(after);
  jump.amplitude_before = before.amplitude;
  jump.amplitude_after = after.amplitude;
  sweep->jumps.push_back(jump);

  // A jump down leaves the upper branch for the lower; a jump up the reverse.
  const bool down = jump.kind == JumpKind::kJumpDown;
  for (int i = 0; i < static_cast<int>(points.size()); ++i) {
    const bool before_jump = i <= best;
    points[i].branch = before_jump == down ? Branch::kUpper : Branch::kLower;
  }
}

void DetectJumps(const JumpDetectionOptions& options, std::vector<Sweep>* sweeps) {
  for (Sweep& sweep : *sweeps) DetectJumps(options, &sweep);
}

std::string DescribeJumps(const Sweep& sweep) {
  std::string text = sweep.Name() + ": ";
  if (sweep.jumps.empty()) {
    double largest_amplitude = 0.0;
    for (const DwellPoint& point : sweep.points) {
      largest_amplitude = std::max(largest_amplitude, point.amplitude);
    }
    return text + "no jump (" + std::to_string(sweep.points.size()) + " dwells, largest a " +
           ShortScientific(largest_amplitude) + ")";
  }
  for (size_t j = 0; j < sweep.jumps.size(); ++j) {
    if (j > 0) text += "; ";
    text += DescribeJump(sweep, sweep.jumps[j]);
  }
  return text;
}

}  // namespace dwellfit
