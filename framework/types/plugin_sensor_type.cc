// plugin_sensor: a sensor of a type a loaded plugin registers
// (add_sensor_type, framework/plugin_api.h), sensed by the plugin_sensors
// module (framework/plugin_sensors.h). Its row names the sensor type.
#include <string>
#include <vector>

#include "framework/object_type.h"
#include "framework/plugin_sensors.h"
#include "framework/registry.h"
#include "framework/suggest.h"
#include "framework/types/core_types.h"

namespace swarmsim {

// Its Lua API area (framework/lua_api_plugins.cc): sim.readPluginSensor.
void RegisterPluginSensorApi(lua_State* L);

namespace {

constexpr ObjectKey kKeys[] = {
    {"sensor", "required", "the sensor type, one a loaded plugin registers (plugins: [...])"},
};

std::unique_ptr<RowTable> MakeRows(const ObjectTypeDescriptor&) {
  return std::make_unique<Rows<PluginSensorRow>>();
}

void Read(const ObjectTypeDescriptor&, const ObjectReader& r, void* row) {
  const std::string name = r.String("sensor", /*required=*/true);
  std::vector<std::string> known;
  if (const ModuleRegistry* registry = r.registry()) {
    if (registry->FindPluginSensor(name) != nullptr) {
      static_cast<PluginSensorRow*>(row)->sensor = name;
      return;
    }
    for (const PluginSensorType& t : registry->plugin_sensors()) known.push_back(t.name);
  }
  if (known.empty())
    r.Fail("sensor", "unknown plugin sensor type '" + name +
                         "': no loaded plugin registers sensor types (plugins: [...])");
  std::string list;
  for (const std::string& k : known) list += (list.empty() ? "" : ", ") + k;
  r.Fail("sensor", "unknown plugin sensor type '" + name + "' (registered: " + list + ")" +
                       Suggest(name, known));
}

}  // namespace

const ObjectTypeDescriptor kPluginSensorType{
    .name = "plugin_sensor",
    .description = "a sensor of a type a loaded plugin registers; readings of any size",
    .make_rows = MakeRows,
    .keys = kKeys,
    .read = Read,
    .register_lua = RegisterPluginSensorApi,
};

}  // namespace swarmsim
