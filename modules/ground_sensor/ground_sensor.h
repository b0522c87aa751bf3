// ground_sensor: the floor under a point of a robot (the foot-bot's "base"
// and "motor" ground sensors, the e-puck's three: a forager finds its nest
// by it, a line follower its line), read from the world's floor layer
// (framework/floor_layer.h: the `floor:` section, modules/floor, with any
// paint on it) as a colour, a grey level or a binary value.
//
// framework/README.md's worked example of a sensor as one folder: its
// type (rows, keys, reader, scale, hash, visual) and Lua area in
// ground_sensor_type.cc, its sense-phase module in module.cc, and Register()
// the one line that adds them (modules/builtin.cc).
#pragma once

#include <cstdint>
#include <span>

#include "framework/math.h"
#include "framework/object_rows.h"
#include "framework/sensor_noise.h"
#include "framework/shared_settings.h"

namespace swarmsim {
class FloorLayer;
class ModuleRegistry;
class Scene;
}  // namespace swarmsim

namespace swarmsim::ground_sensor {

inline constexpr const char* kTypeName = "ground_sensor";

// What a sensor reads: the colour, the grey level of it, or 1/0 for a grey
// level at or above / below the threshold (light / dark).
enum class Mode : uint8_t { kColor, kGrey, kBinary };

// The grey level of a colour (ITU-R BT.601 luma, as ARGoS's ToGrayScale):
// 0.299 r + 0.587 g + 0.114 b, in 0..1; a grey colour (r = g = b) reads its
// own level exactly (white 1, not 0.9999...).
inline double Grey(const Vec3& rgb) {
  if (rgb.x == rgb.y && rgb.y == rgb.z) return rgb.x;
  return 0.299 * rgb.x + 0.587 * rgb.y + 0.114 * rgb.z;
}

// Settings: shared by the copies of one model entry (shared_settings.h).
struct GroundSensorSettings {  // 48 bytes
  double radius = 0.005;       // m: drawn as a disc this big
  double threshold = 0.5;      // binary: 1 when the (noisy) grey level is >= it
  NoiseSettings noise;         // on the grey level (each channel in colour mode); failure reads 0
  Mode mode = Mode::kGrey;
};
struct GroundSensorRow {  // 40 bytes
  Shared<GroundSensorSettings> settings;
  // State, at the last sense phase (hashed): the colour seen (grey and
  // binary sensors see no colour: value, value, value) and the value read
  // (colour: its grey level; grey; binary 0 or 1). Black and 0 before the
  // first sense phase and when the sensor fails.
  Vec3 color;
  double value = 0;
};

// The type's value in `scene`; false if the scene has no ground sensor type
// (a registry without the module).
bool FindSensorType(const Scene& scene, ObjectType* type);

// Reads rows [begin, end) of `rows` (the scene's ground sensors) from
// `floor` (null: every sensor reads black, 0). `seed` and `step` key the
// noise streams (framework/sensor_noise.h). The sense phase runs it on
// ranges of rows in parallel; each row is written by one call only.
void SenseRows(const Scene& scene, const FloorLayer* floor, uint64_t seed, int64_t step,
               Rows<GroundSensorRow>* rows, size_t begin, size_t end);

// The ground_sensor type, its Lua area (sim.readGroundSensor,
// sim.readGroundSensors) and the "ground_sensor" module that senses in
// every world.
void Register(ModuleRegistry* registry);

}  // namespace swarmsim::ground_sensor
