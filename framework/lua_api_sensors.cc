// sim.* sensors: proximity sensors.
//
// Readings are written in the sense phase and only read during the control
// phase, so any robot may read any sensor.
#include "framework/lua_api.h"
#include "framework/scene.h"

namespace swarmsim {
namespace {

// sim.readProximitySensor(h) -> 0 when nothing is detected; else
// 1, distance (m), {x, y, z} (detected point in the sensor frame), handle of
// the detected object, {nx, ny, nz} (the surface normal there, sensor
// frame): CoppeliaSim's order. The no-detection path allocates nothing: a
// robot calls this for each of its sensors every step.
int ReadProximitySensor(lua_State* L) {
  const Scene& scene = *Context(L).scene;
  const ObjectId id = CheckObject(L, 1);
  // Fast check; the Scene's accessor produces the message on a bad handle.
  const ProximitySensorData& sensor =
      scene.IsValid(id) && scene.type_at(id.index()) == ObjectType::kProximitySensor
          ? scene.proximity_sensors()[scene.row_at(id.index())]
          : scene.proximity_sensor(id);
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
  const double n_S[3] = {sensor.more->normal.x, sensor.more->normal.y, sensor.more->normal.z};
  PushNumberArray(L, n_S, 3);
  return 5;
}

}  // namespace

void RegisterSensorsApi(lua_State* L) {
  static constexpr luaL_Reg kFunctions[] = {
      {"readProximitySensor", Guarded<ReadProximitySensor, "sim.readProximitySensor">},
      {nullptr, nullptr},
  };
  luaL_setfuncs(L, kFunctions, 0);
}

}  // namespace swarmsim
