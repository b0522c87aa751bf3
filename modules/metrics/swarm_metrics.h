// The built-in swarm metrics, each a module (framework/module.h) of kind
// "metric": record phase, order 100 (before the paint layer). A world file's
// `metrics: [{name, every}]` (this module's world-file section) adds one
// instance per entry
// (World::AddModule(name, &every)); a row describes the state after the
// step it is labelled with.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "framework/module.h"

namespace swarmsim {

struct WorldSectionDescriptor;

struct SwarmMetricSpec {
  std::string name;     // e.g. "mean_nearest_neighbor_distance"
  int every_steps = 1;  // record every N steps
};

namespace metrics {

// One descriptor per metric: mean_nearest_neighbor_distance, covered_area.
// `make` takes a const int* (record every N steps; null: every step).
std::vector<ModuleDescriptor> SwarmMetricModules();
// The world-file section `metrics:` that adds them (metrics_section.cc;
// ModuleRegistry::RegisterWorldSection).
std::shared_ptr<const WorldSectionDescriptor> MetricsSection();

}  // namespace metrics
}  // namespace swarmsim
