// sim.* custom data: named data blocks attached to objects, copied with their
// model (CoppeliaSim's custom data blocks).
//
//   sim.writeCustomDataBlock(h, tag, data)  data: a string (use sim.packFloats
//       etc. for numbers); nil or '' removes the block. Seen from the next step.
//   sim.readCustomDataBlock(h, tag) -> data or nil
//
// Writes wait for the start of the next step, like signals, so every script
// reads the blocks as they were when the step began, whatever the thread
// count; writes to one block in one step: the highest robot index wins, then
// scene scripts.
#include <cstring>
#include <string>

#include "framework/lua_api.h"
#include "framework/messaging.h"
#include "framework/scene.h"
#include "framework/script_memory.h"

namespace swarmsim {
namespace {

int WriteCustomDataBlock(lua_State* L) {
  const LuaContext& c = Context(L);
  const ObjectId id = CheckObject(L, 1);
  c.scene->SlotOf(id);  // a bad handle is an error now, not a silent no-op later
  const char* tag = ArgString(L, 2);
  const size_t tag_size = std::strlen(tag);  // up to a NUL, as readCustomDataBlock reads it
  size_t size = 0;
  const char* data = lua_isnoneornil(L, 3) ? "" : ArgString(L, 3, &size);
  // Charged until the block is overwritten or removed (Scene::WriteCustomData).
  ChargeScriptData(L, CustomDataBytes(tag_size, size), "the custom data block");
  c.mail->custom_data_writes.push_back({id, std::string(tag, tag_size), std::string(data, size)});
  return 0;
}

int ReadCustomDataBlock(lua_State* L) {
  const LuaContext& c = Context(L);
  const ObjectId id = CheckObject(L, 1);
  const std::string* data = c.scene->ReadCustomData(id, ArgString(L, 2));
  if (data == nullptr) {
    lua_pushnil(L);
  } else {
    lua_pushlstring(L, data->data(), data->size());
  }
  return 1;
}

}  // namespace

void RegisterCustomDataApi(lua_State* L) {
  static constexpr luaL_Reg kFunctions[] = {
      {"writeCustomDataBlock", Guarded<WriteCustomDataBlock, "sim.writeCustomDataBlock">},
      {"readCustomDataBlock", Guarded<ReadCustomDataBlock, "sim.readCustomDataBlock">},
      {nullptr, nullptr},
  };
  luaL_setfuncs(L, kFunctions, 0);
}

}  // namespace swarmsim
