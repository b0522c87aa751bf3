// modules/proximity: proximity sensors (rays, randomized rays and detection
// volumes) against an OctoMap-indexed static environment and a spatial grid
// of robots. The module's public header: its registration (the sense-phase
// module, the `proximity_sensor` type and its Lua area), and the backend
// for benchmarks and tests. The type's rows: proximity_sensor.h.
#pragma once

#include <functional>
#include <memory>

#include "framework/module.h"
#include "framework/registry.h"
#include "modules/proximity/backend.h"
#include "modules/proximity/proximity_sensor.h"

namespace swarmsim::proximity {

struct BackendOptions {
  // Skip the rays of a robot with nothing within reach (the readings are the
  // same either way; false casts every ray, for tests and benchmarks).
  bool early_out = true;
};

swarmsim::ModuleInfo ModuleInfo();
std::unique_ptr<ProximityBackend> MakeBackend(const BackendOptions& options = {});

using BackendFactory = std::function<std::unique_ptr<ProximityBackend>()>;

// Registers the module (kind "proximity", sense phase, order 100, made for
// every world; it provides the world's line of sight) with the backend
// `factory` makes (empty: MakeBackend()), and the `proximity_sensor` type
// (listed after `joint`, where it was a built-in type) with its Lua area.
void Register(ModuleRegistry* registry, BackendFactory factory = {});
// Same, under another name and line (a test double's).
void Register(ModuleRegistry* registry, swarmsim::ModuleInfo info, BackendFactory factory);

// The module driving `backend` (what Register's factory makes for a world).
std::unique_ptr<Module> MakeModule(std::unique_ptr<ProximityBackend> backend);

}  // namespace swarmsim::proximity
