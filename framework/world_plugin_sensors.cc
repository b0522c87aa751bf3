// Plugin sensors (framework/plugin_api.h, SwarmsimSensorFunction): dummies
// tagged with a registered sensor type, sensed robot by robot in parallel.
#include <algorithm>
#include <string>
#include <utility>

#include "framework/error.h"
#include "framework/plugin_world_api.h"
#include "framework/registry.h"
#include "framework/scheduler.h"
#include "framework/world.h"

namespace swarmsim {

static_assert(SWARMSIM_SENSOR_MAX_VALUES == 16, "World::PluginSensorState::values");

namespace {}  // namespace

void World::IndexPluginSensors() {
  std::vector<std::pair<int, uint32_t>> found;  // (robot or -1, slot)
  for (uint32_t slot = 0; slot < scene_.slot_count(); ++slot) {
    if (!scene_.alive_at(slot) || scene_.type_at(slot) != ObjectType::kDummy) continue;
    if (scene_.ReadCustomData(scene_.IdAt(slot), kPluginSensorTag) == nullptr) continue;
    found.emplace_back(scene_.instance_of_at(slot), slot);
  }
  // Robots in order, the scene's objects (-1) last.
  std::stable_sort(found.begin(), found.end(), [](const auto& a, const auto& b) {
    return static_cast<unsigned>(a.first) < static_cast<unsigned>(b.first);
  });
  const size_t robots = scene_.instances().size();
  plugin_sensors_.clear();
  plugin_sensor_start_.assign(robots + 2, 0);
  plugin_sensor_of_slot_.assign(scene_.slot_count(), -1);
  for (const auto& [robot, slot] : found) {
    const ObjectId id = scene_.IdAt(slot);
    const std::string& name = *scene_.ReadCustomData(id, kPluginSensorTag);
    PluginSensorState state;
    state.id = id;
    state.type = registry_.FindPluginSensor(name);
    if (state.type == nullptr)
      throw Error("object " + scene_.PathOf(id) + " is a plugin sensor of type '" + name +
                  "', which no loaded plugin registers");
    plugin_sensor_of_slot_[slot] = static_cast<int32_t>(plugin_sensors_.size());
    plugin_sensors_.push_back(state);
    ++plugin_sensor_start_[robot >= 0 ? robot + 1 : robots + 1];
  }
  for (size_t r = 1; r < plugin_sensor_start_.size(); ++r)
    plugin_sensor_start_[r] += plugin_sensor_start_[r - 1];
  plugin_sensor_version_ = scene_.structure_version();
}

void World::SensePluginSensors() {
  if (plugin_sensor_version_ != scene_.structure_version()) IndexPluginSensors();
  if (plugin_sensors_.empty()) return;
  const auto& instances = scene_.instances();
  const int robots = static_cast<int>(instances.size());
  auto sense = [&](int robot, std::string* error) {
    const SwarmsimCallContext context{robot, 0, this, PluginWorldApi()};
    const size_t end = plugin_sensor_start_[robot >= 0 ? robot + 1 : robots + 1];
    for (size_t i = plugin_sensor_start_[robot >= 0 ? robot : robots]; i < end; ++i) {
      PluginSensorState& s = plugin_sensors_[i];
      char message[512] = {0};
      const int n = s.type->function(&context, s.id.ToInteger(), s.values.data(),
                                     static_cast<int>(s.values.size()), message, sizeof message,
                                     s.type->user_data);
      if (n < 0 || n > static_cast<int>(s.values.size())) {
        *error = "plugin sensor '" + s.type->name + "' (" + scene_.PathOf(s.id) + "): " +
                 (n < 0 ? (message[0] ? message : "the sense function failed")
                        : "returned " + std::to_string(n) + " values, at most " +
                              std::to_string(s.values.size()) + " fit");
        return;
      }
      s.count = n;
    }
  };
  // The lowest robot's error wins, whatever the thread count.
  std::vector<std::string> errors(robots + 1);
  scheduler_->ParallelFor(0, robots, kRobotGrain, [&](int64_t begin, int64_t end) {
    for (int64_t r = begin; r < end; ++r)
      if (instances[r].alive && plugin_sensor_start_[r] != plugin_sensor_start_[r + 1])
        sense(static_cast<int>(r), &errors[r]);
  });
  sense(-1, &errors[robots]);
  for (const std::string& e : errors)
    if (!e.empty()) throw Error(e);
}

bool World::PluginSensorReading(ObjectId id, std::span<const double>* values) const {
  const uint32_t slot = scene_.SlotOf(id, "plugin sensor");
  if (scene_.type_at(slot) != ObjectType::kDummy ||
      scene_.ReadCustomData(id, kPluginSensorTag) == nullptr)
    throw Error("object " + scene_.PathOf(id) + " is not a plugin sensor");
  // Not indexed yet (added since the last sense phase): no reading.
  if (slot >= plugin_sensor_of_slot_.size() || plugin_sensor_of_slot_[slot] < 0) return false;
  const PluginSensorState& s = plugin_sensors_[plugin_sensor_of_slot_[slot]];
  if (s.id != id || s.count < 0) return false;
  *values = std::span<const double>(s.values.data(), static_cast<size_t>(s.count));
  return true;
}

}  // namespace swarmsim
