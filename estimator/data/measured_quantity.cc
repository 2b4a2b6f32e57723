#include "dwellfit/estimator/data/measured_quantity.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <string>

#include "dwellfit/estimator/common/input_error.h"
#include "dwellfit/estimator/common/name_table.h"
#include "dwellfit/residuals/model/response_model.h"

namespace dwellfit {
namespace {

// The measured quantity's lag minus the displacement's: -p pi/2.
double ResponseLead(const TestQuantities& test) { return 0.5 * kPi * test.ResponsePower(); }

// Names in enumerator order.
constexpr const char* kExcitationNames[] = {"base_acceleration", "base_displacement", "force"};
constexpr const char* kResponseNames[] = {"displacement", "velocity", "acceleration"};

}  // namespace

const char* ExcitationName(Excitation excitation) { return NameOf(kExcitationNames, excitation); }

bool ExcitationFromName(const std::string& name, Excitation* excitation) {
  return FromName(name, kExcitationNames, excitation);
}

const char* ResponseName(Response response) { return NameOf(kResponseNames, response); }

bool ResponseFromName(const std::string& name, Response* response) {
  return FromName(name, kResponseNames, response);
}

int TestQuantities::ResponsePower() const {
  return response == Response::kDisplacement ? 0 : response == Response::kVelocity ? 1 : 2;
}

int TestQuantities::LevelPower() const {
  return excitation == Excitation::kBaseDisplacement ? 2 : 0;
}

std::optional<double> EstimatePhaseOffset(const TestQuantities& test,
                                          const std::vector<const Sweep*>& sweeps) {
  const int p = test.ResponsePower();
  // Per sweep id (both directions), the dwell of the largest displacement.
  std::map<std::string, const DwellPoint*> peaks;
  for (const Sweep* sweep : sweeps) {
    if (sweep->kind != SweepKind::kFrequency) continue;
    for (const DwellPoint& point : sweep->points) {
      const DwellPoint*& peak = peaks[sweep->id];
      const auto displacement = [p](const DwellPoint& x) {
        return x.amplitude / OmegaPower(x.drive_frequency_rad_s, p);
      };
      if (peak == nullptr || displacement(point) > displacement(*peak)) peak = &point;
    }
  }
  std::vector<double> offsets;
  for (const auto& [id, peak] : peaks) {
    if (!peak->phase_rad) continue;
    // Wrapped into [-pi, pi]: the offset of one sweep, whatever 2 pi the file adds.
    offsets.push_back(
        std::remainder(*peak->phase_rad - (0.5 * kPi - ResponseLead(test)), 2.0 * kPi));
  }
  if (offsets.empty()) return std::nullopt;
  std::nth_element(offsets.begin(), offsets.begin() + offsets.size() / 2, offsets.end());
  return offsets[offsets.size() / 2];
}

void ToModelForm(const TestQuantities& test, double phase_offset_rad, Sweep* sweep) {
  if (test.IsModelForm() && phase_offset_rad == 0.0) return;
  if (test.LevelPower() != 0 && sweep->kind == SweepKind::kFrequency && sweep->points.size() > 1) {
    throw InputError(
        sweep->source_file, sweep->points.front().source_line, "a_base",
        "sweep '" + sweep->Name() +
            "' is a frequency sweep driven by base displacement: its base acceleration "
            "Omega^2 a_base changes along the sweep, and the model's folds and curves hold "
            "the level fixed. With excitation: base_displacement fit amplitude sweeps (each at one "
            "frequency); frequency sweeps at a held displacement are not supported");
  }
  QuantityMap(test, phase_offset_rad, /*to_model=*/true).Apply(sweep);
}

QuantityMap::QuantityMap(const TestQuantities& test, double phase_offset_rad, bool to_model)
    : p_(test.ResponsePower()),
      q_(test.LevelPower()),
      to_model_(to_model),
      phase_shift_rad_(to_model ? ResponseLead(test) - phase_offset_rad
                                : phase_offset_rad - ResponseLead(test)) {}

double QuantityMap::Amplitude(double value, double omega_rad_s) const {
  return to_model_ ? value / OmegaPower(omega_rad_s, p_) : value * OmegaPower(omega_rad_s, p_);
}

double QuantityMap::Level(double value, double omega_rad_s) const {
  return to_model_ ? value * OmegaPower(omega_rad_s, q_) : value / OmegaPower(omega_rad_s, q_);
}

double QuantityMap::Phase(double rad) const { return rad + phase_shift_rad_; }

void QuantityMap::Apply(SweepKind kind, double held_omega_rad_s, JumpBracket* jump) const {
  const bool frequency = kind == SweepKind::kFrequency;
  jump->amplitude_before =
      Amplitude(jump->amplitude_before, frequency ? jump->control_before : held_omega_rad_s);
  jump->amplitude_after =
      Amplitude(jump->amplitude_after, frequency ? jump->control_after : held_omega_rad_s);
  if (!frequency) {
    jump->control_before = Level(jump->control_before, held_omega_rad_s);
    jump->control_after = Level(jump->control_after, held_omega_rad_s);
  }
}

void QuantityMap::Apply(Sweep* sweep) const {
  for (DwellPoint& point : sweep->points) {
    const double omega = point.drive_frequency_rad_s;
    point.amplitude = Amplitude(point.amplitude, omega);
    if (point.sigma) point.sigma = Amplitude(*point.sigma, omega);
    point.a_base = Level(point.a_base, omega);
    if (point.a_base_sigma) point.a_base_sigma = Level(*point.a_base_sigma, omega);
    if (point.phase_rad) point.phase_rad = Phase(*point.phase_rad);
  }
  for (MissingDwell& row : sweep->missing)
    row.a_base = Level(row.a_base, row.drive_frequency_rad_s);
  if (sweep->points.empty()) return;  // no dwell, so no jump
  const double held_omega = sweep->points.front().drive_frequency_rad_s;
  for (JumpBracket& jump : sweep->jumps) Apply(sweep->kind, held_omega, &jump);
}

}  // namespace dwellfit
