// modules/paths: path objects (paper §2.1) and objects following them: a
// `path` type (control points, linear or smooth, open or closed, arc-length
// parametrised), the `paths` module moving each path's followers along it
// in the actuate phase, and the scripts' sim.getPathLength, sim.getPathPose,
// sim.getPathPosition, sim.setPathPosition, sim.setPathVelocity.
#pragma once

namespace swarmsim {
class ModuleRegistry;
}

namespace swarmsim::paths {

// The module and the `path` type.
void Register(ModuleRegistry* registry);

}  // namespace swarmsim::paths
