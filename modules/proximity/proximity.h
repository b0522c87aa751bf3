// Ray proximity sensors: OctoMap-indexed static environment, spatial grid of robots.
#pragma once

#include <memory>

#include "framework/proximity_backend.h"
#include "framework/registry.h"

namespace swarmsim::proximity {

swarmsim::ModuleInfo ModuleInfo();
std::unique_ptr<ProximityBackend> MakeBackend();

}  // namespace swarmsim::proximity
