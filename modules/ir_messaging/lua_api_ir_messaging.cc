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
#include "framework/lua_bytes.h"
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
  ir.outgoing = ArgBytes(L, 2, size, "message",
                         [&](size_t bytes) { return TooLong(scene, id, bytes, size); });
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
