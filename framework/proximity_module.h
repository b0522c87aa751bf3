// The proximity backend (framework/proximity_backend.h) as a module: built
// when the world starts, sensing in the sense phase (ordinary module,
// framework/module.h), and reachable as World::proximity() for
// line-of-sight messages.
#pragma once

#include <memory>

#include "framework/module.h"

namespace swarmsim {

class ProximityBackend;

std::unique_ptr<Module> MakeProximityModule(std::unique_ptr<ProximityBackend> backend);

}  // namespace swarmsim
