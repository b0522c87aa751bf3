// Ray proximity sensors: OctoMap-indexed static environment, spatial grid of robots.
#pragma once

#include <memory>

#include "framework/proximity_backend.h"
#include "framework/registry.h"

namespace swarmsim::proximity {

struct BackendOptions {
  // Skip the rays of a robot with nothing within reach (the readings are the
  // same either way; false casts every ray, for tests and benchmarks).
  bool early_out = true;
};

swarmsim::ModuleInfo ModuleInfo();
std::unique_ptr<ProximityBackend> MakeBackend(const BackendOptions& options = {});

}  // namespace swarmsim::proximity
