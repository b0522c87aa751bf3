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
  std::vector<uint8_t> data;
  if (lua_type(L, 2) == LUA_TSTRING) {
    size_t length = 0;
    const char* bytes = lua_tolstring(L, 2, &length);
    if (length > size) throw Error(TooLong(scene, id, length, size));
    data.assign(bytes, bytes + length);
  } else if (lua_type(L, 2) == LUA_TTABLE) {
    // Element by element up to the first nil, never sized from #t; one past
    // the payload is enough to refuse.
    data.reserve(size);
    for (lua_Integer i = 1;; ++i) {
      const int type = lua_rawgeti(L, 2, i);
      if (type == LUA_TNIL) {
        lua_pop(L, 1);
        break;
      }
      int is_integer = 0;
      const lua_Integer v = lua_tointegerx(L, -1, &is_integer);
      lua_pop(L, 1);
      if (type != LUA_TNUMBER || !is_integer || v < 0 || v > 255)
        throw Error("element " + std::to_string(i) +
                    " of the data must be an integer from 0 to 255 (a byte)");
      if (static_cast<size_t>(i) > size) {
        // Count the rest for the message, up to a bound.
        lua_Integer n = i;
        while (n < i + 1000000 && lua_rawgeti(L, 2, n + 1) != LUA_TNIL) {
          lua_pop(L, 1);
          ++n;
        }
        lua_pop(L, 1);
        throw Error(TooLong(scene, id, static_cast<size_t>(n), size));
      }
      data.push_back(static_cast<uint8_t>(v));
    }
  } else {
    throw Error(std::string("bad argument #2 (a string of bytes or a table of integers 0..255 "
                            "expected, got ") +
                luaL_typename(L, 2) + ")");
  }
  rab.data = std::move(data);
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
