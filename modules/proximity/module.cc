// The proximity backend (backend.h) as a module: built when the world
// starts, sensing in the sense phase (framework/module.h), and the world's
// line of sight (framework/line_of_sight.h) and proximity readings
// (framework/proximity_readings.h: the plugins' C API) while it runs. Register() adds
// it and the proximity_sensor type to a registry.
#include <algorithm>
#include <memory>
#include <string>
#include <vector>

#include "framework/collections.h"
#include "framework/object_type.h"
#include "framework/proximity_readings.h"
#include "framework/registry.h"
#include "framework/scheduler.h"
#include "framework/world.h"
#include "modules/proximity/proximity.h"
#include "modules/proximity/proximity_sensor.h"

namespace swarmsim::proximity {
namespace {

// "file:line:col: proximity sensor /bot#0/eye ('detectable')".
std::string DetectableWhat(const Scene& scene, ObjectId sensor, const std::string& where) {
  return (where.empty() ? "" : where + ": ") + "proximity sensor " + scene.PathOf(sensor) +
         " ('detectable')";
}

class ProximityModule final : public Module, public ProximityReadings {
 public:
  explicit ProximityModule(std::unique_ptr<ProximityBackend> backend)
      : backend_(std::move(backend)) {}

  void Start(World* world) override {
    settings_.octree_resolution = world->settings().octree_resolution;
    settings_.seed = world->settings().seed;
    settings_.scheduler = &world->scheduler();
    backend_->Build(world->scene(), settings_);
    environment_version_ = world->scene().environment_version();
    world->set_line_of_sight(backend_.get());
    world->set_proximity_readings(this);
    RefreshDetectable(world->scene());
  }

  // Snapshots: the readings are the rows'; only the seed may change (a
  // snapshot of another seed: the backend draws from it).
  bool SaveState(const World&, StateWriter*) const override { return true; }
  void LoadState(StateReader*, World* world) override {
    if (settings_.seed == world->settings().seed) return;
    settings_.seed = world->settings().seed;
    backend_->Build(world->scene(), settings_);
    environment_version_ = world->scene().environment_version();
  }

  int Read(const Scene& scene, ObjectId id, double* distance) const noexcept override {
    const ProximitySensorData* p = FindSensor(scene, id);
    if (p == nullptr) return -1;
    if (!p->detected) return 0;
    *distance = p->distance;
    return 1;
  }

  // Every robot's sensors, robots in parallel, then the scene's own sensors.
  void Sense(World* world) override {
    Scene& scene = world->scene();
    backend_->FollowStaticShapes(scene);  // for the line of sight too
    // No proximity sensor anywhere (Kilobots, say): nothing reads the
    // placed shapes, so do not place them (a sensor copied in later brings
    // the work back from the next sense phase).
    if (Sensors(scene).rows.empty()) return;
    // A mill cut the map (Scene::set_environment): the static index again.
    if (environment_version_ != scene.environment_version()) {
      backend_->Build(scene, settings_);
      environment_version_ = scene.environment_version();
    }
    if (detectable_version_ != scene.structure_version()) RefreshDetectable(scene);
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
  // The sensors with a `detectable:` set: per sensor slot, the shapes it may
  // detect (ascending slots), resolved once per scene structure, before the
  // parallel sensing reads them through the backend's filter.
  void RefreshDetectable(const Scene& scene) {
    detectable_version_ = scene.structure_version();
    struct Sets {
      std::vector<char> used;                 // by sensor slot
      std::vector<std::vector<uint32_t>> of;  // by sensor slot: detectable shapes, ascending
    };
    auto sets = std::make_shared<Sets>();
    const Rows<ProximitySensorData>& sensors = Sensors(scene);
    for (size_t r = 0; r < sensors.rows.size(); ++r) {
      const ProximitySensorSettings& more = *sensors.rows[r].settings;
      if (more.detectable.empty()) continue;
      const uint32_t slot = sensors.owners[r];
      sets->used.resize(scene.slot_count(), 0);
      sets->of.resize(scene.slot_count());
      const ObjectId sensor = scene.IdAt(slot);
      sets->of[slot] = EntitySlots(scene, more.detectable, sensor,
                                   DetectableWhat(scene, sensor, more.detectable_where));
      sets->used[slot] = 1;
    }
    if (sets->used.empty()) {
      if (filtering_) backend_->SetDetectableFilter({});
      filtering_ = false;
      return;
    }
    filtering_ = true;
    backend_->SetDetectableFilter([sets](ObjectId sensor, ObjectId shape) {
      const uint32_t s = sensor.index();
      if (s >= sets->used.size() || !sets->used[s]) return true;
      return std::binary_search(sets->of[s].begin(), sets->of[s].end(), shape.index());
    });
  }

  std::unique_ptr<ProximityBackend> backend_;
  ProximitySettings settings_;
  uint64_t environment_version_ = 0;  // of the map the static index holds
  uint64_t detectable_version_ = UINT64_MAX;
  bool filtering_ = false;
};

}  // namespace

std::unique_ptr<Module> MakeModule(std::unique_ptr<ProximityBackend> backend) {
  return std::make_unique<ProximityModule>(std::move(backend));
}

void Register(ModuleRegistry* registry, BackendFactory factory) {
  Register(registry, ModuleInfo(), std::move(factory));
}

void Register(ModuleRegistry* registry, swarmsim::ModuleInfo info, BackendFactory factory) {
  if (!factory) factory = [] { return MakeBackend(); };
  info.kind = "proximity";
  registry->RegisterModule(
      {std::move(info), PhaseBit(Phase::kSense), 100,
       /*every_world=*/true,
       [factory = std::move(factory)](World*, const void*) { return MakeModule(factory()); }});
  // The descriptor is a constant of this module: shared without an owner.
  registry->RegisterObjectType(std::shared_ptr<const ObjectTypeDescriptor>(
      std::shared_ptr<const ObjectTypeDescriptor>(), &SensorTypeDescriptor()));
}

}  // namespace swarmsim::proximity
