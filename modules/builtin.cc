#include "modules/builtin.h"

#include "framework/dynamics_backend.h"
#include "framework/registry.h"
#include "framework/world_section.h"
#include "modules/blobs/blobs.h"
#include "modules/collision/collision.h"
#include "modules/dynamics/box2d/box2d_backend.h"
#include "modules/dynamics/kinematic/kinematic_backend.h"
#include "modules/dynamics/ode/ode_backend.h"
#include "modules/dynamics/planar/planar_backend.h"
#include "modules/environment/environment.h"
#include "modules/floor/floor.h"
#include "modules/force_sensor/force_sensor.h"
#include "modules/graphs/graphs.h"
#include "modules/ground_sensor/ground_sensor.h"
#include "modules/ir_messaging/ir_messaging.h"
#include "modules/kinematics/ik_groups.h"
#include "modules/light/light.h"
#include "modules/metrics/swarm_metrics.h"
#include "modules/mill/mill.h"
#include "modules/paint/paint_nozzle.h"
#include "modules/paths/paths.h"
#include "modules/planning/planning.h"
#include "modules/proximity/proximity.h"
#include "modules/range_and_bearing/range_and_bearing.h"
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
      box2d::ModuleInfo(), {.planar = true}, [] { return box2d::MakeBackend(); },
      BareLoop<box2d::TimeBareLoop>);
  registry->RegisterDynamics(
      ode::ModuleInfo(), {.planar = false}, [] { return ode::MakeBackend(); },
      BareLoop<ode::TimeBareLoop>);
  registry->RegisterDynamicsSection("ode", ode::Section());  // simulation: {ode: {...}}
  registry->RegisterDynamics(kinematic::ModuleInfo(), {.planar = false, .substeps = false},
                             [] { return kinematic::MakeBackend(); });
  registry->RegisterDynamics(
      planar::ModuleInfo(), {.planar = true, .substeps = false},
      [] { return planar::MakeBackend(); }, BareLoop<planar::TimeBareLoop>);
  // The first module types, registered right after the built-in ones so the
  // state hash adds types' rows in the order it did when they were built in:
  // proximity_sensor is listed right after joint (its listed_after), then
  // the built-in plugin_sensor and collection, then force_sensor.
  proximity::Register(registry);
  force_sensor::Register(registry);
  kinematics::Register(registry);
  paint::Register(registry);
  for (ModuleDescriptor& metric : metrics::SwarmMetricModules())
    registry->RegisterModule(std::move(metric));
  collision::Register(registry);
  mill::Register(registry);
  environment::Register(registry);  // the `octomap` map format of `environment:`
  paths::Register(registry);
  planning::Register(registry);
  filters::Register(registry);
  rendering::RegisterObjects(registry);
  graphs::Register(registry);
  blobs::Register(registry);
  ground_sensor::Register(registry);
  floors::Register(registry);  // the floor (floor:), ground sensors' and the paint layer's base
  light::Register(registry);   // light sources and light sensors
  video::Register(registry);   // snapshots and video: the program's view recorder
  range_and_bearing::Register(registry);
  ir_messaging::Register(registry);  // IR transceivers (Kilobot messaging)
  // World-file sections, in the order the loader reads them.
  registry->RegisterWorldSection(metrics::MetricsSection());
  registry->RegisterWorldSection(floors::FloorSection());  // before paint: paint starts from it
  registry->RegisterWorldSection(paint::PaintSection());
}

}  // namespace swarmsim
