#include "dwellfit/estimator/data/jump_detection.h"

#include <glog/logging.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "dwellfit/estimator/common/input_error.h"
#include "dwellfit/estimator/common/string_printf.h"
#include "dwellfit/residuals/model/model_parameters.h"

namespace dwellfit {
namespace {

// "4.7e-3": one decimal of mantissa, exponent without padding zeros.
std::string ShortScientific(double value) {
  const std::string text = StringPrintf("%.1e", value);
  const size_t e = text.find('e');
  if (e == std::string::npos) return text;  // inf or nan
  const int exponent = std::atoi(text.c_str() + e + 1);
  return text.substr(0, e) + "e" + std::to_string(exponent);
}

// True when `text` reads back as `value` up to the rounding of a unit
// conversion: the decimal as the data file has it.
bool ReadsBackAs(const std::string& text, double value) {
  return std::abs(std::strtod(text.c_str(), nullptr) - value) <= 1e-9 * std::abs(value);
}

// Formats both bracket ends with `format` (one precision argument), raising
// the precision from `precision` until the two ends print differently and
// each shows all the digits it has in the data (so it can be copied into the
// config's `jumps:`).
std::pair<std::string, std::string> DistinctPair(const char* format, int precision, double a,
                                                 double b) {
  std::string first, second;
  for (int p = precision; p <= 12; ++p) {
    first = StringPrintf(format, p, a);
    second = StringPrintf(format, p, b);
    if (first != second && ReadsBackAs(first, a) && ReadsBackAs(second, b)) break;
  }
  return {first, second};
}

// "161.041 and 161.012 Hz" or "a_base 0.0354 and 0.036".
std::string DescribeBracket(SweepKind kind, double control_before, double control_after) {
  if (kind == SweepKind::kFrequency) {
    const auto [before, after] =
        DistinctPair("%.*f", 2, RadPerSecondToHz(control_before), RadPerSecondToHz(control_after));
    return before + " and " + after + " Hz";
  }
  const auto [before, after] = DistinctPair("%.*g", 3, control_before, control_after);
  return "a_base " + before + " and " + after;
}

// A note when the jump's direction does not fit a hardening response, or the
// model at all; "" otherwise.
std::string DirectionNote(const Sweep& sweep, const JumpBracket& jump) {
  const bool up_sweep = sweep.direction == SweepDirection::kUp;
  const bool jump_up = jump.kind == JumpKind::kJumpUp;
  if (sweep.kind == SweepKind::kFrequency) {
    // Hardening: the upper branch leans to high frequencies, so going up the
    // response falls off it (jump down) and going down it climbs on (jump up).
    if (up_sweep != jump_up) return "";
    return up_sweep ? "; note: a jump up going up in frequency fits a softening response "
                      "(a hardening one jumps down)"
                    : "; note: a jump down going down in frequency fits a softening response "
                      "(a hardening one jumps up)";
  }
  // At a fixed frequency a rising a_base can only leave the lower branch
  // (jump up) and a falling one only the upper branch (jump down).
  if (up_sweep == jump_up) return "";
  return up_sweep ? "; note: unexpected, the model jumps up as a_base rises"
                  : "; note: unexpected, the model jumps down as a_base falls";
}

std::string DescribeJump(const Sweep& sweep, const JumpBracket& jump) {
  std::string text = std::string(JumpKindName(jump.kind)) + " between " +
                     DescribeBracket(sweep.kind, jump.control_before, jump.control_after);
  if (jump.into_missing_data) {
    text += " into missing data (a " + ShortScientific(jump.amplitude_before) + " -> not measured)";
  } else {
    text += " (a " + ShortScientific(jump.amplitude_before) + " -> " +
            ShortScientific(jump.amplitude_after) + ")";
  }
  return text + DirectionNote(sweep, jump);
}

// The median of `values` (non-empty); the mean of the middle two for an even count.
double Median(std::vector<double> values) {
  const size_t middle = values.size() / 2;
  std::nth_element(values.begin(), values.begin() + middle, values.end());
  const double upper = values[middle];
  if (values.size() % 2 == 1) return upper;
  return 0.5 * (upper + *std::max_element(values.begin(), values.begin() + middle));
}

// The largest amplitude of `points` (0 for none).
double LargestAmplitude(const std::vector<DwellPoint>& points) {
  double largest = 0.0;
  for (const DwellPoint& point : points) largest = std::max(largest, point.amplitude);
  return largest;
}

// Labels the points of `sweep` by its single jump (or kOnly without one): a
// jump down leaves the upper branch for the lower; a jump up the reverse.
void LabelBranches(Sweep* sweep) {
  for (DwellPoint& point : sweep->points) point.branch = Branch::kOnly;
  if (sweep->jumps.empty()) return;
  const JumpBracket& jump = sweep->jumps.front();
  const bool down = jump.kind == JumpKind::kJumpDown;
  for (int i = 0; i < static_cast<int>(sweep->points.size()); ++i) {
    const bool before_jump = i <= jump.index_before;
    sweep->points[i].branch = before_jump == down ? Branch::kUpper : Branch::kLower;
  }
}

// The jump down into the missing rows at the end of `sweep`, if it has one
// (see DetectJumps).
std::optional<JumpBracket> JumpIntoMissingData(const JumpDetectionOptions& options,
                                               const Sweep& sweep) {
  if (sweep.points.empty()) return std::nullopt;
  const int last = static_cast<int>(sweep.points.size()) - 1;
  const DwellPoint& before = sweep.points[last];
  if (before.amplitude < options.min_relative_amplitude * LargestAmplitude(sweep.points)) {
    return std::nullopt;
  }
  for (const MissingDwell& row : sweep.missing) {
    // Rows after the last dwell are all missing; the first at another
    // control closes the bracket.
    if (row.points_before <= last || sweep.Control(row) == sweep.Control(before)) continue;
    JumpBracket jump{JumpKind::kJumpDown, last, sweep.Control(before), sweep.Control(row),
                     before.amplitude};
    jump.into_missing_data = true;  // amplitude_after stays 0
    return jump;
  }
  return std::nullopt;
}

// "161.041 Hz" or "a_base 0.036": one control, with all its digits.
std::string DescribeControl(SweepKind kind, double control) {
  if (kind == SweepKind::kFrequency)
    return StringPrintf("%.10g", RadPerSecondToHz(control)) + " Hz";
  return "a_base " + StringPrintf("%.10g", control);
}

}  // namespace

JumpEvidence WeighJumpEvidence(const JumpDetectionOptions& options, const Sweep& sweep) {
  std::string error;
  CHECK(options.IsValid(&error)) << error;
  const std::vector<DwellPoint>& points = sweep.points;
  for (const DwellPoint& point : points) {
    CHECK_GT(point.amplitude, 0.0) << "dwell amplitudes must be positive (loader drops a <= 0)";
  }
  const double amplitude_floor = options.min_relative_amplitude * LargestAmplitude(points);

  // Candidate steps i -> i+1: r = ln(a_{i+1} / a_i), x = ln(c_{i+1} / c_i).
  std::vector<int> candidates;
  std::vector<double> log_ratio, log_control_step;
  for (int i = 0; i + 1 < static_cast<int>(points.size()); ++i) {
    const double a0 = points[i].amplitude;
    const double a1 = points[i + 1].amplitude;
    const double c0 = sweep.Control(points[i]);
    const double c1 = sweep.Control(points[i + 1]);
    if (std::max(a0, a1) < amplitude_floor || c0 == c1) continue;
    candidates.push_back(i);
    log_ratio.push_back(std::log(a1 / a0));
    log_control_step.push_back(std::log(c1 / c0));
  }
  JumpEvidence evidence;
  evidence.candidate_steps = static_cast<int>(candidates.size());
  if (candidates.empty()) return evidence;

  // Amplitude sweeps: remove the power-law trend a ~ a_base^p.
  if (sweep.kind == SweepKind::kAmplitude) {
    std::vector<double> slopes;
    for (size_t k = 0; k < candidates.size(); ++k) {
      slopes.push_back(log_ratio[k] / log_control_step[k]);
    }
    evidence.trend_slope = Median(slopes);
  }
  std::vector<double> excess;
  size_t best = 0;
  for (size_t k = 0; k < candidates.size(); ++k) {
    excess.push_back(log_ratio[k] - evidence.trend_slope * log_control_step[k]);
    if (std::abs(excess[k]) > std::abs(excess[best])) best = k;
  }
  evidence.step = candidates[best];
  evidence.log_ratio = log_ratio[best];
  evidence.log_excess = excess[best];

  // Robust standard deviation of a step: 1.4826 MAD (exact for normal noise).
  const double centre = Median(excess);
  std::vector<double> deviations;
  for (double e : excess) deviations.push_back(std::abs(e - centre));
  evidence.noise_sigma = 1.4826 * Median(deviations);
  evidence.threshold =
      std::max(std::log(options.min_ratio), options.noise_multiple * evidence.noise_sigma);
  evidence.accepted = evidence.candidate_steps >= options.min_candidate_steps &&
                      std::abs(evidence.log_excess) > evidence.threshold;
  return evidence;
}

void DetectJumps(const JumpDetectionOptions& options, Sweep* sweep) {
  sweep->jumps.clear();
  sweep->jumps_from_config = false;
  const JumpEvidence evidence = WeighJumpEvidence(options, *sweep);
  if (evidence.candidate_steps > 0 && evidence.candidate_steps < options.min_candidate_steps) {
    LOG(WARNING) << "sweep " << sweep->Name() << ": only " << evidence.candidate_steps
                 << " steps reach the amplitude gate (jump_detection.min_candidate_steps "
                 << options.min_candidate_steps
                 << "), too few to tell a jump from noise: no jump detected; if it has one, "
                    "state it in the config's jumps:";
  }
  if (evidence.accepted) {
    const DwellPoint& before = sweep->points[evidence.step];
    const DwellPoint& after = sweep->points[evidence.step + 1];
    const JumpKind kind =
        after.amplitude > before.amplitude ? JumpKind::kJumpUp : JumpKind::kJumpDown;
    sweep->jumps.push_back(JumpBracket{kind, evidence.step, sweep->Control(before),
                                       sweep->Control(after), before.amplitude, after.amplitude});
  } else if (const std::optional<JumpBracket> jump = JumpIntoMissingData(options, *sweep)) {
    sweep->jumps.push_back(*jump);
  }
  LabelBranches(sweep);
}

void DetectJumps(const JumpDetectionOptions& options, std::vector<Sweep>* sweeps) {
  for (Sweep& sweep : *sweeps) DetectJumps(options, &sweep);
}

void ApplyJumpOverride(const JumpOverride& jump_override, const std::string& config_path,
                       Sweep* sweep) {
  const std::string name = "sweep '" + sweep->Name() + "'";
  const auto fail = [&](const std::string& what) {
    throw InputError(config_path, jump_override.line, jump_override.field, name + ": " + what);
  };
  if (jump_override.none) {
    sweep->jumps.clear();
    sweep->jumps_from_config = true;
    LabelBranches(sweep);
    return;
  }
  if (jump_override.control != sweep->kind) {
    fail(sweep->kind == SweepKind::kFrequency
             ? "is a frequency sweep; give its jump as between_hz"
             : "is an amplitude sweep; give its jump as between_a_base");
  }
  const std::vector<DwellPoint>& points = sweep->points;
  if (points.empty()) fail("has no dwells, so no jump between two of them");
  const double before = jump_override.control_before;
  const double after = jump_override.control_after;
  const std::string bracket =
      "[" + DescribeControl(sweep->kind, before) + ", " + DescribeControl(sweep->kind, after) + "]";
  // +1: the bracket runs toward larger controls, as an up-sweep does.
  const double sense = after > before ? 1.0 : -1.0;
  const bool up = sweep->direction == SweepDirection::kUp;
  if (!(after != before) || (sense > 0) != up) {
    fail("the bracket " + bracket + " must run " + (up ? "upward" : "downward") +
         " like the sweep: give the control before the jump first, in measurement order");
  }
  // Equal up to the last digits of a decimal typed for a value read from a file.
  const auto at_or_before = [&](double control, double limit) {
    return sense * (control - limit) <= 1e-12 * std::abs(limit);
  };
  int index_before = -1;
  for (int i = 0; i < static_cast<int>(points.size()); ++i) {
    if (at_or_before(sweep->Control(points[i]), before)) index_before = i;
  }
  const bool enclosed = index_before >= 0 && index_before + 1 < static_cast<int>(points.size()) &&
                        at_or_before(after, sweep->Control(points[index_before + 1]));
  if (!enclosed) {
    std::string inside;
    for (const DwellPoint& point : points) {
      const double control = sweep->Control(point);
      if (!at_or_before(control, before) && !at_or_before(after, control)) {
        inside += (inside.empty() ? "" : ", ") + DescribeControl(sweep->kind, control);
        if (inside.size() > 200) break;
      }
    }
    std::string what = "the bracket " + bracket + " does not lie between two consecutive dwells";
    if (!inside.empty()) {
      what += " (dwells inside it: " + inside + ")";
    } else if (index_before < 0 || index_before + 1 >= static_cast<int>(points.size())) {
      what += " (the sweep runs from " +
              DescribeControl(sweep->kind, sweep->Control(points.front())) + " to " +
              DescribeControl(sweep->kind, sweep->Control(points.back())) + ")";
    }
    fail(what + "; give the controls of the last dwell before the jump and the first after it");
  }
  sweep->jumps = {JumpBracket{jump_override.kind, index_before, before, after,
                              points[index_before].amplitude, points[index_before + 1].amplitude}};
  sweep->jumps_from_config = true;
  LabelBranches(sweep);
}

void ApplyJumpOverrides(const std::vector<JumpOverride>& overrides, const std::string& config_path,
                        std::vector<Sweep>* sweeps) {
  for (const JumpOverride& jump_override : overrides) {
    const auto found = std::find_if(sweeps->begin(), sweeps->end(), [&](const Sweep& sweep) {
      return sweep.Name() == jump_override.sweep;
    });
    if (found == sweeps->end()) {
      std::string available;
      for (const Sweep& sweep : *sweeps) {
        available += (available.empty() ? "" : ", ") + sweep.Name();
      }
      throw InputError(
          config_path, jump_override.line, jump_override.field,
          "sweep '" + jump_override.sweep + "' is not in the data; available: " + available);
    }
    ApplyJumpOverride(jump_override, config_path, &*found);
  }
}

std::string DescribeJumps(const Sweep& sweep) {
  std::string text = sweep.Name() + ": ";
  const std::string from_config = sweep.jumps_from_config ? " [config]" : "";
  if (sweep.jumps.empty()) {
    return text + "no jump (" + std::to_string(sweep.points.size()) + " dwells, largest a " +
           ShortScientific(LargestAmplitude(sweep.points)) + ")" + from_config;
  }
  for (size_t j = 0; j < sweep.jumps.size(); ++j) {
    if (j > 0) text += "; ";
    text += DescribeJump(sweep, sweep.jumps[j]);
  }
  return text + from_config;
}

bool JumpDetectionOptions::IsValid(std::string* error) const {
  if (!(min_ratio > 1.0) || !std::isfinite(min_ratio)) {
    *error = "jump_detection.min_ratio must be greater than 1";
    return false;
  }
  if (!(min_relative_amplitude >= 0.0 && min_relative_amplitude <= 1.0)) {
    *error = "jump_detection.min_relative_amplitude must lie in [0, 1]";
    return false;
  }
  if (!(noise_multiple >= 0.0) || !std::isfinite(noise_multiple)) {
    *error = "jump_detection.noise_multiple must be a non-negative number (0: no noise test)";
    return false;
  }
  if (min_candidate_steps < 1) {
    *error = "jump_detection.min_candidate_steps must be at least 1";
    return false;
  }
  return true;
}

}  // namespace dwellfit
