#include "modules/dynamics/box2d/box2d_backend.h"

#include <box2d/b2_common.h>

#include <chrono>
#include <string>

#include "framework/error.h"
#include "framework/scene.h"
#include "modules/dynamics/box2d/plane_world.h"

namespace swarmsim::box2d {

namespace {

void CheckStepArguments(double dt, int substeps) {
  if (!(dt > 0) || substeps < 0)
    throw Error("box2d: a step needs dt > 0 and substeps >= 0 (got dt " + std::to_string(dt) +
                ", substeps " + std::to_string(substeps) + ")");
}

class Box2dBackend final : public DynamicsBackend {
 public:
  explicit Box2dBackend(const Options& options) : options_(options) {}

  void Build(const Scene& scene, const DynamicsSettings& settings) override {
    world_ = std::make_unique<PlaneWorld>(options_, settings);
    world_->Build(scene);
    built_version_ = scene.structure_version();
  }

  void Step(Scene* scene, double dt, int substeps) override {
    SWARMSIM_CHECK(world_ != nullptr, "box2d: Step() before Build()");
    CheckStepArguments(dt, substeps);
    // Objects added or removed: rebuild from the scene (velocities included).
    // Otherwise follow bodies moved from outside.
    if (scene->structure_version() != built_version_) {
      world_->Build(*scene);
      built_version_ = scene->structure_version();
    } else {
      world_->SyncTeleports(*scene);
    }
    world_->ReadWheelCommands(*scene);
    for (int i = 0; i < substeps; ++i) world_->Substep(dt);
    world_->WriteBack(scene);
  }

  void HashState(StateHasher* hasher) const override {
    if (world_) world_->Hash(hasher);
  }

  int body_count() const override { return world_ ? world_->body_count() : 0; }

 private:
  Options options_;
  std::unique_ptr<PlaneWorld> world_;
  uint64_t built_version_ = 0;
};

}  // namespace

swarmsim::ModuleInfo ModuleInfo() {
  // Major.minor only: Debian's 2.4.1 library reports its b2_version as 2.4.0.
  return {"dynamics", "box2d",
          "1.0 (Box2D " + std::to_string(b2_version.major) + "." +
              std::to_string(b2_version.minor) + ")",
          "top-down plane: wheeled robots with Coulomb traction, walls, pushable objects"};
}

std::unique_ptr<DynamicsBackend> MakeBackend() { return MakeBackend(Options{}); }

std::unique_ptr<DynamicsBackend> MakeBackend(const Options& options) {
  return std::make_unique<Box2dBackend>(options);
}

double TimeBareLoop(const Scene& scene, double dt, int substeps, int steps, const Options& options,
                    const DynamicsSettings& settings) {
  CheckStepArguments(dt, substeps);
  PlaneWorld world(options, settings);
  world.Build(scene);
  world.ReadWheelCommands(scene);
  const int64_t total = static_cast<int64_t>(steps) * substeps;
  const auto start = std::chrono::steady_clock::now();
  for (int64_t i = 0; i < total; ++i) world.Substep(dt);
  const auto stop = std::chrono::steady_clock::now();
  return std::chrono::duration<double>(stop - start).count();
}

}  // namespace swarmsim::box2d
