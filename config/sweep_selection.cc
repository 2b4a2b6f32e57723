#include "dwellfit/config/sweep_selection.h"

namespace dwellfit {

std::string SweepSelection::Name() const {
  if (!direction.has_value()) return sweep_id;
  return sweep_id + "/" + SweepDirectionName(*direction);
}

bool SweepSelection::Selects(const Sweep& sweep) const {
  return sweep.id == sweep_id && (!direction.has_value() || *direction == sweep.direction);
}

bool SweepSelection::Overlaps(const SweepSelection& other) const {
  if (sweep_id != other.sweep_id) return false;
  return !direction.has_value() || !other.direction.has_value() || *direction == *other.direction;
}

bool ParseSweepSelection(const std::string& text, SweepSelection* selection, std::string* error) {
  SweepSelection parsed;
  const std::string::size_type slash = text.rfind('/');
  parsed.sweep_id = text.substr(0, slash);
  if (slash != std::string::npos) {
    const std::string direction_name = text.substr(slash + 1);
    SweepDirection direction;
    if (!SweepDirectionFromName(direction_name, &direction)) {
      *error = "'" + text + "' has direction '" + direction_name + "'; write '" + parsed.sweep_id +
               "' for both directions, or '" + parsed.sweep_id + "/up' or '" + parsed.sweep_id +
               "/down' for one";
      return false;
    }
    parsed.direction = direction;
  }
  if (parsed.sweep_id.empty()) {
    *error = "'" + text + "' has no sweep id; write the value of the data's 'sweep' column, " +
             "e.g. 'F1' or 'F1/up'";
    return false;
  }
  *selection = parsed;
  return true;
}

}  // namespace dwellfit
