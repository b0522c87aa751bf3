// sim.* light sources and light sensors (the Lua area of both types):
//   sim.setLightSourceOn(h, on)                 switches it, keeping its intensity
//   sim.setLightSourceIntensity(h, intensity)   >= 0 (0: dark, still on)
//   sim.getLightSource(h) -> intensity, on
//   sim.readLightSensor(h) -> reading
//   sim.readLightSensors(handles [, readings]) -> readings
// A robot's scripts may switch and dim only their own robot's light
// sources (scene scripts: any): the sensors read them in the next sense
// phase, after every script of the step has run, so a light switched off
// in step t reads 0 from step t + 1. Readings are written in the sense
// phase only, so any script may read any sensor.
#include <cmath>
#include <cstdio>
#include <string>

#include "framework/error.h"
#include "framework/lua_api.h"
#include "framework/scene.h"
#include "modules/light/light.h"
#include "modules/light/module.h"

namespace swarmsim::light {

namespace {

// "0.5", "1e+30", "nan" (0/0 printed "-nan"), "inf".
std::string NumberText(double value) {
  if (std::isnan(value)) return "nan";
  char text[32];
  std::snprintf(text, sizeof text, "%g", value);
  return text;
}

// The light source at argument 1, if the calling script may change it.
LightSourceRow& OwnSource(lua_State* L, const char* verb) {
  const LuaContext& c = Context(L);
  Scene& scene = *c.scene;
  ObjectType type;
  scene.FindType(kLightSourceTypeName, &type);  // registered with these functions
  const ObjectId id = CheckObject(L, 1);
  LightSourceRow& light = scene.row<LightSourceRow>(type, id, "light source");
  if (verb != nullptr && c.instance >= 0 && scene.instance_of(id) != c.instance)
    throw Error("a robot's script may " + std::string(verb) + " only its own light sources ('" +
                scene.PathOf(id) + "' belongs to another robot or to the scene)");
  return light;
}

int SetLightSourceOn(lua_State* L) {
  LightSourceRow& light = OwnSource(L, "switch");
  ArgType(L, 2, LUA_TBOOLEAN);
  light.on = lua_toboolean(L, 2) != 0;
  return 0;
}

int SetLightSourceIntensity(lua_State* L) {
  LightSourceRow& light = OwnSource(L, "dim");
  const double intensity = ArgNumber(L, 2);
  if (!(intensity >= 0 && std::isfinite(intensity)))
    throw Error("the intensity must be a finite number >= 0 (got " + NumberText(intensity) + ")");
  light.intensity = intensity;
  return 0;
}

int GetLightSource(lua_State* L) {
  const LightSourceRow& light = OwnSource(L, nullptr);
  lua_pushnumber(L, light.intensity);
  lua_pushboolean(L, light.on);
  return 2;
}

// The sensor `id`; FindSensor first (no allocation), the checked lookup
// for the message on a bad handle.
const LightSensorRow& SensorOf(const Scene& scene, ObjectId id) {
  if (const LightSensorRow* sensor = FindSensor(scene, id)) return *sensor;
  ObjectType type;
  scene.FindType(kLightSensorTypeName, &type);
  return scene.row<LightSensorRow>(type, id, "light sensor");
}

int ReadLightSensor(lua_State* L) {
  lua_pushnumber(L, SensorOf(*Context(L).scene, CheckObject(L, 1)).reading);
  return 1;
}

// sim.readLightSensors(handles [, readings]) -> readings: each sensor's
// reading into readings[i] (entries 1 .. #handles; a table reused from step
// to step is filled in place and nothing is allocated), or a new table.
int ReadLightSensors(lua_State* L) {
  const Scene& scene = *Context(L).scene;
  FillFromHandles(L, [&](ObjectId id) { lua_pushnumber(L, SensorOf(scene, id).reading); });
  return 1;
}

}  // namespace

void RegisterLightApi(lua_State* L) {
  static constexpr luaL_Reg kFunctions[] = {
      {"setLightSourceOn", Guarded<SetLightSourceOn, "sim.setLightSourceOn">},
      {"setLightSourceIntensity", Guarded<SetLightSourceIntensity, "sim.setLightSourceIntensity">},
      {"getLightSource", Guarded<GetLightSource, "sim.getLightSource">},
      {"readLightSensor", Guarded<ReadLightSensor, "sim.readLightSensor">},
      {"readLightSensors", Guarded<ReadLightSensors, "sim.readLightSensors">},
      {nullptr, nullptr},
  };
  luaL_setfuncs(L, kFunctions, 0);
}

}  // namespace swarmsim::light
