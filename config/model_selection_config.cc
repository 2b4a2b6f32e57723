#include "dwellfit/config/model_selection_config.h"

#include <algorithm>
#include <cmath>

#include "dwellfit/config/strict_yaml.h"
#include "dwellfit/estimator/common/string_printf.h"

namespace dwellfit {
namespace {

// The names of the enum values, in the enums' order.
constexpr const char* kSchemeNames[] = {"none", "leave_one_level_out"};
constexpr const char* kTrainingNames[] = {"config", "all"};

// A non-empty list of a member's terms, each once (`name` gives the
// config's spelling of a term).
template <typename Term>
std::vector<Term> ReadTerms(const ConfigValue& value, const ConfigSource& source, const char* what,
                            const std::vector<Term>& all, const char* (*name)(Term)) {
  std::vector<std::string> allowed;
  for (Term term : all) allowed.push_back(name(term));
  std::vector<Term> terms;
  for (const ConfigValue& entry : ReadList(value, source)) {
    const std::string text = ReadOneOf(entry, source, what, allowed);
    const Term term = all[std::find(allowed.begin(), allowed.end(), text) - allowed.begin()];
    if (std::find(terms.begin(), terms.end(), term) != terms.end()) {
      throw source.Error(entry.path, entry.mark,
                         std::string(what) + " lists '" + text + "' twice; keep one");
    }
    terms.push_back(term);
  }
  if (terms.empty()) {
    throw source.Error(value.path, value.mark,
                       std::string(what) + " lists no term; give one or more of " +
                           allowed.front() + ", " + allowed.back());
  }
  return terms;
}

// One list of choices: entries `free`, `initial` (the config's initial
// guess, which must be given) or a number (omega in Hz).
std::vector<ParameterChoice> ReadChoices(const ConfigValue& value, const ConfigSource& source,
                                         ParameterIndex index,
                                         const KnownParameters& initial_guess) {
  const bool omega = index == kNaturalFrequency;
  std::vector<ParameterChoice> choices;
  for (const ConfigValue& entry : ReadList(value, source)) {
    const std::string text = entry.node.IsScalar() ? entry.node.Scalar() : "";
    ParameterChoice choice;
    if (text == "free") {
      choice.text = "free";
    } else if (text == "initial") {
      if (!initial_guess[index]) {
        const std::string key = omega ? "omega_hz" : ParameterName(index);
        throw source.Error(entry.path, entry.mark,
                           "'initial' holds " + std::string(ParameterName(index)) +
                               " at the config's initial guess, but initial_guess." + key +
                               " is auto; give it, or write the value here");
      }
      choice.value = *initial_guess[index];
      const double shown = omega ? RadPerSecondToHz(*choice.value) : *choice.value;
      choice.text = StringPrintf("%.6g", shown);
    } else {
      const double number = ReadFiniteDouble(entry, source);
      choice.value = omega ? HzToRadPerSecond(number) : number;
      if (!std::isfinite(*choice.value)) {
        throw source.Error(entry.path, entry.mark, "the frequency is too large");
      }
      choice.text = text;
    }
    choices.push_back(choice);
  }
  return choices;
}

// The enum value `value` names, one of `names` (in the enum's order).
template <typename Enum, std::size_t N>
Enum ReadEnum(const ConfigValue& value, const ConfigSource& source, const std::string& what,
              const char* const (&names)[N]) {
  const std::vector<std::string> allowed(names, names + N);
  const std::string name = ReadOneOf(value, source, what, allowed);
  return static_cast<Enum>(std::find(allowed.begin(), allowed.end(), name) - allowed.begin());
}

std::vector<SweepSelection> ReadPool(const ConfigValue& value, const ConfigSource& source) {
  std::vector<SweepSelection> pool;
  for (const ConfigValue& entry : ReadList(value, source)) {
    SweepSelection selection;
    std::string error;
    if (!ParseSweepSelection(ReadNonEmptyString(entry, source), &selection, &error)) {
      throw source.Error(entry.path, entry.mark, error);
    }
    for (const SweepSelection& earlier : pool) {
      if (earlier.Overlaps(selection)) {
        throw source.Error(entry.path, entry.mark,
                           "sweep '" + selection.Name() + "' overlaps '" + earlier.Name() +
                               "' listed before; list each sweep once");
      }
    }
    pool.push_back(selection);
  }
  if (pool.empty()) {
    throw source.Error(value.path, value.mark,
                       "the pool is empty; list the sweeps to cross-validate over, or leave "
                       "`pool` out for the config's fitted and validation sweeps");
  }
  return pool;
}

}  // namespace

const char* CrossValidationSchemeName(CrossValidationScheme scheme) {
  return kSchemeNames[static_cast<int>(scheme)];
}

const char* CrossValidationTrainingName(CrossValidationTraining training) {
  return kTrainingNames[static_cast<int>(training)];
}

bool ModelSelectionConfig::IsValid(std::string* error) const {
  const struct {
    const char* name;
    const std::vector<ParameterChoice>* choices;
  } lists[] = {{"delta", &delta}, {"mu2", &mu2}, {"omega_hz", &omega}};
  for (const auto& list : lists) {
    if (list.choices->empty()) {
      *error = std::string(list.name) + " lists no choice; give free and/or values";
      return false;
    }
    for (std::size_t i = 0; i < list.choices->size(); ++i) {
      for (std::size_t j = 0; j < i; ++j) {
        if ((*list.choices)[i].value == (*list.choices)[j].value) {
          *error = std::string(list.name) + " lists '" + (*list.choices)[i].text + "' twice";
          return false;
        }
      }
    }
  }
  for (const ParameterChoice& choice : omega) {
    if (choice.value && !(*choice.value > 0.0)) {
      *error = "omega_hz: a fixed natural frequency must be positive, got " + choice.text;
      return false;
    }
  }
  for (const ParameterChoice& choice : mu2) {
    if (choice.value && *choice.value < 0.0) {
      *error = "mu2: a fixed value must be >= 0 (the parameter is bounded below by 0), got " +
               choice.text;
      return false;
    }
  }
  if (threads < 1) {
    *error = "threads must be >= 1, got " + std::to_string(threads);
    return false;
  }
  return true;
}

ModelSelectionConfig ReadModelSelectionConfig(const ConfigValue& value, const ConfigSource& source,
                                              const KnownParameters& initial_guess) {
  const StrictMap block(value, source,
                        {"backbone", "damping", "delta", "mu2", "omega_hz", "cross_validation",
                         "training", "pool", "threads"});
  ModelSelectionConfig config;
  if (const auto v = block.Optional("backbone")) {
    config.backbone = ReadTerms<BackboneTerm>(
        *v, source, "backbone", {BackboneTerm::kInertia, BackboneTerm::kQuintic}, BackboneTermName);
  }
  if (const auto v = block.Optional("damping")) {
    config.damping = ReadTerms<DampingTerm>(
        *v, source, "damping", {DampingTerm::kQuadratic, DampingTerm::kCubic}, DampingTermName);
  }
  if (const auto v = block.Optional("delta")) {
    config.delta = ReadChoices(*v, source, kDelta, initial_guess);
  }
  if (const auto v = block.Optional("mu2"))
    config.mu2 = ReadChoices(*v, source, kMu2, initial_guess);
  if (const auto v = block.Optional("omega_hz")) {
    config.omega = ReadChoices(*v, source, kNaturalFrequency, initial_guess);
  }
  if (const auto v = block.Optional("cross_validation")) {
    config.scheme =
        ReadEnum<CrossValidationScheme>(*v, source, "cross-validation scheme", kSchemeNames);
  }
  if (const auto v = block.Optional("training")) {
    config.training = ReadEnum<CrossValidationTraining>(*v, source, "training set", kTrainingNames);
  }
  if (const auto v = block.Optional("pool")) config.pool = ReadPool(*v, source);
  if (const auto v = block.Optional("threads")) config.threads = ReadInt(*v, source);
  std::string message;
  if (!config.IsValid(&message)) throw source.Error(value.path, value.mark, message);
  return config;
}

}  // namespace dwellfit
