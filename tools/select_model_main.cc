// select_model: compares model variants of a config (its `model_selection:`
// block, or the defaults) by their held-out jump frequencies, upper-branch
// amplitudes and the stability of their parameters over leave-one-level-out
// cross-validation (the rule: estimator/studies/model_selection.h), and
// names the recommended variant. Writes model_selection.csv,
// model_selection.md, model_selection_levels.csv (every held-out prediction
// with its 95 % interval) and recommended.yaml (the recommended variant's config,
// ready for `identify --config`) into <output_dir>/model_selection (all or
// nothing), and prints the Markdown.
//
// Exit codes: 0 a variant is recommended; 1 bad input (config, data, flags);
// 2 no variant qualifies (every variant has a fit that did not converge or
// failed): the tables are written all the same, to show why.
#include <iostream>
#include <string>
#include <utility>
#include <vector>

#include "dwellfit/config/identify_config.h"
#include "dwellfit/estimator/common/input_error.h"
#include "dwellfit/estimator/common/memory_policy.h"
#include "dwellfit/estimator/run/output_files.h"
#include "dwellfit/estimator/studies/model_selection.h"
#include "dwellfit/estimator/studies/study_pages.h"
#include "dwellfit/tools/tool_main.h"
#include "gflags/gflags.h"
#include "glog/logging.h"

DEFINE_string(config, "", "YAML config file (required), e.g. datasets/clamped-beam-27C/beam.yaml");
DEFINE_string(set, "",
              "Overrides any config value: key.path=value[,...], e.g. "
              "model_selection.training=all");
DEFINE_int32(threads, 0, "Fits run at once; overrides model_selection.threads when positive");
DEFINE_string(output_dir, "",
              "Directory for the two files (default: the config's output_dir/model_selection)");

int main(int argc, char** argv) {
  const dwellfit::ToolSpec tool = {
      "select_model",
      "compares model variants by cost, AIC, BIC and cross-validation.\n"
      "  select_model --config beam.yaml [--set k=v,...] [--threads N] [--output_dir DIR]",
      __FILE__};
  return dwellfit::RunTool(argc, argv, tool, [] {
    if (FLAGS_config.empty()) {
      std::cerr << "select_model: give the config file with --config FILE; see --help\n";
      return dwellfit::kToolExitUsage;
    }
    const dwellfit::IdentifyConfig config =
        dwellfit::LoadIdentifyConfig(FLAGS_config, dwellfit::ParseSetFlag(FLAGS_set, "--set"));
    const std::string directory =
        FLAGS_output_dir.empty() ? config.output_dir + "/model_selection" : FLAGS_output_dir;
    dwellfit::CheckOutputDirectory(directory,
                                   FLAGS_output_dir.empty() ? "output_dir" : "--output_dir");
    const dwellfit::ModelSelectionReport report =
        dwellfit::RunModelSelection(config, FLAGS_threads);
    const std::string markdown = dwellfit::ModelSelectionMarkdown(report);
    std::vector<std::pair<std::string, std::string>> files = {
        {"model_selection.csv", dwellfit::ModelSelectionCsv(report)},
        {"model_selection.md", markdown},
        {"model_selection_levels.csv", dwellfit::ModelSelectionLevelsCsv(report)},
        {"report.html", dwellfit::ModelSelectionToHtml(report, markdown)}};
    const std::string recommended = dwellfit::RecommendedConfigYaml(config, report);
    if (!recommended.empty()) files.push_back({"recommended.yaml", recommended});
    dwellfit::WriteFilesAtomically(directory, files);
    std::cout << markdown << "\nwrote " << directory
              << "/model_selection.{csv,md}, model_selection_levels.csv, report.html";
    if (!recommended.empty()) {
      std::cout << " and " << directory << "/recommended.yaml (run it: identify --config "
                << directory << "/recommended.yaml)";
    }
    std::cout << "\n";
    if (report.recommended < 0) {
      std::cerr << "select_model: " << report.verdict << "\n";
      return 3;
    }
    return 0;
  });
}
