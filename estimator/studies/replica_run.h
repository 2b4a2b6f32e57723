// One noisy replica of a dwell plan (relative noise sigma, seed) resolved as
// a measured run (resolved_run.h), for the coverage and sensitivity studies.
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
