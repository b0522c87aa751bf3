#include "modules/dynamics/ode/ode_backend.h"

#include "modules/dynamics/engine_backend.h"
#include "modules/dynamics/ode/ode_world.h"

namespace swarmsim::ode {

swarmsim::ModuleInfo ModuleInfo() {
  return {"dynamics", "ode", "1.0 (ODE 0.16, double precision)",
          "3D rigid bodies: boxes, spheres, cylinders, capsules; hinge, slider, ball and fixed "
          "joints with motors and servos; kinematic bodies for hybrid simulation; " +
              SolverThreading()};
}

std::unique_ptr<DynamicsBackend> MakeBackend() { return MakeBackend(Options{}); }

std::unique_ptr<DynamicsBackend> MakeBackend(const Options& options) {
  return std::make_unique<dynamics::EngineBackend<OdeWorld>>(options);
}

double TimeBareLoop(const Scene& scene, double dt, int substeps, int steps, const Options& options,
                    const DynamicsSettings& settings) {
  return dynamics::TimeBareLoop<OdeWorld>(scene, dt, substeps, steps, options, settings);
}

}  // namespace swarmsim::ode
