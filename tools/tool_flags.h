// How every tool's main() parses its command line: gflags, after refusing a
// flag given twice. gflags keeps the last value of a repeated flag without a
// word, so `identify --set a=1 --set b=2` would run without a=1
// (config/config_override.h, RepeatedFlag).
#ifndef DWELLFIT_TOOLS_TOOL_FLAGS_H_
#define DWELLFIT_TOOLS_TOOL_FLAGS_H_

#include <iostream>
#include <string>
#include <vector>

#include "dwellfit/config/config_override.h"
#include "gflags/gflags.h"

namespace dwellfit {

// False, after a message on stderr naming the flag, when argv gives one of
// the tool's flags more than once.
inline bool FlagsGivenOnce(int argc, char** argv, const char* tool) {
  const auto kind = [](const std::string& name) {
    gflags::CommandLineFlagInfo info;
    if (!gflags::GetCommandLineFlagInfo(name.c_str(), &info)) return FlagKind::kUnknown;
    return info.type == "bool" ? FlagKind::kBool : FlagKind::kValue;
  };
  const auto repeated = RepeatedFlag(std::vector<std::string>(argv + 1, argv + argc), kind);
  if (!repeated) return true;
  std::cerr << tool << ": --" << *repeated
            << " is given more than once, and only its last value would count; give it once"
            << (*repeated == "set" ? " (several overrides in one --set: --set a=1,b=2)" : "")
            << "\n";
  return false;
}

// Parses the tool's flags with gflags (removing them from argv), after
// FlagsGivenOnce: false, having said why, when a flag is given twice; the
// tool then exits with its usage status.
inline bool ParseToolFlags(int* argc, char*** argv, const char* tool) {
  if (!FlagsGivenOnce(*argc, *argv, tool)) return false;
  gflags::ParseCommandLineFlags(argc, argv, /*remove_flags=*/true);
  return true;
}

}  // namespace dwellfit

#endif  // DWELLFIT_TOOLS_TOOL_FLAGS_H_
