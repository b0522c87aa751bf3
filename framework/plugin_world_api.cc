#include "framework/plugin_world_api.h"

#include <cmath>
#include <span>
#include <variant>

#include "framework/device_access.h"
#include "framework/plugin_controllers.h"
#include "framework/plugin_object_type.h"
#include "framework/plugin_sensors.h"
#include "framework/proximity_readings.h"
#include "framework/range_and_bearing_access.h"
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
  const ProximityReadings* readings = W(world).proximity_readings();
  if (readings == nullptr) return -1;
  return readings->Read(W(world).scene(), ObjectId::FromInteger(sensor), distance);
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

// --- ABI 6 ---------------------------------------------------------------------------
// None of these may throw: they are called from C.

int ReadProximitySensors(void* world, const int64_t* sensors, int count, double* distances) {
  const Scene& scene = W(world).scene();
  const ProximityReadings* readings = W(world).proximity_readings();
  int detected = 0;
  bool all_sensors = true;
  for (int i = 0; i < count; ++i) {
    double distance = 0;
    const int read = readings != nullptr
                         ? readings->Read(scene, ObjectId::FromInteger(sensors[i]), &distance)
                         : -1;
    distances[i] = -1;
    if (read < 0) {
      all_sensors = false;
      continue;
    }
    if (read == 0) continue;
    distances[i] = distance;
    ++detected;
  }
  return all_sensors ? detected : -1;
}

int ReadPluginSensor(void* world, int64_t sensor, double* out, int max) {
  try {
    std::span<const double> values;
    if (!PluginSensorReading(W(world), ObjectId::FromInteger(sensor), &values)) return 0;
    for (size_t k = 0; k < values.size() && static_cast<int>(k) < max; ++k) out[k] = values[k];
    return static_cast<int>(values.size());
  } catch (const std::exception&) {
    return -1;  // not a plugin sensor
  }
}

// The joint `joint` of robot `robot`, or null.
JointData* OwnJoint(void* world, int robot, int64_t joint) {
  Scene& scene = W(world).scene();
  const ObjectId id = ObjectId::FromInteger(joint);
  if (!scene.IsValid(id) || scene.type(id) != ObjectType::kJoint) return nullptr;
  if (scene.instance_of(id) != robot) return nullptr;
  return &scene.mutable_joint(id);
}

int SetJointTargetPosition(void* world, int robot, int64_t joint, double position) {
  JointData* j = OwnJoint(world, robot, joint);
  if (j == nullptr || !std::isfinite(position)) return 0;
  j->target_position = position;
  return 1;
}

int JointState(void* world, int64_t joint, double* position, double* velocity) {
  const Scene& scene = W(world).scene();
  const ObjectId id = ObjectId::FromInteger(joint);
  if (!scene.IsValid(id) || scene.type(id) != ObjectType::kJoint) return 0;
  const JointData& j = scene.joint(id);
  if (position != nullptr) *position = j.position;
  if (velocity != nullptr) *velocity = j.velocity;
  return 1;
}

int Parameter(void* world, int robot, const char* name, SwarmsimValue* out) {
  if (name == nullptr || out == nullptr) return 0;
  const ParamValue* v = W(world).FindParameter(robot, name);
  if (v == nullptr) return 0;
  *out = {};
  if (const double* d = std::get_if<double>(v)) {
    out->type = kSwarmsimNumber, out->number = *d;
  } else if (const bool* b = std::get_if<bool>(v)) {
    out->type = kSwarmsimNumber, out->number = *b ? 1 : 0;
  } else {
    const std::string& text = std::get<std::string>(*v);
    out->type = kSwarmsimString, out->text = text.data(), out->size = text.size();
  }
  return 1;
}

int SendMessage(void* world, int robot, int scope, const char* data, size_t size, int64_t target,
                double range, int line_of_sight) {
  World& w = W(world);
  const Scene& scene = w.scene();
  constexpr size_t kMaxMessageBytes = 1 << 20;  // as sim.send*Message
  if (robot < 0 || robot >= w.robot_count() || !scene.instance(robot).alive ||
      (data == nullptr && size > 0) || size > kMaxMessageBytes || scope < kSwarmsimMessageGlobal ||
      scope > kSwarmsimMessageRange)
    return -1;
  Message m;
  m.scope = static_cast<MessageScope>(scope);  // same order as SwarmsimMessageScope
  if (m.scope == MessageScope::kDirect) {
    m.target = ObjectId::FromInteger(target);
    if (!scene.IsValid(m.target)) return -1;
  }
  if (m.scope == MessageScope::kRange) {
    if (!(range >= 0) || !std::isfinite(range)) return -1;
    m.range = range;
    m.line_of_sight = line_of_sight != 0;
  }
  // Charged to the robot's memory account, as a script's message is.
  RobotMail& mail = w.messaging().robot_mail(robot);
  const uint64_t bytes = size + sizeof(Message);
  if (mail.memory != nullptr && mail.memory->Charge(bytes) != ScriptMemory::kOk) return -1;
  try {
    m.data.assign(data != nullptr ? data : "", size);
    m.sender = scene.instance(robot).root;
    m.sender_instance = robot;
    mail.outbox.push_back(std::move(m));
  } catch (const std::exception&) {
    if (mail.memory != nullptr) mail.memory->Release(bytes);
    return -1;  // out of memory
  }
  return 0;
}

