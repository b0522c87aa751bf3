#include "modules/dynamics/planar/planar_backend.h"

#include <chrono>
#include <memory>
#include <string>

#include "framework/scene.h"
#include "modules/dynamics/engine_backend.h"
#include "modules/dynamics/planar/planar_world.h"

namespace swarmsim::planar {

namespace {

class PlanarBackend final : public DynamicsBackend {
 public:
  void Build(const Scene& scene, const DynamicsSettings& settings) override {
    world_ = std::make_unique<PlanarWorld>(Options{}, settings);
    world_->Build(scene);
    built_version_ = scene.structure_version();
  }

  void Step(Scene* scene, double dt, int substeps) override {
    SWARMSIM_CHECK(world_ != nullptr, "planar: Step() before Build()");
    dynamics::CheckStepArguments("planar", dt, substeps);
    // Objects added or removed, or switched between dynamic and static.
    if (scene->structure_version() != built_version_) {
      world_->Build(*scene);
      built_version_ = scene->structure_version();
    }
    if (substeps == 0) return;
    // One advance over the whole step: the motion is exact over it, and
    // Advance cuts it where a body would move too far (planar_backend.h).
    const double duration = dt * substeps;
    world_->SyncFromScene(*scene);
    world_->ReadCommands(*scene, duration);
    world_->Advance(duration);
    world_->EndPushes();
    world_->WriteBack(scene, duration);
  }

  bool TakeVelocities(Scene* scene, std::span<const uint32_t> slots) override {
    if (!world_ || scene->structure_version() != built_version_) return false;  // Build reads
    world_->Push(*scene, slots);
    return true;
  }

  void HashState(StateHasher* hasher) const override {
    if (world_) world_->Hash(hasher);
  }

  int body_count() const override { return world_ ? world_->body_count() : 0; }

 private:
  std::unique_ptr<PlanarWorld> world_;
  uint64_t built_version_ = 0;
};

}  // namespace

swarmsim::ModuleInfo ModuleInfo() {
  return {"dynamics", "planar", "1.0",
          "kinematic wheels and exact circle/rectangle overlap resolution in the plane (no "
          "forces): swarms that only drive and bump"};
}

std::unique_ptr<DynamicsBackend> MakeBackend() { return std::make_unique<PlanarBackend>(); }

double TimeBareLoop(const Scene& scene, double dt, int substeps, int steps, const Options& options,
                    const DynamicsSettings& settings) {
  dynamics::CheckStepArguments("planar", dt, substeps);
  PlanarWorld world(options, settings);
  world.Build(scene);
  world.ReadCommands(scene);
  const auto start = std::chrono::steady_clock::now();
  if (substeps > 0)
    for (int i = 0; i < steps; ++i) world.Advance(dt * substeps);
  const auto stop = std::chrono::steady_clock::now();
  return std::chrono::duration<double>(stop - start).count();
}

}  // namespace swarmsim::planar
