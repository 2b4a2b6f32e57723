// Fuzz body of the dwell-plan reader (config/dwell_plan_reader.h). An
// accepted plan must be valid (DwellPlan::IsValid) and give each sweep's
// control grid, as simulate_dwell asks for it, with frequencies finite in
// rad/s.
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include "dwellfit/config/dwell_plan_reader.h"
#include "dwellfit/estimator/simulation/dwell_simulator.h"
#include "dwellfit/estimator/common/input_error.h"
#include "dwellfit/residuals/model/model_parameters.h"
#include "tests/fuzz/fuzz_targets.h"

namespace dwellfit::fuzz {
namespace {

void CheckGrids(const DwellPlan& plan) {
  std::string error;
  if (!plan.IsValid(&error)) throw std::logic_error("ParseDwellPlan accepted an invalid plan");
  for (const SweepPlan& sweep : plan.sweeps) {
    for (SweepDirection direction : sweep.directions) {
      const std::vector<double> grid = ControlGrid(sweep, direction);
      if (grid.size() != static_cast<std::size_t>(sweep.NumSteps()) + 1) {
        throw std::logic_error("ControlGrid: sweep " + sweep.id + ": wrong number of dwells");
      }
      for (double control : grid) {
        // The simulator works in rad/s: frequencies must stay finite there.
        const double frequency_hz =
            sweep.kind == SweepKind::kFrequency ? control : sweep.held_frequency_hz;
        if (!(control > 0.0) || !std::isfinite(control) ||
            !std::isfinite(HzToRadPerSecond(frequency_hz))) {
          throw std::logic_error("ControlGrid: sweep " + sweep.id + ": control " +
                                 std::to_string(control) + " at " + std::to_string(frequency_hz) +
                                 " Hz is not positive and finite (in rad/s too)");
        }
      }
    }
  }
}

}  // namespace

void DwellPlanBody(const std::uint8_t* data, std::size_t size) {
  DwellPlan plan;
  try {
    plan = ParseDwellPlan(std::string(reinterpret_cast<const char*>(data), size), "plan.yaml");
  } catch (const InputError&) {
    return;
  }
  CheckGrids(plan);
}

}  // namespace dwellfit::fuzz
