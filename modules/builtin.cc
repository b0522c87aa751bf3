#include "modules/builtin.h"

#include "framework/dynamics_backend.h"
#include "framework/registry.h"
#include "modules/blobs/blobs.h"
#include "modules/collision/collision.h"
#include "modules/dynamics/box2d/box2d_backend.h"
#include "modules/dynamics/kinematic/kinematic_backend.h"
#include "modules/dynamics/ode/ode_backend.h"
#include "modules/dynamics/planar/planar_backend.h"
#include "modules/graphs/graphs.h"
#include "modules/kinematics/ik_groups.h"
#include "modules/metrics/swarm_metrics.h"
#include "modules/mill/mill.h"
#include "modules/paint/paint_layer.h"
#include "modules/paths/paths.h"
#include "modules/planning/planning.h"
#include "modules/proximity/proximity.h"
#include "modules/rendering/filters/filters.h"
#include "modules/rendering/objects.h"
#include "modules/rendering/video/recorder.h"

namespace swarmsim {

namespace {

// The engine alone, for `swarmsim bench`'s "<physics>-only" row.
template <auto kTimeBareLoop>
double BareLoop(const Scene& scene, double dt, int substeps, int steps, double gravity) {
  DynamicsSettings settings;
  settings.gravity = gravity;
  return kTimeBareLoop(scene, dt, substeps, steps, {}, settings);
}

}  // namespace

// One line per module.
void RegisterBuiltinModules(ModuleRegistry* registry) {
  registry->RegisterDynamics(
      box2d::ModuleInfo(), [] { return box2d::MakeBackend(); }, BareLoop<box2d::TimeBareLoop>);
  registry->RegisterDynamics(
      ode::ModuleInfo(), [] { return ode::MakeBackend(); }, BareLoop<ode::TimeBareLoop>);
  registry->RegisterDynamics(kinematic::ModuleInfo(), [] { return kinematic::MakeBackend(); });
  registry->RegisterDynamics(
      planar::ModuleInfo(), [] { return planar::MakeBackend(); }, BareLoop<planar::TimeBareLoop>);
  proximity::Register(registry);
  registry->RegisterCalculation(kinematics::IkModuleInfo(),
                                [] { return kinematics::MakeIkGroups(); });
  registry->RegisterModule(paint::PaintModule());
  for (ModuleDescriptor& metric : metrics::SwarmMetricModules())
    registry->RegisterModule(std::move(metric));
  collision::Register(registry);
  mill::Register(registry);
  paths::Register(registry);
  planning::Register(registry);
  filters::Register(registry);
  rendering::RegisterObjects(registry);
  graphs::Register(registry);
  blobs::Register(registry);
  registry->RegisterModule(video::RecorderModule());
}

}  // namespace swarmsim
