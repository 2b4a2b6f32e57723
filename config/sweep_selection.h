// Which measured sweeps a config fits or validates: "F1" names both directions
// of sweep F1, "F1/up" and "F1/down" one direction each (Sweep::Name()).
#ifndef DWELLFIT_CONFIG_SWEEP_SELECTION_H_
#define DWELLFIT_CONFIG_SWEEP_SELECTION_H_

#include <optional>
#include <string>

#include "dwellfit/estimator/data/sweep.h"

namespace dwellfit {

struct SweepSelection {
  std::string sweep_id;                     // the data's `sweep` column
  std::optional<SweepDirection> direction;  // unset: both directions

  // "F1", "F1/up" or "F1/down": the text a config uses.
  std::string Name() const;
  bool Selects(const Sweep& sweep) const;
  // True when some sweep is selected by both (F1 overlaps F1/up; F1/up does
  // not overlap F1/down).
  bool Overlaps(const SweepSelection& other) const;
};

// Parses "F1", "F1/up" or "F1/down". The text after the last '/' must be a
// direction. Returns false and sets `error` (what to write instead) otherwise.
bool ParseSweepSelection(const std::string& text, SweepSelection* selection, std::string* error);

}  // namespace dwellfit

#endif  // DWELLFIT_CONFIG_SWEEP_SELECTION_H_
