// Every tool's main(): its command-line manners and its error policy, in one
// place (RunTool).
//
// Manners: `--help` prints the tool's usage and its own flags and exits 0
// (`--helpfull` every flag, glog's and gflags' included); `--version` prints
// dwellfit's version and those of the libraries it was built with, and exits
// 0; an unknown flag, a flag given twice, a flag value of the wrong type or a
// stray argument is a usage error (exit 2), with a did-you-mean for a
// misspelt flag.
//
// Error policy: the tool's body runs inside RunTool's handlers, so that no
// tool aborts on an exception. Bad input (InputError, naming file, line and
// field) exits 1; memory, threads, disk or file size running out exit 6 with
// what ran out; anything else is a defect of the tool and exits 7 with its
// text. A tool's own outcomes (a fit that did not converge, ...) are exit
// codes of its body, 3 to 5 (README, "Exit status").
//
// Each tool is one translation unit (tools/CMakeLists.txt), so these inline
// functions and tool_flags.h's flag are defined once per program.
#ifndef DWELLFIT_TOOLS_TOOL_MAIN_H_
#define DWELLFIT_TOOLS_TOOL_MAIN_H_

#include <algorithm>
#include <cerrno>
#include <csignal>
#include <cstring>
#include <filesystem>
#include <functional>
#include <iostream>
#include <new>
#include <optional>
#include <string>
#include <system_error>
#include <vector>

#include "dwellfit/config/strict_yaml.h"
#include "dwellfit/estimator/common/input_error.h"
#include "dwellfit/estimator/common/memory_policy.h"
#include "dwellfit/estimator/common/version.h"
#include "dwellfit/tools/tool_flags.h"
#include "gflags/gflags.h"
#include "glog/logging.h"

