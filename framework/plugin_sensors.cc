#include "framework/plugin_sensors.h"

#include <algorithm>
#include <string>
#include <utility>

#include "framework/error.h"
#include "framework/plugin_world_api.h"
#include "framework/registry.h"
#include "framework/scheduler.h"
#include "framework/world.h"

namespace swarmsim {

namespace {

class PluginSensors final : public Module {
 public:
  void Sense(World* world) override;
  bool Reading(const Scene& scene, ObjectId id, std::span<const double>* values) const;
  // Snapshots: a world without plugin sensors has nothing here.
  bool SaveState(const World&, StateWriter*) const override { return sensors_.empty(); }

 private:
  struct Sensor {  // 40 bytes
    ObjectId id;
    const PluginSensorType* type = nullptr;
    uint32_t adr = 0;  // its reading: values_[adr .. adr + type->max_values)
    int count = -1;    // numbers in the last reading; -1 before the first
  };
  void Index(const World& world);

  std::vector<Sensor> sensors_;          // robot by robot, then the scene's
  std::vector<double> values_;           // every sensor's reading (flat)
  std::vector<uint32_t> start_;          // robots + 2: robot r's are [r], [r + 1)
  std::vector<int32_t> sensor_of_slot_;  // index into sensors_ or -1 (slots)
  uint64_t version_ = UINT64_MAX;        // scene structure they were indexed at
};

void PluginSensors::Index(const World& world) {
  const Scene& scene = world.scene();
  std::vector<std::pair<int, uint32_t>> found;  // (robot or -1, slot)
  for (uint32_t slot = 0; slot < scene.slot_count(); ++slot) {
    if (!scene.alive_at(slot) || scene.type_at(slot) != ObjectType::kPluginSensor) continue;
    found.emplace_back(scene.instance_of_at(slot), slot);
  }
  // Robots in order, the scene's objects (-1) last.
  std::stable_sort(found.begin(), found.end(), [](const auto& a, const auto& b) {
    return static_cast<unsigned>(a.first) < static_cast<unsigned>(b.first);
  });
  const size_t robots = scene.instances().size();
  sensors_.clear();
  start_.assign(robots + 2, 0);
  sensor_of_slot_.assign(scene.slot_count(), -1);
  size_t size = 0;
  const RowTable& rows = *scene.rows(ObjectType::kPluginSensor);
  for (const auto& [robot, slot] : found) {
    const ObjectId id = scene.IdAt(slot);
    const std::string& name =
        static_cast<const Rows<PluginSensorRow>&>(rows).rows[scene.row_at(slot)].sensor;
    Sensor sensor;
    sensor.id = id;
    sensor.type = world.registry().FindPluginSensor(name);
    if (sensor.type == nullptr)
      throw Error("object " + scene.PathOf(id) + " is a plugin sensor of type '" + name +
                  "', which no loaded plugin registers");
    sensor.adr = static_cast<uint32_t>(size);
    size += static_cast<size_t>(sensor.type->max_values);
    sensor_of_slot_[slot] = static_cast<int32_t>(sensors_.size());
    sensors_.push_back(sensor);
    ++start_[robot >= 0 ? robot + 1 : robots + 1];
  }
  values_.assign(size, 0.0);
  for (size_t r = 1; r < start_.size(); ++r) start_[r] += start_[r - 1];
  version_ = scene.structure_version();
}

void PluginSensors::Sense(World* world) {
  Scene& scene = world->scene();
  if (version_ != scene.structure_version()) Index(*world);
  if (sensors_.empty()) return;
  const auto& instances = scene.instances();
  const int robots = static_cast<int>(instances.size());
  auto sense = [&](int robot, std::string* error) {
    const SwarmsimCallContext context{robot, 0, world, PluginWorldApi()};
    const size_t end = start_[robot >= 0 ? robot + 1 : robots + 1];
    for (size_t i = start_[robot >= 0 ? robot : robots]; i < end; ++i) {
      Sensor& s = sensors_[i];
      char message[512] = {0};
      const int max = s.type->max_values;
      const int n = s.type->function(&context, s.id.ToInteger(), values_.data() + s.adr, max,
                                     message, sizeof message, s.type->user_data);
      if (n < 0 || n > max) {
        *error = "plugin sensor '" + s.type->name + "' (" + scene.PathOf(s.id) + "): " +
                 (n < 0 ? (message[0] ? message : "the sense function failed")
                        : "returned " + std::to_string(n) + " values, at most " +
                              std::to_string(max) + " fit");
        return;
      }
      s.count = n;
    }
  };
  // The lowest robot's error wins, whatever the thread count.
  std::vector<std::string> errors(robots + 1);
  world->scheduler().ParallelFor(0, robots, kRobotGrain, [&](int64_t begin, int64_t end) {
    for (int64_t r = begin; r < end; ++r)
      if (instances[r].alive && start_[r] != start_[r + 1]) sense(static_cast<int>(r), &errors[r]);
  });
  sense(-1, &errors[robots]);
  for (const std::string& e : errors)
    if (!e.empty()) throw Error(e);
}

bool PluginSensors::Reading(const Scene& scene, ObjectId id,
                            std::span<const double>* values) const {
  const uint32_t slot = scene.SlotOf(id);
  // Not indexed yet (added since the last sense phase): no reading.
  if (slot >= sensor_of_slot_.size() || sensor_of_slot_[slot] < 0) return false;
  const Sensor& s = sensors_[sensor_of_slot_[slot]];
  if (s.id != id || s.count < 0) return false;
  *values = std::span<const double>(values_.data() + s.adr, static_cast<size_t>(s.count));
  return true;
}

}  // namespace

ModuleDescriptor PluginSensorsModule() {
  return {{"sensor", "plugin_sensors", "1.0",
           "the plugin sensor types' objects, sensed after the proximity sensors"},
          PhaseBit(Phase::kSense),
          200,
          /*every_world=*/true,
          [](World*, const void*) { return std::make_unique<PluginSensors>(); }};
}

bool PluginSensorReading(const World& world, ObjectId id, std::span<const double>* values) {
  const Scene& scene = world.scene();
  const uint32_t slot = scene.SlotOf(id, "plugin sensor");
  if (scene.type_at(slot) != ObjectType::kPluginSensor)
    throw Error("object " + scene.PathOf(id) + " is not a plugin sensor");
  const auto* module = dynamic_cast<const PluginSensors*>(world.find_module("plugin_sensors"));
  return module != nullptr && module->Reading(scene, id, values);
}

// Defined beside the module it registers (registry.cc does not depend on it).
void ModuleRegistry::RegisterPluginSensor(ModuleInfo info, PluginSensorType type) {
  if (type.name.empty() || type.function == nullptr)
    throw Error("a plugin sensor type needs a name and a sense function");
  if (FindPluginSensor(type.name) != nullptr)
    throw Error("plugin sensor type '" + type.name + "' is registered twice");
  if (type.max_values < 1) throw Error("plugin sensor type '" + type.name + "' holds no values");
  info.kind = "sensor";
  modules_.push_back(std::move(info));
  plugin_sensors_.push_back(std::move(type));
  // The module that senses every type's objects, with the first type.
  if (FindModule("plugin_sensors") == nullptr) RegisterModule(PluginSensorsModule());
}

}  // namespace swarmsim
