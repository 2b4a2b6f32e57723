// Reading a DwellPlan (estimator/simulation/dwell_simulator.h) from YAML.
//
//   truth:                  # all six required
//     eta_e: 100            # forcing effectiveness
//     mu1: 0.2              # linear damping [1/s]
//     mu2: 300              # quadratic damping
//     delta: 1.0e4          # nonlinear inertia
//     alpha: 9.0e8          # cubic stiffness
//     omega_hz: 40          # linear natural frequency w [Hz] (rad/s inside)
//   sweeps:                 # one or more; ids unique
//     - id: F0.01
//       kind: frequency     # drive frequency stepped, a_base held
//       a_base: 0.01
//       from_hz: 38
//       to_hz: 46
//       step_hz: 0.1
//       directions: [up, down]   # optional, default [up, down]
//       start: lower             # optional: lower (default, from rest) or upper
//     - id: A41.5
//       kind: amplitude     # a_base stepped, drive frequency held
//       freq_hz: 41.5
//       a_base_from: 0.002
//       a_base_to: 0.05
//       a_base_step: 0.001
//   noise:                  # optional; default none
//     relative_sigma: 0.01  # a *= 1 + relative_sigma N(0, 1)
//     seed: 7               # std::mt19937_64 seed, a non-negative integer
//   model:                  # optional; the response model the dwells follow
//     averaging: first_order   # (default) or second_order (model_form.h)
//
// Keys are strict, as in identify's config (config/strict_yaml.h): an
// unknown, misplaced or repeated key is an error, as is a value that does not
// make a sweep (see SweepPlan::IsValid). Errors name the file, the 1-based
// line and the key path (`sweeps[0].a_base`).
#ifndef DWELLFIT_CONFIG_DWELL_PLAN_READER_H_
#define DWELLFIT_CONFIG_DWELL_PLAN_READER_H_

#include <string>

#include "dwellfit/config/config_source.h"
#include "dwellfit/config/strict_yaml.h"
#include "dwellfit/estimator/simulation/dwell_simulator.h"

namespace dwellfit {

// The `model: {averaging: first_order | second_order, damping: quadratic |
// cubic, backbone: inertia | quintic}` block of a plan and of identify's
// config (ModelForm); an unknown name is an error at its line listing the
// choices, and the second order with a family term is refused.
ModelForm ReadModelForm(const ConfigValue& value, const ConfigSource& source);

// Parses the YAML text of a plan; `source` names it in errors (a file path).
// Throws InputError with source, line and field for any bad content.
DwellPlan ParseDwellPlan(const std::string& yaml_text, const std::string& source);

// Reads and parses the plan file `path`. Throws InputError.
DwellPlan ReadDwellPlan(const std::string& path);

}  // namespace dwellfit

#endif  // DWELLFIT_CONFIG_DWELL_PLAN_READER_H_
