// sim.* LEDs and blob cameras (the Lua area of the led type):
//   sim.setLedColor(h, {r, g, b})  each 0..1; {0, 0, 0} emits nothing
//   sim.setLedOn(h, on)            switches it, keeping its colour
//   sim.getLedColor(h) -> {r, g, b}, on
//   sim.readBlobCamera(h) -> {{color = {r, g, b}, distance = m, bearing = rad,
//                              elevation = rad, handle = the LED}, ...}
// A robot's scripts may set and get only their own robot's LEDs (scene
// scripts: any): they change during the control phase, so another robot's
// would read or land depending on the thread schedule; other robots' LEDs
// are seen through a blob camera. Cameras are written in the sense phase
// only, so any script may read any camera.
#include <string>

#include "framework/error.h"
#include "framework/lua_api.h"
#include "framework/scene.h"
#include "modules/blobs/blob_camera.h"
#include "modules/blobs/leds.h"

namespace swarmsim::blobs {

namespace {

// The row of the object at argument 1, which must be of type `type_name`.
template <typename Row>
Row& ArgRow(lua_State* L, const char* type_name, ObjectId* id) {
  Scene& scene = *Context(L).scene;
  *id = CheckObject(L, 1);
  const uint32_t slot = scene.SlotOf(*id);
  ObjectType type;
  if (!scene.FindType(type_name, &type) || scene.type_at(slot) != type)
    throw Error("object " + scene.PathOf(*id) + " is a " + scene.type_name(scene.type_at(slot)) +
                ", not a " + type_name);
  return static_cast<Rows<Row>&>(*scene.rows(type)).rows[scene.row_at(slot)];
}

// The LED at argument 1, if the calling script may touch it.
LedRow& OwnLed(lua_State* L, const char* verb) {
  const LuaContext& c = Context(L);
  ObjectId id;
  LedRow& led = ArgRow<LedRow>(L, kLedTypeName, &id);
  if (c.instance >= 0 && c.scene->instance_of(id) != c.instance)
    throw Error("a robot's script may " + std::string(verb) + " only its own LEDs ('" +
                c.scene->PathOf(id) +
                "' belongs to another robot or to the scene); a blob camera sees the others");
  return led;
}

int SetLedColor(lua_State* L) {
  LedRow& led = OwnLed(L, "set");
  led.color = ArgColor(L, 2);
  return 0;
}

int SetLedOn(lua_State* L) {
  LedRow& led = OwnLed(L, "switch");
  ArgType(L, 2, LUA_TBOOLEAN);
  led.on = lua_toboolean(L, 2) != 0;
  return 0;
}

int GetLedColor(lua_State* L) {
  const LedRow& led = OwnLed(L, "read");
  const double rgb[3] = {led.color.x, led.color.y, led.color.z};
  PushNumberArray(L, rgb, 3);
  lua_pushboolean(L, led.on);
  return 2;
}

int ReadBlobCamera(lua_State* L) {
  ObjectId id;
  const BlobCameraRow& camera = ArgRow<BlobCameraRow>(L, kBlobCameraTypeName, &id);
  lua_createtable(L, static_cast<int>(camera.blobs.size()), 0);
  for (size_t i = 0; i < camera.blobs.size(); ++i) {
    const Blob& b = camera.blobs[i];
    lua_createtable(L, 0, 5);
    const double rgb[3] = {b.color.x, b.color.y, b.color.z};
    PushNumberArray(L, rgb, 3);
    lua_setfield(L, -2, "color");
    lua_pushnumber(L, b.distance);
    lua_setfield(L, -2, "distance");
    lua_pushnumber(L, b.bearing);
    lua_setfield(L, -2, "bearing");
    lua_pushnumber(L, b.elevation);
    lua_setfield(L, -2, "elevation");
    lua_pushinteger(L, b.led.ToInteger());
    lua_setfield(L, -2, "handle");
    lua_rawseti(L, -2, static_cast<lua_Integer>(i + 1));
  }
  return 1;
}

}  // namespace

void RegisterBlobsApi(lua_State* L) {
  static constexpr luaL_Reg kFunctions[] = {
      {"setLedColor", Guarded<SetLedColor, "sim.setLedColor">},
      {"setLedOn", Guarded<SetLedOn, "sim.setLedOn">},
      {"getLedColor", Guarded<GetLedColor, "sim.getLedColor">},
      {"readBlobCamera", Guarded<ReadBlobCamera, "sim.readBlobCamera">},
      {nullptr, nullptr},
  };
  luaL_setfuncs(L, kFunctions, 0);
}

}  // namespace swarmsim::blobs
