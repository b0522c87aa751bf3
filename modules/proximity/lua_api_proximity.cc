// sim.* proximity sensors (the Lua area of the proximity_sensor type):
//   sim.readProximitySensor(h) and sim.readProximitySensors(handles [, out]);
//   sim.readProximityValue(h) and sim.readProximityValues(handles [, out]) for
//   sensors with a response curve (`response:`).
//
// Readings are written in the sense phase and only read during the control
// phase, so any robot may read any sensor.
#include <string>

#include "framework/error.h"
#include "framework/lua_api.h"
#include "framework/scene.h"
#include "modules/proximity/proximity_sensor.h"

namespace swarmsim::proximity {
namespace {

// sim.readProximitySensor(h) -> 0 when nothing is detected; else
// 1, distance (m), {x, y, z} (detected point in the sensor frame), handle of
// the detected object, {nx, ny, nz} (the surface normal there, sensor
// frame): CoppeliaSim's order. The no-detection path allocates nothing: a
// robot calls this for each of its sensors every step.
//
// The sensor `id`; the fast check first, Sensor() producing the message on
// a bad handle.
const ProximitySensorData& SensorOf(const Scene& scene, ObjectId id) {
  const ProximitySensorData* sensor = FindSensor(scene, id);
  return sensor != nullptr ? *sensor : Sensor(scene, id);
}

int ReadProximitySensor(lua_State* L) {
  const Scene& scene = *Context(L).scene;
  const ProximitySensorData& sensor = SensorOf(scene, CheckObject(L, 1));
  if (!sensor.detected) {
    lua_pushinteger(L, 0);
    return 1;
  }
  lua_pushinteger(L, 1);
  lua_pushnumber(L, sensor.distance);
  const Vec3 p = sensor.p_SD();
  const double p_SD[3] = {p.x, p.y, p.z};
  PushNumberArray(L, p_SD, 3);
  lua_pushinteger(L, sensor.detected_object.IsNull() ? -1 : sensor.detected_object.ToInteger());
  const double n_S[3] = {sensor.normal.x, sensor.normal.y, sensor.normal.z};
  PushNumberArray(L, n_S, 3);
  return 5;
}

// sim.readProximitySensors(handles [, distances]) -> count, distances: the
// distance (m) each sensor of the array `handles` reads, as the second
// result of sim.readProximitySensor(handles[i]), or -1 when it detects
// nothing; `count`: how many detect something. The distances go into
// `distances` (entries 1 .. #handles overwritten, the rest left alone),
// reused in place from step to step so that the call allocates nothing, or
// into a new table when it is absent or nil.
int ReadProximitySensors(lua_State* L) {
  const Scene& scene = *Context(L).scene;
  lua_Integer count = 0;
  FillFromHandles(L, [&](ObjectId id) {
    const ProximitySensorData& sensor = SensorOf(scene, id);
    if (sensor.detected) {
      ++count;
      lua_pushnumber(L, sensor.distance);
    } else {
      lua_pushinteger(L, -1);
    }
  });
  lua_pushinteger(L, count);
  lua_insert(L, 2);
  return 2;
}

// The value of a sensor with a response curve: its last reading's, or the
// curve's far end when it detects nothing. A sensor without one is an error
// naming it (throws: Guarded and FillFromHandles turn it into a Lua error).
double ValueOf(const Scene& scene, ObjectId id) {
  const ProximitySensorData& sensor = SensorOf(scene, id);
  const ProximitySensorSettings& settings = *sensor.settings;
  if (!settings.has_response())
    throw Error("proximity sensor " + scene.PathOf(id) +
                " has no 'response' curve (worlds/README.md, proximity_sensor): read its "
                "distance with sim.readProximitySensor");
  return sensor.detected ? static_cast<double>(sensor.value) : settings.response.back().second;
}

// sim.readProximityValue(h) -> the sensor's value on its response curve
// (the far end's value when it detects nothing).
int ReadProximityValue(lua_State* L) {
  lua_pushnumber(L, ValueOf(*Context(L).scene, CheckObject(L, 1)));
  return 1;
}

// sim.readProximityValues(handles [, values]) -> values: each sensor's
// sim.readProximityValue, into `values` (entries 1 .. #handles, reused in
// place: no allocation) or a new table.
int ReadProximityValues(lua_State* L) {
  const Scene& scene = *Context(L).scene;
  FillFromHandles(L, [&](ObjectId id) { lua_pushnumber(L, ValueOf(scene, id)); });
  return 1;
}

}  // namespace

void RegisterProximityApi(lua_State* L) {
  static constexpr luaL_Reg kFunctions[] = {
      {"readProximitySensor", Guarded<ReadProximitySensor, "sim.readProximitySensor">},
      {"readProximitySensors", Guarded<ReadProximitySensors, "sim.readProximitySensors">},
      {"readProximityValue", Guarded<ReadProximityValue, "sim.readProximityValue">},
      {"readProximityValues", Guarded<ReadProximityValues, "sim.readProximityValues">},
      {nullptr, nullptr},
  };
  luaL_setfuncs(L, kFunctions, 0);
}

}  // namespace swarmsim::proximity
