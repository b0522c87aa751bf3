// sim.* force sensors, the force_sensor type's Lua area (force_sensor.h).
//
// Readings are written in the physics phase and only read during the
// control phase, so any robot may read any sensor.
#include "framework/lua_api.h"
#include "framework/scene.h"
#include "modules/force_sensor/force_sensor.h"

namespace swarmsim::force_sensor {
namespace {

// sim.readForceSensor(h) -> state, {fx, fy, fz}, {tx, ty, tz}, as in
// CoppeliaSim: state bit 0 is set when a reading is available (a dynamics
// backend simulates the link), bit 1 when the link broke. Force (N) and
// torque (N m, about the sensor's origin) are what the parent exerts on the
// child, in the sensor's frame, averaged over filter_samples; zero with no
// reading or once broken.
int ReadForceSensor(lua_State* L) {
  const Scene& scene = *Context(L).scene;
  const ForceSensorData& sensor = Row(scene, CheckObject(L, 1));
  const int state = (sensor.has_reading && !sensor.broken ? 1 : 0) | (sensor.broken ? 2 : 0);
  lua_pushinteger(L, state);
  const bool live = sensor.has_reading && !sensor.broken;
  const double f[3] = {live ? sensor.force.x : 0, live ? sensor.force.y : 0,
                       live ? sensor.force.z : 0};
  const double t[3] = {live ? sensor.torque.x : 0, live ? sensor.torque.y : 0,
                       live ? sensor.torque.z : 0};
  PushNumberArray(L, f, 3);
  PushNumberArray(L, t, 3);
  return 3;
}

}  // namespace

void RegisterForceSensorApi(lua_State* L) {
  static constexpr luaL_Reg kFunctions[] = {
      {"readForceSensor", Guarded<ReadForceSensor, "sim.readForceSensor">},
      {nullptr, nullptr},
  };
  luaL_setfuncs(L, kFunctions, 0);
}

}  // namespace swarmsim::force_sensor
