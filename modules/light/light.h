// modules/light: light sources and the light sensors that read them
// (ARGoS's light entity and foot-bot / e-puck light sensors), built in.
//
// A `light_source` is a point light at its object's origin (its height is
// its z): an intensity and a switch that scripts change
// (sim.setLightSourceIntensity, sim.setLightSourceOn), and a colour it is
// drawn in (snapshots, video, the viewer: its type's visual, a glowing
// sphere). A `light_sensor` reads, every sense phase, the light arriving
// along its +x axis from every light source that is on:
//
//   reading = sum over lights of  intensity / d^2 * response(theta)
//   response(theta) = 1 - theta / (fov / 2)  for theta < fov / 2, else 0
//
// d (m) the distance from the sensor's origin to the light (at least 1 mm),
// theta the angle between the sensor's +x and the direction to the light
// (3D). With the default fov of 180 degrees the response is ARGoS's foot-bot
// light sensor's (1 - 2 theta / pi, zero behind), and the distance term
// the inverse-square law of a point source (an intensity of 1 reads 1 at
// 1 m straight ahead). A light is left out when it is beyond the sensor's
// `range` (0: any distance), belongs to the sensor's own robot, or is
// hidden: by a static shape or the environment map (the world's line of
// sight, framework/line_of_sight.h; `occlusion`) and, with
// `robot_occlusion`, by other robots' bodies and dynamic shapes (exact ray
// tests, modules/proximity/ray_cast.h). Then the noise keys
// (framework/sensor_noise.h): failure reads 0, Gaussian and uniform noise
// are added, the result is clamped to >= 0 and to `saturation` (if set).
//
// Public: the rows, for tests, benchmarks and the Python arrays; scripts use
// sim.readLightSensor / sim.readLightSensors.
#pragma once

#include <cstdint>
#include <span>

#include "framework/handle.h"
#include "framework/math.h"
#include "framework/sensor_noise.h"
#include "framework/shared_settings.h"

namespace swarmsim {
class ModuleRegistry;
class Scene;
}  // namespace swarmsim

namespace swarmsim::light {

inline constexpr const char* kLightSourceTypeName = "light_source";
inline constexpr const char* kLightSensorTypeName = "light_sensor";

// What does not change per copy (shared by the copies of a model entry).
struct LightSourceSettings {
  Vec3 color{1, 1, 1};   // RGB 0..1: how it is drawn (sensors read intensity only)
  double radius = 0.02;  // m: the sphere it is drawn as
};
struct LightSourceRow {                  // 24 bytes
  Shared<LightSourceSettings> settings;  // Edit() to change one copy's
  double intensity = 1;                  // >= 0, state: scripts dim it (hashed)
  bool on = true;                        // state: scripts switch it (hashed)
  bool lit() const { return on && intensity > 0; }
};

struct LightSensorSettings {
  double fov = 3.141592653589793;  // rad, (0, 2 pi]: full width of the cone about +x it reads
  double range = 0;                // m: lights farther are not read (0: any distance)
  bool occlusion = true;           // static shapes and the map hide lights
  bool robot_occlusion = false;    // other robots' bodies (and dynamic shapes) hide lights
  double saturation = 0;           // the reading's maximum (0: none)
  NoiseSettings noise;             // noise, noise_uniform, failure_probability
};
struct LightSensorRow {                  // 16 bytes
  Shared<LightSensorSettings> settings;  // Edit() to change one copy's
  double reading = 0;                    // state: written in the sense phase (hashed)
};

// The light sensors' rows (empty if the type is not registered), and the
// slot of each row's object in *owners.
std::span<const LightSensorRow> Sensors(const Scene& scene, std::span<const uint32_t>* owners);
// The sensor `id`, or null if it is not a light sensor.
const LightSensorRow* FindSensor(const Scene& scene, ObjectId id);
// Whether the scene has the light_sensor type, and its value.
bool FindSensorType(const Scene& scene, ObjectType* type);

// The types light_source and light_sensor, their Lua area and the "light"
// sense-phase module.
void Register(ModuleRegistry* registry);

}  // namespace swarmsim::light
