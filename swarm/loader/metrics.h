// Swarm-level metrics computed in the record phase (Observers).
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "framework/world.h"

namespace swarmsim {

struct SwarmMetricSpec {
  std::string name;     // e.g. "mean_nearest_neighbor_distance"
  int every_steps = 1;  // record every N steps
};

// Names of the built-in swarm metrics, with a one-line description each.
std::vector<std::pair<std::string, std::string>> KnownSwarmMetrics();
// Throws swarmsim::Error for an unknown name.
std::unique_ptr<Observer> MakeSwarmMetric(const SwarmMetricSpec& spec);

}  // namespace swarmsim
