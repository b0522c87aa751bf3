// World.snapshot(), restore(), reset() and pickling (framework/world_state.h
// is the design): the bytes Python sees are the world's snapshot followed by
// the metrics the Python World has kept (World.metrics, metric_history), so
// that a restored World reports what the original did.
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "framework/world.h"

namespace swarmsim::python {

// The metrics a Python World keeps beside its world (world.h).
struct MetricMaps {
  std::map<std::string, double>* swarm;
  std::map<std::string, std::map<int, double>>* robots;
  std::map<std::string, std::vector<std::pair<int64_t, double>>>* history;
};

// world->SaveState() and the metrics. Throws swarmsim::Error naming what
// cannot be saved.
std::string PackSnapshot(World* world, const MetricMaps& metrics);
// Restores both; throws swarmsim::Error for bytes of another world, corrupt
// or truncated ones, leaving the world and the metrics as they were.
// With `reseed`, the snapshot of a world before its first step becomes that
// world as a load with another seed makes it (World::RestoreState).
void UnpackSnapshot(std::string_view bytes, World* world, const MetricMaps& metrics,
                    const World::Reseed* reseed = nullptr);

}  // namespace swarmsim::python
