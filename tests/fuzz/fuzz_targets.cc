#include "tests/fuzz/fuzz_targets.h"

#include <glog/logging.h>

namespace dwellfit::fuzz {

const std::vector<FuzzTarget>& AllFuzzTargets() {
  static const std::vector<FuzzTarget> targets = {
      {"sweep_csv", &SweepCsvBody, ".csv"},
      {"identify_config", &IdentifyConfigBody, ".yaml"},
      {"set_flag", &SetFlagBody, ""},
      {"dwell_plan", &DwellPlanBody, ".yaml"},
      {"trace_set", &TraceSetBody, ""},
      {"rig_config", &RigConfigBody, ".yaml"},
      {"result_parameters", &ResultParametersBody, ""},
      {"shard_merge", &ShardMergeBody, ""},
      {"uff58", &Uff58Body, ""},
      {"mat_sweeps", &MatSweepsBody, ""},
  };
  return targets;
}

void QuietLogging() { FLAGS_minloglevel = google::GLOG_ERROR; }

}  // namespace dwellfit::fuzz
