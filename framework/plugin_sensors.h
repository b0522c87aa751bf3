// Plugin sensors (framework/plugin_api.h, SwarmsimSensorFunction) as a
// module: the objects of type plugin_sensor, sensed in the sense
// phase after the proximity sensors, robot by robot in parallel. Each type's
// reading has its own size (max_values numbers), kept in one flat buffer.
#pragma once

#include <span>
#include <string>

#include "framework/handle.h"
#include "framework/module.h"

namespace swarmsim {

// The row of an object of type plugin_sensor (framework/types/): the name
// of its sensor type, as the model file gives it.
struct PluginSensorRow {
  std::string sensor;
};

// "plugin_sensors": kind "sensor", sense phase, order 200, every world.
// ModuleRegistry::RegisterPluginSensor registers it with the first type.
ModuleDescriptor PluginSensorsModule();

// The last reading of the plugin sensor `id` into *values: false before its
// first sense phase. Throws swarmsim::Error if `id` is not a plugin sensor.
bool PluginSensorReading(const World& world, ObjectId id, std::span<const double>* values);

}  // namespace swarmsim
