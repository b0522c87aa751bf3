// sim.* range-and-bearing (the Lua area of the range_and_bearing type):
//   sim.setRangeAndBearingData(h, data)  data: a string of bytes, or a table
//                                        of integers 0..255; at most the
//                                        board's payload_size bytes; sent
//                                        every step from the next sense
//                                        phase on, until changed
//   sim.getRangeAndBearingData(h) -> string  what it sends (payload_size bytes)
//   sim.readRangeAndBearing(h) -> {{data = string, range = m, bearing = rad,
//                                   elevation = rad}, ...}  nearest first
// A robot's scripts may set and get only their own robot's boards (scene
// scripts: any): the data changes during the control phase, so another
// robot's would be read or land depending on the thread schedule. Readings
// are written in the sense phase only, so any script may read any board.
#include <string>
#include <vector>

#include "framework/error.h"
#include "framework/lua_api.h"
#include "framework/lua_bytes.h"
#include "framework/scene.h"
#include "modules/range_and_bearing/module.h"
#include "modules/range_and_bearing/range_and_bearing.h"

namespace swarmsim::range_and_bearing {

namespace {

RangeAndBearingRow& ArgBoard(lua_State* L, ObjectId* id) {
  Scene& scene = *Context(L).scene;
  *id = CheckObject(L, 1);
  ObjectType type;
  scene.FindType(kTypeName, &type);  // registered with these functions
  return scene.row<RangeAndBearingRow>(type, *id, "range-and-bearing board");
}

// The board at argument 1, if the calling script may touch its data.
RangeAndBearingRow& OwnBoard(lua_State* L, const char* verb, ObjectId* id) {
  const LuaContext& c = Context(L);
  RangeAndBearingRow& rab = ArgBoard(L, id);
  if (c.instance >= 0 && c.scene->instance_of(*id) != c.instance)
    throw Error("a robot's script may " + std::string(verb) +
                " only its own range-and-bearing boards' data ('" + c.scene->PathOf(*id) +
                "' belongs to another robot or to the scene); sim.readRangeAndBearing hears "
                "the others");
  return rab;
}

std::string TooLong(const Scene& scene, ObjectId id, size_t bytes, uint32_t payload_size) {
  return "the data is " + std::to_string(bytes) + " bytes, more than the payload_size (" +
         std::to_string(payload_size) + " bytes) of '" + scene.PathOf(id) + "'";
}

int SetRangeAndBearingData(lua_State* L) {
  ObjectId id;
  RangeAndBearingRow& rab = OwnBoard(L, "set", &id);
  const uint32_t size = rab.settings->payload_size;
  const Scene& scene = *Context(L).scene;
  rab.data =
      ArgBytes(L, 2, size, "data", [&](size_t bytes) { return TooLong(scene, id, bytes, size); });
  return 0;
}

int GetRangeAndBearingData(lua_State* L) {
  ObjectId id;
  const RangeAndBearingRow& rab = OwnBoard(L, "get", &id);
  std::string bytes(rab.settings->payload_size, '\0');
  std::copy(rab.data.begin(), rab.data.end(), bytes.begin());
  PushBytes(L, bytes);
  return 1;
}

int ReadRangeAndBearing(lua_State* L) {
  ObjectId id;
  const RangeAndBearingRow& rab = ArgBoard(L, &id);
  lua_createtable(L, static_cast<int>(rab.readings.size()), 0);
  for (size_t i = 0; i < rab.readings.size(); ++i) {
    const RangeAndBearingReading& r = rab.readings[i];
    lua_createtable(L, 0, 4);
    lua_pushlstring(L, reinterpret_cast<const char*>(rab.received.data() + r.data_offset),
                    r.data_size);
    lua_setfield(L, -2, "data");
    lua_pushnumber(L, r.range);
    lua_setfield(L, -2, "range");
    lua_pushnumber(L, r.bearing);
    lua_setfield(L, -2, "bearing");
    lua_pushnumber(L, r.elevation);
    lua_setfield(L, -2, "elevation");
    lua_rawseti(L, -2, static_cast<lua_Integer>(i + 1));
  }
  return 1;
}

}  // namespace

void RegisterRangeAndBearingApi(lua_State* L) {
  static constexpr luaL_Reg kFunctions[] = {
      {"setRangeAndBearingData", Guarded<SetRangeAndBearingData, "sim.setRangeAndBearingData">},
      {"getRangeAndBearingData", Guarded<GetRangeAndBearingData, "sim.getRangeAndBearingData">},
      {"readRangeAndBearing", Guarded<ReadRangeAndBearing, "sim.readRangeAndBearing">},
      {nullptr, nullptr},
  };
  luaL_setfuncs(L, kFunctions, 0);
}

}  // namespace swarmsim::range_and_bearing
