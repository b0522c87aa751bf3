// What the Box2D and ODE backends share: a DynamicsBackend that owns one
// engine world, rebuilds it when the scene's structure changes and runs the
// step sequence; and the bare loop behind `swarmsim bench`'s engine-only rows.
// Each engine keeps only its world class (engine types stay in its folder).
//
// A World (box2d::PlaneWorld, ode::OdeWorld) provides:
//   using Options = ...;                  the engine's settings
//   static constexpr std::string_view kName;      "box2d": prefixes errors
//   static constexpr bool kIdleWithoutSubsteps;   a step of 0 substeps does
//                                                 nothing (not even a write-back)
//   World(const Options&, const DynamicsSettings&);  checks them (throws Error)
//   void Build(const Scene&);             (re)builds everything from the scene
//   void MarkJoints(Scene*) const;        sets JointData::simulated
//   void SyncFromScene(const Scene&, double duration);  what scripts moved
//                                         since the last write-back; `duration`
//                                         is the whole step's, s
//   void ReadCommands(const Scene&);      joint commands, once per step
//   void Substep(double dt, double fraction);  one engine step; `fraction` in
//                                         [0, 1] is where in the step it starts
//   void WriteBack(Scene*);               poses, velocities, joint states
//   void Hash(StateHasher*) const;        engine state the scene does not hold
//   int body_count() const;
// All calls are direct (World is a template argument): the per-step path
// costs one virtual call (DynamicsBackend::Step), as before.
#pragma once

#include <chrono>
#include <cstdint>
#include <memory>
#include <string>
#include <string_view>

#include "framework/dynamics_backend.h"
#include "framework/error.h"
#include "framework/scene.h"

namespace swarmsim::dynamics {

// A user mistake (a bad time step) as an error naming the engine.
inline void CheckStepArguments(std::string_view engine, double dt, int substeps) {
  if (!(dt > 0) || substeps < 0)
    throw Error(std::string(engine) + ": a step needs dt > 0 and substeps >= 0 (got dt " +
                std::to_string(dt) + ", substeps " + std::to_string(substeps) + ")");
}

template <class World>
class EngineBackend final : public DynamicsBackend {
 public:
  using Options = typename World::Options;

  explicit EngineBackend(const Options& options) : options_(options) {}

  void Build(const Scene& scene, const DynamicsSettings& settings) override {
    world_ = std::make_unique<World>(options_, settings);
    world_->Build(scene);
    built_version_ = scene.structure_version();
  }

  void MarkSimulatedJoints(Scene* scene) const override {
    if (world_) world_->MarkJoints(scene);
  }

  void Step(Scene* scene, double dt, int substeps) override {
    SWARMSIM_CHECK(world_ != nullptr, std::string(World::kName) + ": Step() before Build()");
    CheckStepArguments(World::kName, dt, substeps);
    // Objects added or removed, or switched between dynamic and kinematic:
    // rebuild from the scene (velocities and joint positions included).
    // (A static shape that moved is each engine's own: SyncFromScene.)
    if (scene->structure_version() != built_version_) {
      world_->Build(*scene);
      world_->MarkJoints(scene);
      built_version_ = scene->structure_version();
    }
    if (World::kIdleWithoutSubsteps && substeps == 0) return;
    world_->SyncFromScene(*scene, dt * substeps);
    world_->ReadCommands(*scene);
    for (int i = 0; i < substeps; ++i)
      world_->Substep(dt, static_cast<double>(i) / static_cast<double>(substeps));
    world_->WriteBack(scene);
  }

  void HashState(StateHasher* hasher) const override {
    if (world_) world_->Hash(hasher);
  }

  int body_count() const override { return world_ ? world_->body_count() : 0; }

 private:
  Options options_;
  std::unique_ptr<World> world_;
  uint64_t built_version_ = 0;
};

// The engine alone, for the bench's engine-only rows: builds a World from
// `scene`, reads the joint commands once, then runs steps x substeps engine
// steps of `dt` with no scene write-back. Returns the wall-clock seconds
// spent stepping (not building).
template <class World>
double TimeBareLoop(const Scene& scene, double dt, int substeps, int steps,
                    const typename World::Options& options, const DynamicsSettings& settings) {
  CheckStepArguments(World::kName, dt, substeps);
  World world(options, settings);
  world.Build(scene);
  world.ReadCommands(scene);
  const int64_t total = static_cast<int64_t>(steps) * substeps;
  const auto start = std::chrono::steady_clock::now();
  for (int64_t i = 0; i < total; ++i) world.Substep(dt, 1.0);
  const auto stop = std::chrono::steady_clock::now();
  return std::chrono::duration<double>(stop - start).count();
}

}  // namespace swarmsim::dynamics
