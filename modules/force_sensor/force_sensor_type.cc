// force_sensor: V-REP's force sensor, a rigid link between its parent shape
// and the first dynamic shape below it that measures the force and torque it
// transmits and breaks when they stay above a threshold (force_sensor.h).
#include <memory>

#include "framework/error.h"
#include "framework/object_type.h"
#include "framework/registry.h"
#include "framework/scene.h"
#include "framework/state_hash.h"
#include "modules/force_sensor/force_sensor.h"

namespace swarmsim::force_sensor {

// Its Lua API area (lua_api_force.cc).
void RegisterForceSensorApi(lua_State* L);

namespace {

constexpr ObjectKey kKeys[] = {
    {"filter_samples", "1",
     "readings are the mean of the last N samples (one per control step), 1..1000"},
    {"force_threshold", "none", "N, a step whose (filtered) |F| exceeds it is a violation"},
    {"torque_threshold", "none", "N m, likewise for |T|"},
    {"break_after", "1", "consecutive violating steps that break the link, 1..1000000"},
    {"noise", "0", "N, >= 0: std dev of Gaussian noise on each force component read"},
    {"noise_uniform", "0", "N, >= 0: half width of uniform noise on each force component read"},
    {"torque_noise", "0", "N m, >= 0: std dev of Gaussian noise on each torque component read"},
    {"torque_noise_uniform", "0",
     "N m, >= 0: half width of uniform noise on each torque component"},
    {"failure_probability", "0", "0..1: chance that a step's reading is missing (state 0)"},
};

std::unique_ptr<RowTable> MakeRows(const ObjectTypeDescriptor&) {
  return std::make_unique<Rows<ForceSensorData>>();
}

// A copy starts from the settings, unbroken and with no reading.
void Copy(const void* source, void* row) {
  const ForceSensorData& from = *static_cast<const ForceSensorData*>(source);
  ForceSensorData& to = *static_cast<ForceSensorData*>(row);
  to.filter_samples = from.filter_samples;
  to.force_threshold = from.force_threshold;
  to.torque_threshold = from.torque_threshold;
  to.break_after = from.break_after;
  to.force_noise = from.force_noise;
  to.torque_noise = from.torque_noise;
}

void Scale(const ObjectTypeDescriptor&, void* row, double s, ScaleContext*) {
  ForceSensorData& f = *static_cast<ForceSensorData*>(row);
  f.force_threshold *= s * s * s;
  f.torque_threshold *= s * s * s * s;
  for (double* v : {&f.force_noise.gaussian, &f.force_noise.uniform}) *v *= s * s * s;
  for (double* v : {&f.torque_noise.gaussian, &f.torque_noise.uniform}) *v *= s * s * s * s;
}

void Hash(const Scene& scene, ObjectType type, StateHasher* h) {
  const Rows<ForceSensorData>& sensors = scene.rows<ForceSensorData>(type);
  for (size_t r = 0; r < sensors.size(); ++r) {
    const ForceSensorData& f = sensors.rows[r];
    h->AddValue(sensors.owners[r]);
    h->AddValue(f.broken);
    h->AddValue(f.violations);
    h->AddValue(f.force);
    h->AddValue(f.torque);
  }
}

void Read(const ObjectTypeDescriptor&, const ObjectReader& r, void* row) {
  ForceSensorData& s = *static_cast<ForceSensorData*>(row);
  if (r.Has("filter_samples"))
    s.filter_samples = static_cast<int>(r.Integer("filter_samples", 1, 1000));
  if (r.Has("force_threshold")) s.force_threshold = r.Number("force_threshold", kPositive);
  if (r.Has("torque_threshold")) s.torque_threshold = r.Number("torque_threshold", kPositive);
  if (r.Has("break_after")) s.break_after = static_cast<int>(r.Integer("break_after", 1, 1000000));
  ReadNoise(r, "", 1e12, &s.force_noise);
  ReadNoise(r, "torque_", 1e12, &s.torque_noise);
  s.torque_noise.failure = s.force_noise.failure;  // one reading: both fail together
}

constinit const ObjectTypeDescriptor kForceSensorType{
    .name = "force_sensor",
    .description = "a breakable rigid link that measures the force and torque it transmits",
    .make_rows = MakeRows,
    .copy_row = Copy,
    .scale_row = Scale,
    .hash_rows = Hash,
    .keys = kKeys,
    .read = Read,
    .register_lua = RegisterForceSensorApi,
};

}  // namespace

const ForceSensorData& Row(const Scene& scene, ObjectId id) {
  ObjectType type;
  if (!scene.FindType(kForceSensorTypeName, &type))
    throw Error("the scene has no force sensor type (modules/force_sensor is not registered)");
  return scene.row<ForceSensorData>(type, id, "force sensor");
}

const ObjectTypeDescriptor& Descriptor() { return kForceSensorType; }

void Register(ModuleRegistry* registry) {
  registry->RegisterObjectType(std::make_shared<const ObjectTypeDescriptor>(kForceSensorType));
}

}  // namespace swarmsim::force_sensor
