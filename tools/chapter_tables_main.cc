// chapter_tables: writes the with/without-penalty comparison of the chapter's
// Tables 3.3 (numerical data against its truth) and 3.4 (measured data, with
// predicted against measured jump frequencies) as Markdown.
#include <iostream>
#include <string>

#include "dwellfit/config/dwell_plan_reader.h"
#include "dwellfit/config/identify_config.h"
#include "dwellfit/estimator/common/input_error.h"
#include "dwellfit/estimator/common/memory_policy.h"
#include "dwellfit/estimator/run/output_files.h"
#include "dwellfit/estimator/studies/chapter_tables.h"
#include "dwellfit/tools/tool_main.h"
#include "gflags/gflags.h"
#include "glog/logging.h"

DEFINE_string(numerical, "datasets/thesis-numerical/beam.yaml",
              "Config on simulated data (Table 3.3)");
DEFINE_string(truth_plan, "datasets/thesis-numerical/plan.yaml",
              "Dwell plan the numerical data were simulated from: its truth");
DEFINE_string(measured, "datasets/clamped-beam-27C/beam.yaml",
              "Config on measured data (Table 3.4)");
DEFINE_string(output, "docs/chapter-tables.md", "Markdown file to write");

int main(int argc, char** argv) {
  const dwellfit::ToolSpec tool = {
      "chapter_tables",
      "writes the chapter's Tables 3.3 and 3.4 (with and without the bifurcation-range "
      "penalty) as Markdown.\n  chapter_tables [--numerical CFG --truth_plan PLAN --measured CFG "
      "--output FILE]",
      __FILE__};
  return dwellfit::RunTool(argc, argv, tool, [] {
    dwellfit::CheckOutputFile(FLAGS_output, "--output",
                              {FLAGS_numerical, FLAGS_truth_plan, FLAGS_measured});
    const std::string markdown =
        dwellfit::ChapterTablesMarkdown(dwellfit::LoadIdentifyConfig(FLAGS_numerical),
                                        dwellfit::ReadDwellPlan(FLAGS_truth_plan).truth,
                                        dwellfit::LoadIdentifyConfig(FLAGS_measured));
    dwellfit::WriteReportAtomically(FLAGS_output, markdown);
    std::cout << "wrote " << FLAGS_output << "\n";
    return 0;
  });
}
