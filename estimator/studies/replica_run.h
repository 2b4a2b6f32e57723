// One noisy replica of a dwell plan resolved as a measured run: the plan
// simulated with relative noise sigma and a seed, then labelled, the
// config's jumps applied, its sweeps selected and the start found from the
// replica's data (resolved_run.h). The coverage and sensitivity studies
// both fit replicas made here.
#ifndef DWELLFIT_ESTIMATOR_STUDIES_REPLICA_RUN_H_
#define DWELLFIT_ESTIMATOR_STUDIES_REPLICA_RUN_H_

#include <cstdint>

#include "dwellfit/config/identify_config.h"
#include "dwellfit/estimator/run/resolved_run.h"
#include "dwellfit/estimator/simulation/dwell_simulator.h"

namespace dwellfit {

// Throws InputError as ResolveRun does.
inline ResolvedRun ResolveReplicaRun(const IdentifyConfig& config, const DwellPlan& plan,
                                     double relative_noise, std::uint64_t seed) {
  DwellPlan replica = plan;
  replica.noise.relative_sigma = relative_noise;
  replica.noise.seed = seed;
  return ResolveRun(config, SimulateDwells(replica));
}

}  // namespace dwellfit

#endif  // DWELLFIT_ESTIMATOR_STUDIES_REPLICA_RUN_H_