int ReceiveMessage(void* world, int robot, SwarmsimMessage* out) {
  PluginControllers* controllers = W(world).plugin_controllers();
  return controllers != nullptr ? controllers->Receive(robot, out) : 0;
}

double RandomUniform(void* world, int robot) {
  World& w = W(world);
  if (robot < 0 || robot >= w.robot_count()) return 0;
  return w.runtime(robot).rng.Uniform();
}

// The range_and_bearing module's world instance, if the world has one.
const RangeAndBearingAccess* Boards(World& w) {
  return dynamic_cast<const RangeAndBearingAccess*>(w.find_module("range_and_bearing"));
}

int SetRangeAndBearingData(void* world, int robot, int64_t board, const uint8_t* data,
                           size_t size) {
  World& w = W(world);
  const RangeAndBearingAccess* boards = Boards(w);
  if (boards == nullptr || (data == nullptr && size > 0)) return -1;
  return boards->SetData(&w.scene(), robot, ObjectId::FromInteger(board), data, size);
}

int ReadRangeAndBearing(void* world, int64_t board, SwarmsimRangeAndBearingReading* out, int max) {
  World& w = W(world);
  const RangeAndBearingAccess* boards = Boards(w);
  if (boards == nullptr) return -1;
  return boards->Read(w.scene(), ObjectId::FromInteger(board), out, out != nullptr ? max : 0);
}

// --- ABI 8 ---------------------------------------------------------------------------
// Each through the narrow service of the module that owns the device
// (framework/device_access.h): the framework names no module's types.

// The world's services, found when it started (framework/world.h).
const World::DeviceServices& Services(void* world) { return W(world).device_services(); }

int ReadSensorValue(void* world, int64_t sensor, double* value) {
  World& w = W(world);
  if (value == nullptr) return -1;
  const ObjectId id = ObjectId::FromInteger(sensor);
  for (const SensorValueAccess* s : {Services(world).light, Services(world).ground})
    if (s != nullptr && s->ReadValue(w.scene(), id, value) == 0) return 0;
  return -1;
}

int SetLed(void* world, int robot, int64_t led, double red, double green, double blue, int on) {
  const LedAccess* leds = Services(world).leds;
  if (leds == nullptr) return -1;
  return leds->SetLed(&W(world).scene(), robot, ObjectId::FromInteger(led), {red, green, blue},
                      on != 0);
}

int IrSend(void* world, int robot, int64_t ir, const uint8_t* data, size_t size) {
  const IrAccess* transceivers = Services(world).ir;
  if (transceivers == nullptr || (data == nullptr && size > 0)) return -1;
  return transceivers->Send(&W(world).scene(), robot, ObjectId::FromInteger(ir), data, size);
}

int IrSent(void* world, int64_t ir) {
  const IrAccess* transceivers = Services(world).ir;
  if (transceivers == nullptr) return -1;
  return transceivers->Sent(W(world).scene(), ObjectId::FromInteger(ir));
}

int IrReceive(void* world, int64_t ir, SwarmsimIrMessage* out, int max) {
  const IrAccess* transceivers = Services(world).ir;
  if (transceivers == nullptr) return -1;
  return transceivers->Receive(W(world).scene(), ObjectId::FromInteger(ir), out,
                               out != nullptr ? max : 0);
}

constexpr SwarmsimWorldApi kWorldApi = {WorldTime,
                                        ObjectPosition,
                                        NumberParameter,
                                        FindObject,
                                        RobotRoot,
                                        ReadProximitySensor,
                                        SetJointTargetVelocity,
                                        StepCount,
                                        RobotCount,
                                        ObjectValues,
                                        ObjectsOfType,
                                        RobotOf,
                                        RecordMetric,
                                        ReadProximitySensors,
                                        ReadPluginSensor,
                                        SetJointTargetPosition,
                                        JointState,
                                        Parameter,
                                        SendMessage,
                                        ReceiveMessage,
                                        RandomUniform,
                                        SetRangeAndBearingData,
                                        ReadRangeAndBearing,
                                        ReadSensorValue,
                                        SetLed,
                                        IrSend,
                                        IrSent,
                                        IrReceive};

}  // namespace

const SwarmsimWorldApi* PluginWorldApi() { return &kWorldApi; }

}  // namespace swarmsim
