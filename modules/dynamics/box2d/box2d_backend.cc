#include "modules/dynamics/box2d/box2d_backend.h"

#include <box2d/b2_common.h>

#include <string>

#include "modules/dynamics/box2d/plane_partition.h"
#include "modules/dynamics/engine_backend.h"

namespace swarmsim::box2d {

swarmsim::ModuleInfo ModuleInfo() {
  // Major.minor only: Debian's 2.4.1 library reports its b2_version as 2.4.0.
  return {"dynamics", "box2d",
          "1.0 (Box2D " + std::to_string(b2_version.major) + "." +
              std::to_string(b2_version.minor) + ")",
          "top-down plane: wheeled robots with Coulomb traction, walls, pushable objects"};
}

std::unique_ptr<DynamicsBackend> MakeBackend() { return MakeBackend(Options{}); }

std::unique_ptr<DynamicsBackend> MakeBackend(const Options& options) {
  return std::make_unique<dynamics::EngineBackend<PartitionedPlaneWorld>>(options);
}

double TimeBareLoop(const Scene& scene, double dt, int substeps, int steps, const Options& options,
                    const DynamicsSettings& settings) {
  return dynamics::TimeBareLoop<PartitionedPlaneWorld>(scene, dt, substeps, steps, options,
                                                       settings);
}

}  // namespace swarmsim::box2d
