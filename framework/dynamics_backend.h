// The interface every dynamics engine implements (Box2D, ODE, kinematic).
//
// A backend mirrors the scene's shapes and joints into its engine at Build(),
// steps them, and writes back the world poses and velocities of the bodies it
// simulates (Scene::SetSimulatedState) and the positions/velocities of the
// joints it drives. Engine types never leave the module.
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <string>

namespace swarmsim {

class Scene;
class StateHasher;
class TaskScheduler;

// A backend's own settings, read from the world file's `simulation.<backend>`
// mapping (`simulation: {physics: ode, ode: {erp: 0.2}}`) by the reader the
// backend registered (ModuleRegistry::RegisterDynamicsSection). Each backend
// derives its own and casts back in Build.
struct DynamicsOptions {
  virtual ~DynamicsOptions() = default;
};

struct DynamicsSettings {
  double gravity = 9.81;  // m/s^2, magnitude; 2D backends use it for ground friction
  // Regions of the arena stepped independently (simulation.physics_partitions):
  // 0 = auto (the backend chooses from the scene, never from the thread
  // count), 1 = one engine world. Part of the model: it changes results.
  int partitions = 1;
  // Workers for independent parts of the step (regions, islands). Never
  // changes results: the same world gives the same state for any thread
  // count. Null: everything on the caller's thread.
  TaskScheduler* scheduler = nullptr;
  // The world's `simulation.<backend>` settings (WorldSettings::physics_options),
  // or null: the backend's defaults.
  std::shared_ptr<const DynamicsOptions> options;
};

// What a backend simulates, declared when it registers
// (ModuleRegistry::RegisterDynamics): callers (summaries, the Python
// module, benchmarks) ask this instead of testing the backend's name.
struct DynamicsCapabilities {
  // Bodies move in the ground plane only: pose (x, y, yaw), no gravity
  // along z (box2d, planar). Python's World.planar; poses as (x, y, yaw).
  bool planar = false;
  // An engine integrates bodies in substeps (simulation.physics_substeps);
  // false for a backend that only moves what scripts and joints move
  // (kinematic) or takes the control step in one (planar: exact motion, cut
  // only where a body would tunnel). The run's summary names substeps only
  // where they are taken.
  bool substeps = true;
};

class DynamicsBackend {
 public:
  virtual ~DynamicsBackend() = default;

  // Creates engine bodies for every shape and joint in the scene. Called once
  // at start, after the world is placed.
  virtual void Build(const Scene& scene, const DynamicsSettings& settings) = 0;
  // Advances `substeps` steps of `dt` seconds each, reading joint targets
  // from the scene and writing simulated poses, velocities and joint states.
  // Must be deterministic: same inputs, same outputs, bit for bit.
  virtual void Step(Scene* scene, double dt, int substeps) = 0;
  // Folds any engine state that is not mirrored in the scene and changes the
  // future (warm-start caches, contact state) into the hash. May do nothing
  // when the engine is rebuilt identically from the scene.
  virtual void HashState(StateHasher* /*hasher*/) const {}
  // Sets JointData::simulated on the joints whose position and velocity the
  // engine integrates (World::Actuate then skips them). Called after Build;
  // a backend that rebuilds itself in Step marks them again there.
  virtual void MarkSimulatedJoints(Scene* /*scene*/) const {}
  // The scene's velocities of the shapes at `slots` were set between steps
  // (World::SetVelocities: Python's World.set_velocities, robots' roots and
  // the shapes on them). Returns true once the engine has taken them (the
  // kinematic and planar backends: a robot moves at its velocity for the
  // next step); false (the default) makes World build the engine again from
  // the scene, which reads every body's velocity (box2d, ode).
  virtual bool TakeVelocities(Scene* /*scene*/, std::span<const uint32_t> /*slots*/) {
    return false;
  }
  // Number of bodies the engine simulates (for summaries).
  virtual int body_count() const = 0;
};

}  // namespace swarmsim
