// Many fits of one config, varying what the flags say
// (estimator/studies/sensitivity_study.h, docs/sensitivity.md).
//
//   sensitivity --config beam.yaml --plan plan.yaml --replicas 1000 --noise 0.01 \
//               --threads 2 --output_dir study/
//   sensitivity --config beam.yaml --vary 'penalties.bifurcation_range.exponent=2|4|10' ...
//   sensitivity ... --shard 0/4 --output_dir study/shard0   (and 1/4, 2/4, 3/4)
//   sensitivity --merge study/shard0,study/shard1,study/shard2,study/shard3 --output_dir study/
#include <unistd.h>

#include <algorithm>
#include <iostream>
#include <sstream>
#include <thread>

#include "dwellfit/config/config_override.h"
#include "dwellfit/config/dwell_plan_reader.h"
#include "dwellfit/estimator/common/input_error.h"
#include "dwellfit/estimator/common/memory_policy.h"
#include "dwellfit/estimator/run/output_files.h"
#include "dwellfit/estimator/studies/sensitivity_study.h"
#include "dwellfit/tools/tool_main.h"
#include "gflags/gflags.h"
#include "glog/logging.h"

DEFINE_string(config, "", "identify config YAML (required unless --merge).");
DEFINE_string(plan, "",
              "dwell plan YAML: replicas simulate it with --noise (else: the config's data).");
DEFINE_int32(replicas, 1, "noisy replicas per case (needs --plan).");
DEFINE_double(noise, 0.01, "relative noise sigma of the replicas: a *= 1 + noise N(0, 1).");
DEFINE_uint64(first_seed, 1, "seed of replica 0; replica r uses first_seed + r.");
DEFINE_string(vary, "",
              "axes 'key=v1|v2|...;key2=...' of config keys (as --set takes them); "
              "the cases are their Cartesian product.");
DEFINE_string(set, "", "config overrides for every case, as identify's --set.");
DEFINE_int32(threads, 0, "fits run at once (0: one per processor).");
DEFINE_string(shard, "", "k/N: run only the fits i with i % N == k.");
DEFINE_string(merge, "", "comma-separated shard folders to join into --output_dir.");
DEFINE_bool(standard_errors, true, "compute standard errors (ceres::Covariance) of every fit.");
DEFINE_bool(figures, true, "draw histogram (and profile) figures with gnuplot.");
DEFINE_string(output_dir, "", "folder for fits.csv, summary.yaml, study.yaml, figures (required).");

namespace {

void ParseShard(const std::string& text, dwellfit::SensitivityOptions* options) {
  if (text.empty()) return;
  int k = -1, n = 0;
  char slash = 0;
  std::istringstream in(text);
  if (!(in >> k >> slash >> n) || slash != '/' || !in.eof()) {
    throw dwellfit::InputError("--shard", 0, "", "'" + text + "' is not k/N, e.g. 0/4");
  }
  options->shard = k;
  options->shards = n;
}

dwellfit::SensitivityStudy Run() {
  using namespace dwellfit;
  if (!FLAGS_merge.empty()) {
    std::vector<std::string> folders;
    std::stringstream list(FLAGS_merge);
    for (std::string folder; std::getline(list, folder, ',');) folders.push_back(folder);
    return MergeShards(folders);
  }
  if (FLAGS_config.empty()) throw InputError("--config", 0, "", "give --config (or --merge)");
  SensitivityOptions options;
  options.config_path = FLAGS_config;
  options.overrides = ParseSetFlag(FLAGS_set, "--set");
  options.vary = ParseVaryFlag(FLAGS_vary, "--vary");
  if (!FLAGS_plan.empty()) options.plan = ReadDwellPlan(FLAGS_plan);
  options.replicas = FLAGS_replicas;
  options.noise = FLAGS_noise;
  options.first_seed = FLAGS_first_seed;
  options.threads =
      FLAGS_threads > 0 ? FLAGS_threads : std::max(1u, std::thread::hardware_concurrency());
  options.standard_errors = FLAGS_standard_errors;
  ParseShard(FLAGS_shard, &options);
  return RunSensitivityStudy(options, MakeProgressPrinter(std::cerr, isatty(STDERR_FILENO)));
}

}  // namespace

int main(int argc, char** argv) {
  const dwellfit::ToolSpec tool = {
      "sensitivity",
      "Many fits of one config varying noise, replicas, starts, penalties, fixed values, fixed "
      "sets or fitted sweeps.\nUsage: sensitivity --config beam.yaml [--plan plan.yaml "
      "--replicas 1000 --noise 0.01] [--vary 'key=v1|v2'] [--threads 2] [--shard k/N] "
      "--output_dir study/\n       sensitivity --merge dir0,dir1,... --output_dir study/",
      __FILE__};
  return dwellfit::RunTool(argc, argv, tool, [] {
    if (FLAGS_output_dir.empty()) throw dwellfit::InputError("--output_dir", 0, "", "required");
    dwellfit::CheckOutputDirectory(FLAGS_output_dir, "--output_dir");
    const dwellfit::SensitivityStudy study = Run();
    const bool whole = study.shards == 1;
    dwellfit::WriteFilesAtomically(FLAGS_output_dir,
                                   dwellfit::StudyFiles(study, whole && FLAGS_figures, std::cerr));
    int usable = 0;
    for (const dwellfit::FitRow& row : study.rows)
      usable += row.status == "converged" || row.status == "no_convergence";
    std::cout << study.rows.size() << " fits (" << usable << " usable) in " << study.seconds
              << " s; wrote " << FLAGS_output_dir << "/fits.csv, summary.yaml, study.yaml\n";
    if (usable == 0) {
      std::cerr << "sensitivity: no fit is usable; see the status column of fits.csv\n";
      return 3;
    }
    return 0;
  });
}
