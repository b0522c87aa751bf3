#include "modules/dynamics/ode/ode_backend.h"

#include <ode/ode.h>

#include <chrono>
#include <string>

#include "framework/error.h"
#include "framework/scene.h"
#include "modules/dynamics/ode/ode_world.h"

namespace swarmsim::ode {

namespace {

void CheckStepArguments(double dt, int substeps) {
  if (!(dt > 0) || substeps < 0)
    throw Error("ode: a step needs dt > 0 and substeps >= 0 (got dt " + std::to_string(dt) +
                ", substeps " + std::to_string(substeps) + ")");
}

class OdeBackend final : public DynamicsBackend {
 public:
  explicit OdeBackend(const Options& options) : options_(options) {}

  void Build(const Scene& scene, const DynamicsSettings& settings) override {
    world_ = std::make_unique<OdeWorld>(options_, settings);
    world_->Build(scene);
    built_version_ = scene.structure_version();
  }

  void MarkSimulatedJoints(Scene* scene) const override {
    if (world_) world_->MarkJoints(scene);
  }

  void Step(Scene* scene, double dt, int substeps) override {
    SWARMSIM_CHECK(world_ != nullptr, "ode: Step() before Build()");
    CheckStepArguments(dt, substeps);
    // Objects added or removed, or switched between dynamic and kinematic:
    // rebuild from the scene (velocities and joint positions included).
    if (scene->structure_version() != built_version_) {
      world_->Build(*scene);
      world_->MarkJoints(scene);
      built_version_ = scene->structure_version();
    }
    if (substeps == 0) return;
    world_->SyncFromScene(*scene, dt * substeps);
    world_->ReadJointCommands(*scene);
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
  std::unique_ptr<OdeWorld> world_;
  uint64_t built_version_ = 0;
};

}  // namespace

swarmsim::ModuleInfo ModuleInfo() {
  return {"dynamics", "ode", "1.0 (ODE 0.16, double precision)",
          "3D rigid bodies: boxes, spheres, cylinders, capsules; hinge, slider, ball and fixed "
          "joints with motors and servos; kinematic bodies for hybrid simulation"};
}

std::unique_ptr<DynamicsBackend> MakeBackend() { return MakeBackend(Options{}); }

std::unique_ptr<DynamicsBackend> MakeBackend(const Options& options) {
  return std::make_unique<OdeBackend>(options);
}

double TimeBareLoop(const Scene& scene, double dt, int substeps, int steps, const Options& options,
                    const DynamicsSettings& settings) {
  CheckStepArguments(dt, substeps);
  OdeWorld world(options, settings);
  world.Build(scene);
  world.ReadJointCommands(scene);
  const auto start = std::chrono::steady_clock::now();
  for (int s = 0; s < steps; ++s)
    for (int i = 0; i < substeps; ++i) world.Substep(dt, 1.0);
  const auto stop = std::chrono::steady_clock::now();
  return std::chrono::duration<double>(stop - start).count();
}

}  // namespace swarmsim::ode