namespace dwellfit {

// Exit statuses every tool shares; identify's own are in
// estimator/run/identify_run.h.
inline constexpr int kToolExitInput = 1;     // bad input: a file, the config, a flag's value
inline constexpr int kToolExitUsage = 2;     // bad command line
inline constexpr int kToolExitResource = 6;  // memory, threads, disk or file size ran out
inline constexpr int kToolExitDefect = 7;    // an error the tool has no words for (a bug)

struct ToolSpec {
  const char* name;   // "identify"
  const char* usage;  // what it does, then its synopsis
  const char* file;   // __FILE__ of its main: --help lists the flags defined there
};

// True for the flags a tool lists in --help: those of its main file and of
// tool_flags.h.
inline bool OwnFlag(const gflags::CommandLineFlagInfo& flag, const ToolSpec& tool) {
  const auto base = [](const std::string& path) {
    return std::filesystem::path(path).filename().string();
  };
  const std::string file = base(flag.filename);
  return file == base(tool.file) || file == "tool_flags.h";
}

// " (did you mean 'figures'?)" for a misspelt "figure": the tool's own flag
// nearest to `name` (DidYouMean); empty when none is near.
inline std::string NearestFlag(const std::string& name, const ToolSpec& tool) {
  std::vector<gflags::CommandLineFlagInfo> flags;
  gflags::GetAllFlags(&flags);
  std::vector<std::string> names;
  for (const gflags::CommandLineFlagInfo& flag : flags) {
    if (OwnFlag(flag, tool)) names.push_back(flag.name);
  }
  return DidYouMean(name, names);
}

// What is wrong with the command line `args` (argv without the program), in
// words; none when gflags can parse it as given. Sets each flag it meets
// (gflags' parse later sets the same values again). A flag is `-name` or
// `--name`, with `=value` or (not for a bool) the value as the next argument;
// `--noname` is a bool's false; nothing after `--` is a flag.
inline std::optional<std::string> CommandLineProblem(const std::vector<std::string>& args,
                                                     const ToolSpec& tool) {
  std::vector<std::string> seen;
  for (std::size_t i = 0; i < args.size(); ++i) {
    const std::string& arg = args[i];
    if (arg == "--") break;
    if (arg.size() < 2 || arg[0] != '-') {
      return "unexpected argument '" + EscapeForMessage(arg) + "'";
    }
    const std::string body = arg.substr(arg[1] == '-' ? 2 : 1);
    const std::string::size_type equals = body.find('=');
    std::string name = body.substr(0, equals);
    std::optional<std::string> value;
    if (equals != std::string::npos) value = body.substr(equals + 1);
    gflags::CommandLineFlagInfo info;
    if (!gflags::GetCommandLineFlagInfo(name.c_str(), &info) && name.rfind("no", 0) == 0 &&
        gflags::GetCommandLineFlagInfo(name.substr(2).c_str(), &info) && info.type == "bool" &&
        !value) {
      name = name.substr(2);
      value = "false";
    }
    if (info.name != name) return "unknown flag --" + name + NearestFlag(name, tool);
    if (std::find(seen.begin(), seen.end(), name) != seen.end()) {
      return "--" + name + " is given more than once, and only its last value would count; " +
             "give it once" +
             (name == "set" ? " (several overrides in one --set: --set a=1,b=2)" : "");
    }
    seen.push_back(name);
    if (!value && info.type == "bool") value = "true";
    if (!value && ++i == args.size()) return "--" + name + " needs a value";
    if (!value) value = args[i];
    // gflags reads numbers with strtod/strtol, which take "0x28" and "inf".
    const bool numeric = info.type == "double" || info.type.find("int") != std::string::npos;
    if (numeric && value->find_first_not_of("0123456789+-.eE") != std::string::npos) {
      return "--" + name + " '" + EscapeForMessage(*value) + "' is not a decimal number";
    }
    if (gflags::SetCommandLineOption(name.c_str(), value->c_str()).empty()) {
      return "--" + name + " '" + EscapeForMessage(*value) + "' is not a valid " + info.type +
             " value";
    }
  }
  return std::nullopt;
}

// True when the paths `a` and `b` name one file (whether it exists or not);
// false when either cannot be resolved.
inline bool SameFile(const std::string& a, const std::string& b) {
  std::error_code error_a, error_b;
  const std::filesystem::path resolved_a = std::filesystem::weakly_canonical(a, error_a);
  const std::filesystem::path resolved_b = std::filesystem::weakly_canonical(b, error_b);
  return !error_a && !error_b && resolved_a == resolved_b;
}

// Throws InputError (naming `flag`) before a run's work when the output file
// `path` is a folder or one of the run's `inputs`.
inline void CheckOutputFile(const std::string& path, const std::string& flag,
                            const std::vector<std::string>& inputs) {
  std::error_code error;
  if (std::filesystem::is_directory(path, error)) {
    throw InputError(path, 0, flag, "is a folder; give a file name");
  }
  for (const std::string& input : inputs) {
    if (!input.empty() && SameFile(input, path)) {
      throw InputError(path, 0, flag, "is an input of this run; give another file");
    }
  }
}

// --help: the usage, then the tool's own flags with their defaults.
inline void PrintToolHelp(const ToolSpec& tool) {
  std::cout << tool.name << ": " << tool.usage << "\n\nFlags:\n";
  std::vector<gflags::CommandLineFlagInfo> flags;
  gflags::GetAllFlags(&flags);
  // The tool's own flags first, then --verbose (tool_flags.h).
  std::stable_partition(flags.begin(), flags.end(), [&tool](const auto& flag) {
    return OwnFlag(flag, tool) && flag.filename.find("tool_flags.h") == std::string::npos;
  });
  for (const gflags::CommandLineFlagInfo& flag : flags) {
    if (!OwnFlag(flag, tool)) continue;
    std::cout << "  --" << flag.name << " (" << flag.type << ", default '" << flag.default_value
              << "')\n      " << flag.description << "\n";
  }
  std::cout << "  --help, --helpfull (every flag, glog's included), --version\n";
}

// --version: dwellfit's and its libraries' versions (as built).
inline void PrintToolVersion(const ToolSpec& tool) {
  std::cout << "dwellfit " << DwellfitVersion() << " (" << tool.name << ")\nbuilt with "
            << DWELLFIT_DEPENDENCY_VERSIONS << "\n";
}

// True when a gflags bool flag such as "help" is set.
inline bool BoolFlagSet(const char* name) {
  std::string value;
  return gflags::GetCommandLineOption(name, &value) && value == "true";
}

// Parses the command line: -1 to go on, else the exit status (help and
// version printed, or a usage error said).
inline int ParseToolCommandLine(int* argc, char*** argv, const ToolSpec& tool) {
  QuietLibraryLogging(tool.name);
  const std::vector<std::string> args(*argv + 1, *argv + *argc);
  if (const auto problem = CommandLineProblem(args, tool)) {
    std::cerr << tool.name << ": " << *problem << " (see --help)\n";
    return kToolExitUsage;
  }
  gflags::ParseCommandLineNonHelpFlags(argc, argv, /*remove_flags=*/true);
  if (BoolFlagSet("help")) return PrintToolHelp(tool), 0;
  if (BoolFlagSet("version")) return PrintToolVersion(tool), 0;
  if (BoolFlagSet("helpfull")) return gflags::ShowUsageWithFlags((*argv)[0]), 0;
  gflags::HandleCommandLineHelpFlags();  // --helpshort, --helpmatch=S, ...: print and exit
  return -1;
}

// Runs a tool: parses its command line (ParseToolCommandLine), then `body`
// under the error policy at the top of this file. Returns the exit status.
inline int RunTool(int argc, char** argv, const ToolSpec& tool, const std::function<int()>& body) {
  // A file size limit (ulimit -f) stops a write with EFBIG, reported as an
  // I/O error, rather than killing the process with SIGXFSZ.
  std::signal(SIGXFSZ, SIG_IGN);
  KeepFreedMemoryForReuse();
  google::InitGoogleLogging(argv[0]);
  gflags::SetUsageMessage(tool.usage);
  const auto say = [&tool](const std::string& text) {
    std::cerr << tool.name << ": " << text << "\n";
  };
  try {
    const int parsed = ParseToolCommandLine(&argc, &argv, tool);
    return parsed >= 0 ? parsed : body();
  } catch (const InputError& error) {
    say(error.what());
    return kToolExitInput;
  } catch (const std::bad_alloc&) {
    say("out of memory: the run needs more than this process may allocate (ulimit -v, or the "
        "machine's memory); give it a smaller input, study or thread count");
    return kToolExitResource;
  } catch (const std::system_error& error) {  // I/O (std::ios_base::failure), threads, files
    say(std::string("the system refused: ") + error.what() + " (" + error.code().message() +
        "); check the disk space, the file size limit and the thread limit");
    return kToolExitResource;
  } catch (const std::exception& error) {
    say(std::string("internal error: ") + error.what() +
        "; this is a defect of dwellfit: please report it with the command line");
    return kToolExitDefect;
  }
}

}  // namespace dwellfit

#endif  // DWELLFIT_TOOLS_TOOL_MAIN_H_
