// modules/collision: collision detection and minimum distance on FCL 0.7
// (paper §2.2): the `distance` and `collision` object types, computed
// after physics each step (robots in parallel) and recorded into
// metrics.csv, and the scripts' sim.checkCollision, sim.checkDistance,
// sim.readDistance, sim.readCollision.
#pragma once

namespace swarmsim {
class ModuleRegistry;
}

namespace swarmsim::collision {

// The module and its two object types.
void Register(ModuleRegistry* registry);

}  // namespace swarmsim::collision
