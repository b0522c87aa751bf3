#include "framework/plugin_world_api.h"

#include <variant>

#include "framework/plugin_object_type.h"
#include "framework/world.h"

namespace swarmsim {
namespace {

World& W(void* world) { return *static_cast<World*>(world); }

double WorldTime(void* world) { return W(world).time(); }

int ObjectPosition(void* world, int64_t object, double out[3]) {
  const Scene& scene = W(world).scene();
  const ObjectId id = ObjectId::FromInteger(object);
  if (!scene.IsValid(id)) return 0;
  const Vec3 p = scene.world_pose(id).p;
  out[0] = p.x, out[1] = p.y, out[2] = p.z;
  return 1;
}

int NumberParameter(void* world, int robot, const char* name, double* out) {
  const ParamValue* v = W(world).FindParameter(robot, name);
  if (v == nullptr || !std::holds_alternative<double>(*v)) return 0;
  *out = std::get<double>(*v);
  return 1;
}

int FindObject(void* world, int64_t from, const char* path, int64_t* out) {
  const Scene& scene = W(world).scene();
  ObjectId origin;
  if (from != 0) {
    origin = ObjectId::FromInteger(from);
    if (!scene.IsValid(origin)) return 0;
  }
  try {
    const ObjectId id = scene.FindObject(path != nullptr ? path : "", origin);
    if (id.IsNull()) return 0;
    *out = id.ToInteger();
    return 1;
  } catch (const std::exception&) {
    return 0;  // a malformed path
  }
}

int64_t RobotRoot(void* world, int robot) {
  const Scene& scene = W(world).scene();
  if (robot < 0 || robot >= static_cast<int>(scene.instances().size())) return 0;
  const ModelInstance& instance = scene.instance(robot);
  return instance.alive ? instance.root.ToInteger() : 0;
}

int ReadProximitySensor(void* world, int64_t sensor, double* distance) {
  const Scene& scene = W(world).scene();
  const ObjectId id = ObjectId::FromInteger(sensor);
  if (!scene.IsValid(id) || scene.type(id) != ObjectType::kProximitySensor) return -1;
  const ProximitySensorData& p = scene.proximity_sensor(id);
  if (!p.detected) return 0;
  *distance = p.distance;
  return 1;
}

int SetJointTargetVelocity(void* world, int robot, int64_t joint, double velocity) {
  Scene& scene = W(world).scene();
  const ObjectId id = ObjectId::FromInteger(joint);
  if (!scene.IsValid(id) || scene.type(id) != ObjectType::kJoint) return 0;
  if (scene.instance_of(id) != robot) return 0;
  scene.mutable_joint(id).target_velocity = velocity;
  return 1;
}

int64_t StepCount(void* world) { return W(world).step_count(); }
int RobotCount(void* world) { return W(world).robot_count(); }

int ObjectValues(void* world, int64_t object, double* out, int max) {
  const std::vector<double>* values =
      PluginObjectValues(W(world).scene(), ObjectId::FromInteger(object));
  if (values == nullptr) return -1;
  for (size_t k = 0; k < values->size() && static_cast<int>(k) < max; ++k) out[k] = (*values)[k];
  return static_cast<int>(values->size());
}

int ObjectsOfType(void* world, const char* type, int64_t* out, int max) {
  const Scene& scene = W(world).scene();
  ObjectType t;
  if (type == nullptr || !scene.FindType(type, &t)) return -1;
  int count = 0;
  for (uint32_t slot = 0; slot < scene.slot_count(); ++slot) {
    if (!scene.alive_at(slot) || scene.type_at(slot) != t) continue;
    if (count < max) out[count] = scene.IdAt(slot).ToInteger();
    ++count;
  }
  return count;
}

int RobotOf(void* world, int64_t object) {
  const Scene& scene = W(world).scene();
  const ObjectId id = ObjectId::FromInteger(object);
  return scene.IsValid(id) ? scene.instance_of(id) : -1;
}

int RecordMetric(void* world, int robot, const char* name, double value) {
  return W(world).RecordPluginMetric(robot, name != nullptr ? name : "", value) ? 0 : -1;
}

constexpr SwarmsimWorldApi kWorldApi = {
    WorldTime,   ObjectPosition,      NumberParameter,        FindObject,
    RobotRoot,   ReadProximitySensor, SetJointTargetVelocity, StepCount,
    RobotCount,  ObjectValues,        ObjectsOfType,          RobotOf,
    RecordMetric};

}  // namespace

const SwarmsimWorldApi* PluginWorldApi() { return &kWorldApi; }

}  // namespace swarmsim
