#include "framework/proximity_module.h"

#include "framework/proximity_backend.h"
#include "framework/registry.h"
#include "framework/scheduler.h"
#include "framework/world.h"

namespace swarmsim {
namespace {

class ProximityModule final : public Module {
 public:
  explicit ProximityModule(std::unique_ptr<ProximityBackend> backend)
      : backend_(std::move(backend)) {}

  void Start(World* world) override {
    ProximitySettings settings;
    settings.octree_resolution = world->settings().octree_resolution;
    settings.seed = world->settings().seed;
    backend_->Build(world->scene(), settings);
    world->set_proximity(backend_.get());
  }

  // Every robot's sensors, robots in parallel, then the scene's own sensors.
  void Sense(World* world) override {
    Scene& scene = world->scene();
    backend_->SetStep(static_cast<uint64_t>(world->step_count()));
    backend_->Update(scene);
    const auto& instances = scene.instances();
    world->scheduler().ParallelFor(0, static_cast<int64_t>(instances.size()), kRobotGrain,
                                   [&](int64_t begin, int64_t end) {
                                     for (int64_t r = begin; r < end; ++r)
                                       if (instances[r].alive)
                                         backend_->SenseInstance(&scene, static_cast<int>(r));
                                   });
    backend_->SenseSceneSensors(&scene);
  }

 private:
  std::unique_ptr<ProximityBackend> backend_;
};

}  // namespace

std::unique_ptr<Module> MakeProximityModule(std::unique_ptr<ProximityBackend> backend) {
  return std::make_unique<ProximityModule>(std::move(backend));
}

// Defined beside the adapter it registers (registry.cc does not depend on it).
void ModuleRegistry::RegisterProximity(ModuleInfo info, ProximityFactory factory) {
  info.kind = "proximity";
  RegisterModule({std::move(info), PhaseBit(ModulePhase::kSense), 100, /*every_world=*/true,
                  [factory = std::move(factory)](World*, const void*) {
                    return MakeProximityModule(factory());
                  }});
}

}  // namespace swarmsim
