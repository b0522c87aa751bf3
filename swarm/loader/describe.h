// What `swarmsim describe WORLD` prints of a loaded world, and Python's
// World.describe() returns: its settings, modules, environment, warnings and
// parameters, then each models entry (copies, what a URDF import brought,
// scripts, controllers, parameters with units and ranges, copies' own
// values). Nothing runs.
#pragma once

#include <ostream>

#include "swarm/loader/world_loader.h"

namespace swarmsim {

void PrintDescription(const LoadedWorld& w, std::ostream& out);

}  // namespace swarmsim
