// Force sensors (V-REP's force sensor object): a rigid link between the
// sensor's parent shape and its child shape that measures the force and
// torque it transmits and breaks when they stay above a threshold. The
// force_sensor module's public header: the type's rows and how the
// dynamics backends and the graphs find them; the type descriptor
// (force_sensor_type.cc) and its Lua area (lua_api_force.cc) are the
// folder's own.
//
// The dynamics backend simulates the link (ODE: a fixed joint with feedback;
// Box2D: a weld joint) and hands one raw sample per control step to
// RecordForceSensorSample; averaging and breaking are the same for every
// backend. A backend that does not simulate the link leaves has_reading false.
#pragma once

#include <cmath>
#include <cstdint>
#include <vector>

#include "framework/math.h"
#include "framework/object_rows.h"
#include "framework/scene.h"
#include "framework/sensor_noise.h"

namespace swarmsim {

class ModuleRegistry;
struct ObjectTypeDescriptor;

inline constexpr const char* kForceSensorTypeName = "force_sensor";

struct ForceSensorData {
  // Settings.
  int filter_samples = 1;              // readings are the mean of the last N samples (1..1000)
  double force_threshold = INFINITY;   // N, |F| above it counts as a violation
  double torque_threshold = INFINITY;  // N m, |T| above it counts as a violation
  int break_after = 1;                 // consecutive violating steps that break the link
  // Noise on what scripts read (sim.readForceSensor), not on the link: per
  // component of force (N) and torque (N m), and failure (no reading that
  // step), drawn at read time from the stream of (seed, slot, step)
  // (framework/sensor_noise.h), so two reads in one step agree.
  NoiseSettings force_noise, torque_noise;
  // State, written by the dynamics backend in the physics phase.
  bool has_reading = false;  // a backend simulates the link and sampled it
  bool broken = false;       // the link broke: parent and child move apart
  int violations = 0;        // consecutive violating steps so far
  Vec3 force;                // N, filtered, in the sensor frame: parent on child
  Vec3 torque;               // N m, filtered, in the sensor frame, about the sensor origin
  std::vector<Vec3> force_samples, torque_samples;  // ring buffers (filter_samples)
  uint32_t next_sample = 0;
};

// Adds one raw sample (sensor frame), updates the filtered reading and the
// violation count, and sets `broken` when the count reaches break_after.
// Returns true if the link broke with this sample.
bool RecordForceSensorSample(ForceSensorData* sensor, const Vec3& force_S, const Vec3& torque_S);

namespace force_sensor {

// The scene's force sensor rows (row r belongs to the object at slot
// owners[r]), or null when the type is not registered (a bare Scene).
inline Rows<ForceSensorData>* RowsOf(Scene* scene) {
  ObjectType type;
  return scene->FindType(kForceSensorTypeName, &type) ? &scene->rows<ForceSensorData>(type)
                                                      : nullptr;
}
inline const Rows<ForceSensorData>* RowsOf(const Scene& scene) {
  ObjectType type;
  return scene.FindType(kForceSensorTypeName, &type) ? &scene.rows<ForceSensorData>(type) : nullptr;
}
// Whether the scene has any force sensor.
inline bool Any(const Scene& scene) {
  const Rows<ForceSensorData>* rows = RowsOf(scene);
  return rows != nullptr && !rows->rows.empty();
}
// The force sensor type of `scene`, if registered (null otherwise): a
// backend walking the tree compares type_at(slot) with it.
inline bool FindType(const Scene& scene, ObjectType* type) {
  return scene.FindType(kForceSensorTypeName, type);
}
// The row of force sensor `id`; throws swarmsim::Error for a stale handle
// or another type.
const ForceSensorData& Row(const Scene& scene, ObjectId id);

// The type's descriptor (a bare Scene registers it: Scene::RegisterType).
const ObjectTypeDescriptor& Descriptor();
// Registers the force_sensor object type with its Lua area (modules/builtin.cc).
void Register(ModuleRegistry* registry);

}  // namespace force_sensor

}  // namespace swarmsim
