// ground_sensor: the colour of the floor under a robot (an e-puck's or
// foot-bot's ground sensor: a foraging robot finds its nest by it), read
// from the world's floor layer (framework/floor_layer.h: the paint layer).
//
// framework/README.md's worked example of a sensor as one folder: its
// type (rows, key, reader, scale, hash, visual), its Lua area and its
// sense-phase module are all in ground_sensor.cc, and Register() is the one
// line that adds them (in modules/builtin.cc for a module of the tree; here
// the test registers it: tests/modules/ground_sensor/ground_sensor_test.cc).
#pragma once

#include "framework/math.h"
#include "framework/shared_settings.h"

namespace swarmsim {
class ModuleRegistry;
}

namespace swarmsim::ground_sensor {

inline constexpr const char* kTypeName = "ground_sensor";

// Settings: shared by the copies of one model entry (shared_settings.h).
struct GroundSensorSettings {
  double radius = 0.005;  // m: drawn as a disc this big
};
struct GroundSensorRow {  // 32 bytes
  Shared<GroundSensorSettings> settings;
  Vec3 seen;  // RGB 0..1, state: the floor under it at the last sense phase
};

// The ground_sensor type, its Lua area (sim.readGroundSensor) and the
// "ground_sensor" module that senses in every world.
void Register(ModuleRegistry* registry);

}  // namespace swarmsim::ground_sensor
