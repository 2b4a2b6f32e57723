// convergence_family: fits every member of the convergence family
// (estimator/studies/convergence_family.h) from the automatic start and
// writes the Markdown report. Exits 1 unless at least 98 % of the members
// reach the truth and none reports convergence away from it.
#include <algorithm>
#include <iostream>
#include <string>
#include <vector>

#include "dwellfit/config/identify_config.h"
#include "dwellfit/estimator/common/input_error.h"
#include "dwellfit/estimator/common/memory_policy.h"
#include "dwellfit/estimator/run/output_files.h"
#include "dwellfit/estimator/studies/convergence_family.h"
#include "dwellfit/tools/tool_main.h"
#include "gflags/gflags.h"
#include "glog/logging.h"

DEFINE_string(base, "datasets/thesis-numerical/beam.yaml",
              "Config whose solver, stage, residual and penalty settings every member uses");
DEFINE_string(output, "docs/convergence-family.md", "Markdown file to write");

int main(int argc, char** argv) {
  const dwellfit::ToolSpec tool = {
      "convergence_family",
      "fits the convergence family from the automatic start and writes its report.\n"
      "  convergence_family [--base CFG --output FILE]",
      __FILE__};
  return dwellfit::RunTool(argc, argv, tool, [] {
    dwellfit::CheckOutputFile(FLAGS_output, "--output", {FLAGS_base});
    const dwellfit::IdentifyConfig base = dwellfit::LoadIdentifyConfig(FLAGS_base);
    std::vector<dwellfit::FamilyOutcome> outcomes;
    for (const dwellfit::FamilyMember& member : dwellfit::ConvergenceFamily()) {
      outcomes.push_back(dwellfit::RunFamilyMember(base, member));
    }
    dwellfit::WriteReportAtomically(FLAGS_output, dwellfit::ConvergenceFamilyMarkdown(outcomes));
    const auto reached = std::count_if(outcomes.begin(), outcomes.end(),
                                       [](const auto& o) { return o.ReachedTruth(); });
    const auto silent = std::count_if(outcomes.begin(), outcomes.end(),
                                      [](const auto& o) { return o.SilentlyWrong(); });
    std::cout << "wrote " << FLAGS_output << ": " << reached << " of " << outcomes.size()
              << " members reach the truth, " << silent << " silently wrong\n";
    return 100 * reached >= 98 * static_cast<long>(outcomes.size()) && silent == 0 ? 0 : 3;
  });
}
