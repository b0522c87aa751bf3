// modules/proximity's public header for what reads or writes proximity
// sensors from outside the module (the recorder, the Python module, graphs,
// the plugins' world API, tests and benchmarks): the `proximity_sensor`
// type's rows and how to find them in a Scene. The type itself (keys,
// reader, hash, Lua area) is the module's (proximity_sensor_type.cc); it is
// registered by proximity::Register (proximity.h).
//
// The lookups below are inline and name the type by its name only (no
// symbol of the module), so the framework's plugin world API can read
// readings without linking the module.
#pragma once

#include <cstdint>
#include <cstring>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "framework/handle.h"
#include "framework/math.h"
#include "framework/object_rows.h"
#include "framework/scene.h"
#include "framework/sensor_noise.h"
#include "framework/shared_settings.h"

namespace swarmsim {

struct ObjectTypeDescriptor;

// The detection volume of a proximity sensor (volume.h): a ray along +z
// (V-REP's convention), random rays in a cone about +z, or a solid volume
// (cone, pyramid, cylinder about +z; disc: a sector in the xy plane about +x).
enum class ProximityVolume : uint8_t { kRay, kRandomizedRay, kCone, kPyramid, kCylinder, kDisc };
const char* ToString(ProximityVolume volume);

// A proximity sensor's settings: constant while it runs, shared by every
// copy made from one model entry (framework/shared_settings.h; Edit() is
// copy on write).
struct ProximitySensorSettings {
  double range = 0.1;  // m: nothing farther than this is detected
  ProximityVolume volume = ProximityVolume::kRay;
  double angle = 0.5235987755982988;    // rad: cone, randomized_ray half-angle; disc half sector
  double angle_y = 0.5235987755982988;  // rad: pyramid half-angle about y (angle: about x)
  double radius = 0.05;                 // m: cylinder
  double thickness = 0.01;              // m: disc, along z
  double blind_zone = 0;                // m: the volume starts at this distance along its axis
  double max_detection_angle = 3.141592653589793;  // rad: reflectance cut-off (pi: none)
  uint16_t ray_count = 16;                         // randomized_ray
  bool detect_front = true;  // meshes: faces seen from outside (counter-clockwise)
  bool detect_back = true;   // meshes: faces seen from inside
  // What the sensor detects: a collection's or object subtree's path
  // (framework/collections.h), resolved from the sensor; empty: everything.
  std::string detectable;
  std::string detectable_where;  // "file:line:column" of `detectable`, for errors
  // Noise on the distance of a detection and failure (framework/sensor_noise.h:
  // `noise`, `noise_uniform`, `failure_probability`): a detected distance d
  // reads clamp(d + noise, 0, range); a failed sensor detects nothing.
  NoiseSettings noise;
  // The response curve (`response:`, a real IR sensor's raw value against
  // distance): [distance (m), value] pairs, distances strictly increasing,
  // interpolated linearly; nearer than the first: the first value; nothing
  // detected (or farther than the last): the last value. Empty: the sensor
  // reads distances only (no value), as before. With a response, `noise`
  // and `noise_uniform` perturb the value, not the distance.
  std::vector<std::pair<double, double>> response;
  // The value's part above the far end scales with cos(angle of incidence)
  // (Lambertian reflection; `response_incidence: lambertian`), or not (`none`).
  bool response_lambertian = true;
  bool has_response() const { return !response.empty(); }
  // The table's value at distance `d` (m), cosine of incidence `cos_i`.
  double ResponseAt(double d, double cos_i) const {
    const auto& t = response;
    const double far = t.back().second;
    double v = far;
    if (d <= t.front().first) {
      v = t.front().second;
    } else {
      for (size_t i = 1; i < t.size(); ++i)
        if (d < t[i].first) {
          const double f = (d - t[i - 1].first) / (t[i].first - t[i - 1].first);
          v = t[i - 1].second + f * (t[i].second - t[i - 1].second);
          break;
        }
    }
    if (response_lambertian) v = far + (v - far) * (cos_i < 0 ? 0.0 : cos_i > 1 ? 1.0 : cos_i);
    return v;
  }
  // The table's smallest and largest values (noise clamps to them).
  double ResponseMin() const {
    double m = response.front().second;
    for (const auto& [d, v] : response) m = v < m ? v : m;
    return m;
  }
  double ResponseMax() const {
    double m = response.front().second;
    for (const auto& [d, v] : response) m = v > m ? v : m;
    return m;
  }
};

// A proximity sensor: its shared settings and its reading (80 bytes; a
// robot's control step reads all of its sensors' rows; `value` sits in the
// padding after `detected`).
struct ProximitySensorData {
  Shared<ProximitySensorSettings> settings;
  // Reading, written in the sense phase:
  double distance = 0;       // m, from the sensor's origin to the detected point
  ObjectId detected_object;  // shape that was hit
  bool detected = false;
  // A sensor with a response curve: its value (the curve at the distance,
  // with noise), also when nothing is detected (the far end). Else 0.
  float value = 0;
  // The detected point (volumes; a ray's is on +z, see p_SD()) and the
  // outward surface normal there, in the sensor frame.
  Vec3 point, normal;
  double range() const { return settings->range; }
  ProximityVolume volume() const { return settings->volume; }
  // The detected point in the sensor frame: for a ray, on its +z axis.
  Vec3 p_SD() const { return volume() == ProximityVolume::kRay ? Vec3{0, 0, distance} : point; }
};
static_assert(sizeof(ProximitySensorData) <= 80, "a proximity reading stays 80 bytes");

namespace proximity {

inline constexpr char kSensorTypeName[] = "proximity_sensor";

// The type's value in `scene`; false if the scene has no proximity sensor
// type (a world whose registry lacks the module).
inline bool FindSensorType(const Scene& scene, ObjectType* type) {
  return scene.FindType(kSensorTypeName, type);
}

// Is the object at `slot` (live) a proximity sensor? The type's name is
// kSensorTypeName itself (one pointer compare: scripts read every sensor
// every step), or, from another registration, equal to it.
inline bool IsSensorAt(const Scene& scene, uint32_t slot) {
  const char* name = scene.type_name(scene.type_at(slot));
  return name == kSensorTypeName || std::strcmp(name, kSensorTypeName) == 0;
}

// Every proximity sensor's row (row r belongs to the object at slot
// owners[r]); an empty table if the scene has no such type.
inline const Rows<ProximitySensorData>& Sensors(const Scene& scene) {
  static const Rows<ProximitySensorData> kNone;
  ObjectType type;
  return FindSensorType(scene, &type) ? scene.rows<ProximitySensorData>(type) : kNone;
}

// The row of the proximity sensor `id`, or null if `id` is not a live
// proximity sensor (no exception: the plugins' C API).
inline const ProximitySensorData* FindSensor(const Scene& scene, ObjectId id) {
  if (!scene.IsValid(id)) return nullptr;
  const uint32_t slot = id.index();
  if (!IsSensorAt(scene, slot)) return nullptr;
  return &scene.rows<ProximitySensorData>(scene.type_at(slot)).rows[scene.row_at(slot)];
}

// --- Defined in the module (link swarmsim_proximity) ---------------------------------

// The type's descriptor (proximity_sensor_type.cc).
const ObjectTypeDescriptor& SensorTypeDescriptor();
// The type's value in `scene`, registering it first when the scene lacks it
// (a Scene made without a World: tests, benchmarks).
ObjectType SensorType(Scene* scene);
// A proximity sensor `name` under `parent` (null: a root) at X_PO.
ObjectId AddSensor(Scene* scene, std::string name, ObjectId parent, const Pose& X_PO,
                   const ProximitySensorData& sensor);
// The row of the proximity sensor `id`. Throws swarmsim::Error for a stale
// handle ("proximity sensor handle 12 does not exist") or another type
// ("object 'x' is a shape, not a proximity_sensor").
const ProximitySensorData& Sensor(const Scene& scene, ObjectId id);
ProximitySensorData& MutableSensor(Scene* scene, ObjectId id);
// Every proximity sensor's row, to write (registering the type first when
// the scene lacks it).
Rows<ProximitySensorData>& MutableSensors(Scene* scene);

}  // namespace proximity
}  // namespace swarmsim
