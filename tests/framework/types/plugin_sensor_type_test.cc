// The plugin_sensor type (framework/types/plugin_sensor_type.cc): its
// `sensor` key names a sensor type a loaded plugin registers; a wrong name
// lists the registered ones and suggests the nearest.
#include <gtest/gtest.h>

#include <string>

#include "framework/error.h"
#include "framework/plugin_sensors.h"
#include "framework/registry.h"
#include "framework/types/core_types.h"
#include "tests/framework/error_of.h"
#include "tests/framework/fake_reader.h"

namespace swarmsim {
namespace {

using testing::ErrorOf;
using testing::FakeReader;

int Sense(const SwarmsimCallContext*, int64_t, double*, int, char*, size_t, void*) { return 0; }

std::string ReadSensor(const ModuleRegistry* registry, const std::string& name) {
  FakeReader reader{{"sensor", name}};
  reader.set_registry(registry);
  PluginSensorRow row;
  kPluginSensorType.read(kPluginSensorType, reader, &row);
  return row.sensor;
}

TEST(PluginSensorTypeTest, TheSensorKeyNamesARegisteredType) {
  ModuleRegistry registry;
  registry.RegisterPluginSensor({}, {"light", "", Sense, nullptr, 2});
  registry.RegisterPluginSensor({}, {"spectrum", "", Sense, nullptr, 256});
  EXPECT_EQ(ReadSensor(&registry, "spectrum"), "spectrum");
  EXPECT_EQ(ErrorOf([&] { ReadSensor(&registry, "lihgt"); }),
            "model.yaml:2:3: unknown plugin sensor type 'lihgt' (registered: light, spectrum); "
            "did you mean 'light'?");
  EXPECT_EQ(ErrorOf([&] { ReadSensor(&registry, "camera"); }),
            "model.yaml:2:3: unknown plugin sensor type 'camera' (registered: light, spectrum) "
            "(expected one of: light, spectrum)");
}

TEST(PluginSensorTypeTest, WithoutAPluginsSensorTypesTheMessageSaysSo) {
  ModuleRegistry empty;
  for (const ModuleRegistry* registry :
       std::initializer_list<const ModuleRegistry*>{&empty, nullptr})
    EXPECT_EQ(ErrorOf([&] { ReadSensor(registry, "light"); }),
              "model.yaml:2:3: unknown plugin sensor type 'light': no loaded plugin registers "
              "sensor types (plugins: [...])");
  EXPECT_CONTAINS(ErrorOf([] { kPluginSensorType.read(kPluginSensorType, FakeReader{}, nullptr); }),
                  "missing 'sensor'");
}

}  // namespace
}  // namespace swarmsim
