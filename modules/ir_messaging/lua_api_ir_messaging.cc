// sim.* IR messaging (the Lua area of the ir_transceiver type):
//   sim.sendIrMessage(h, data)   data: a string of bytes, or a table of
//                                integers 0..255; at most the transceiver's
//                                payload_size bytes; queued to go out once in
//                                the next sense phase (replacing one queued
//                                earlier and not yet sent)
//   sim.readIrMessages(h) -> {{data = string, distance = m}, ...}  what it
//                                heard in the last sense phase, in arrival order
//   sim.getIrSent(h) -> boolean  whether its message went out in the last
//                                sense phase (false: none was queued, or the
//                                channel was busy: queue it again)
// A robot's scripts may send only from their own robot's transceivers
// (scene scripts: any). Inboxes are written in the sense phase only, so any
// script may read any transceiver.
#include <string>
#include <vector>

#include "framework/error.h"
#include "framework/lua_api.h"
#include "framework/scene.h"
#include "modules/ir_messaging/ir_messaging.h"
#include "modules/ir_messaging/module.h"

namespace swarmsim::ir_messaging {

namespace {

IrTransceiverRow& ArgTransceiver(lua_State* L, ObjectId* id) {
  Scene& scene = *Context(L).scene;
  *id = CheckObject(L, 1);
  ObjectType type;
  scene.FindType(kTypeName, &type);  // registered with these functions
  return scene.row<IrTransceiverRow>(type, *id, "IR transceiver");
}

std::string TooLong(const Scene& scene, ObjectId id, size_t bytes, uint32_t payload_size) {
  std::string text = "the message is " + std::to_string(bytes) + " bytes, but '" +
                     scene.PathOf(id) + "' carries at most " + std::to_string(payload_size) +
                     " bytes (its payload_size";
  if (payload_size == 12) text += ": a Kilobot message carries at most 12 bytes";
  return text + ")";
}

int SendIrMessage(lua_State* L) {
  const LuaContext& c = Context(L);
  ObjectId id;
  IrTransceiverRow& ir = ArgTransceiver(L, &id);
  if (c.instance >= 0 && c.scene->instance_of(id) != c.instance)
    throw Error("a robot's script may send only from its own IR transceivers ('" +
                c.scene->PathOf(id) +
                "' belongs to another robot or to the scene); sim.readIrMessages hears the "
                "others");
  const uint32_t size = ir.settings->payload_size;
  const Scene& scene = *c.scene;
  std::vector<uint8_t> data;
  if (lua_type(L, 2) == LUA_TSTRING) {
    size_t length = 0;
    const char* bytes = lua_tolstring(L, 2, &length);
    if (length > size) throw Error(TooLong(scene, id, length, size));
    data.assign(bytes, bytes + length);
  } else if (lua_type(L, 2) == LUA_TTABLE) {
    // Element by element up to the first nil, never sized from #t.
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
                    " of the message must be an integer from 0 to 255 (a byte)");
      if (static_cast<size_t>(i) > size) {
        lua_Integer n = i;  // count the rest for the message, up to a bound
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
  ir.outgoing = std::move(data);
  ir.queued = true;
  return 0;
}

int ReadIrMessages(lua_State* L) {
  ObjectId id;
  const IrTransceiverRow& ir = ArgTransceiver(L, &id);
  lua_createtable(L, static_cast<int>(ir.inbox.size()), 0);
  for (size_t i = 0; i < ir.inbox.size(); ++i) {
    const IrReceived& m = ir.inbox[i];
    lua_createtable(L, 0, 2);
    lua_pushlstring(L, reinterpret_cast<const char*>(ir.received.data() + m.data_offset),
                    m.data_size);
    lua_setfield(L, -2, "data");
    lua_pushnumber(L, m.distance);
    lua_setfield(L, -2, "distance");
    lua_rawseti(L, -2, static_cast<lua_Integer>(i + 1));
  }
  return 1;
}

int GetIrSent(lua_State* L) {
  ObjectId id;
  lua_pushboolean(L, ArgTransceiver(L, &id).sent ? 1 : 0);
  return 1;
}

}  // namespace

void RegisterIrMessagingApi(lua_State* L) {
  static constexpr luaL_Reg kFunctions[] = {
      {"sendIrMessage", Guarded<SendIrMessage, "sim.sendIrMessage">},
      {"readIrMessages", Guarded<ReadIrMessages, "sim.readIrMessages">},
      {"getIrSent", Guarded<GetIrSent, "sim.getIrSent">},
      {nullptr, nullptr},
  };
  luaL_setfuncs(L, kFunctions, 0);
}

}  // namespace swarmsim::ir_messaging
