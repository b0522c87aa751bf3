// sim.* force sensors, the force_sensor type's Lua area (force_sensor.h).
//
// Readings are written in the physics phase and only read during the
// control phase, so any robot may read any sensor.
#include "framework/lua_api.h"
#include "framework/scene.h"
#include "framework/sensor_noise.h"
#include "framework/world.h"
#include "modules/force_sensor/force_sensor.h"

namespace swarmsim::force_sensor {
namespace {

// sim.readForceSensor(h) -> state, {fx, fy, fz}, {tx, ty, tz}, as in
// CoppeliaSim: state bit 0 is set when a reading is available (a dynamics
// backend simulates the link), bit 1 when the link broke. Force (N) and
// torque (N m, about the sensor's origin) are what the parent exerts on the
// child, in the sensor's frame, averaged over filter_samples; zero with no
// reading or once broken. With noise keys, each component has its noise
// and a failed step reads state 0 (no reading), zeros.
int ReadForceSensor(lua_State* L) {
  const Scene& scene = *Context(L).scene;
  const ObjectId id = CheckObject(L, 1);
  const ForceSensorData& sensor = Row(scene, id);
  bool live = sensor.has_reading && !sensor.broken;
  double f[3] = {live ? sensor.force.x : 0, live ? sensor.force.y : 0, live ? sensor.force.z : 0};
  double t[3] = {live ? sensor.torque.x : 0, live ? sensor.torque.y : 0,
                 live ? sensor.torque.z : 0};
  if (live && (sensor.force_noise.any() || sensor.torque_noise.any())) {
    const World& world = *Context(L).world;
    Rng rng =
        NoiseStream(world.settings().seed, id.index(), world.step_count(), NoisePurpose::kForce);
    if (Fails(sensor.force_noise, rng)) {
      live = false;
      for (int i = 0; i < 3; ++i) f[i] = t[i] = 0;
    } else {
      for (double& v : f) v = Perturb(sensor.force_noise, v, rng);
      for (double& v : t) v = Perturb(sensor.torque_noise, v, rng);
    }
  }
  const int state = (live ? 1 : 0) | (sensor.broken ? 2 : 0);
  lua_pushinteger(L, state);
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
