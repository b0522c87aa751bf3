// sim.* messages, signals and packing.
//
// Messages (delivered at the start of the next step, in sender-handle order;
// at most 1 MiB each; until then each is charged to its sender's memory
// account, against simulation.script_memory_mb with its Lua memory):
//   sim.sendGlobalMessage(data)          every script of the world but the sender
//   sim.sendLocalMessage(data)           the other scripts of the sender's model
//   sim.sendDirectMessage(handle, data)  the script attached to object `handle`
//   sim.sendRangeMessage(data, range [, lineOfSight])
//                                        the robots whose model root is within
//                                        `range` m of the sender (optionally
//                                        only those no static shape hides)
//   sim.receiveMessage() -> data, sender, distance, bearing  (nil when done)
// The world's main script has no object: its messages come from
// sim.handle_world, without distance or bearing, and it cannot send by range.
// Signals (scene-wide; a value set in step t is seen from step t+1; the last
// writer in robot order wins; integral numbers read back as integers):
// sim.setSignal, sim.getSignal, sim.clearSignal.
// Packing numbers into message strings: sim.packFloats / unpackFloats
// (float32), packDoubles / unpackDoubles, packInt32s / unpackInt32s,
// packTable / unpackTable (nested tables of numbers, strings, booleans; at
// most 32 levels of tables).
#include <cmath>
#include <cstdint>
#include <cstring>
#include <string>
#include <string_view>

#include "framework/error.h"
#include "framework/lua_api.h"
#include "framework/messaging.h"
#include "framework/plugin_controllers.h"
#include "framework/script_memory.h"
#include "framework/world.h"

namespace swarmsim {
namespace {

constexpr size_t kMaxMessageBytes = 1 << 20;

// The message argument, still owned by Lua (it stays on the stack).
std::string_view CheckData(lua_State* L, int arg) {
  if (lua_type(L, arg) != LUA_TSTRING)
    throw Error(std::string("the message must be a string (got ") + luaL_typename(L, arg) +
                "); pack numbers with sim.packFloats or tables with sim.packTable");
  size_t length = 0;
  const char* data = lua_tolstring(L, arg, &length);
  if (length > kMaxMessageBytes) throw Error("a message may hold at most 1 MiB");
  return {data, length};
}

void Send(lua_State* L, MessageScope scope, std::string_view data, ObjectId target = {},
          double range = 0, bool line_of_sight = false) {
  LuaContext& c = Context(L);
  // Charged to the robot's account until the next step's messages are
  // delivered (Messaging::GatherMessages): the outboxes of a swarm could
  // otherwise take all of the host's memory.
  RobotMail& mail = *c.mail;
  ChargeScriptData(L, data.size() + sizeof(Message), "the message");
  Message m;
  m.data = data;
  m.sender = c.script_object;
  m.target = target;
  m.sender_instance = c.instance;
  m.range = range;
  m.scope = scope;
  m.line_of_sight = line_of_sight;
  mail.outbox.push_back(std::move(m));
}

int SendGlobalMessage(lua_State* L) {
  Send(L, MessageScope::kGlobal, CheckData(L, 1));
  return 0;
}
int SendLocalMessage(lua_State* L) {
  // It went nowhere, without a word.
  if (Context(L).script_object.IsNull())
    throw Error(
        "the main script belongs to no robot: use sim.sendGlobalMessage or "
        "sim.sendDirectMessage");
  Send(L, MessageScope::kLocal, CheckData(L, 1));
  return 0;
}
int SendDirectMessage(lua_State* L) {
  const ObjectId target = CheckObject(L, 1);
  const Scene& scene = *Context(L).scene;
  // A script reads it, or the native controller of the robot it is the root of.
  const auto native_root = [&] {
    PluginControllers* controllers = Context(L).world->plugin_controllers();
    const int robot = scene.instance_of(target);
    return controllers != nullptr && robot >= 0 && scene.instance(robot).root == target &&
           controllers->type_of(robot) != nullptr;
  };
  scene.SlotOf(target);  // a stale handle: "handle ... is stale: the object was removed"
  if (scene.script(target) == nullptr && !native_root())
    throw Error("object " + std::to_string(target.ToInteger()) +
                " carries no script (nor is it the root of a robot with a native controller)");
  Send(L, MessageScope::kDirect, CheckData(L, 2), target);
  return 0;
}
int SendRangeMessage(lua_State* L) {
  if (Context(L).script_object.IsNull())
    throw Error(
        "the main script has no position: use sim.sendGlobalMessage or sim.sendDirectMessage");
  const std::string_view data = CheckData(L, 1);
  const double range = ArgNumber(L, 2);
  if (!(range >= 0) || !std::isfinite(range))
    throw Error("the range must be a non-negative number of metres");
  Send(L, MessageScope::kRange, data, {}, range, lua_toboolean(L, 3) != 0);
  return 0;
}

int ReceiveMessage(lua_State* L) {
  LuaContext& c = Context(L);
  if (c.mailbox == nullptr) return 0;
  ScriptMailbox& mailbox = *c.mailbox;
  const Messaging& messaging = c.world->messaging();
  if (mailbox.round != messaging.round()) mailbox = {messaging.round(), 0};
  const std::vector<ReceivedMessage>& inbox = c.mail->inbox;
  const std::vector<Message>& messages = messaging.messages();
  while (mailbox.next < inbox.size()) {
    const ReceivedMessage& r = inbox[mailbox.next++];
    const Message& m = messages[r.message];
    if (m.scope == MessageScope::kDirect ? m.target != c.script_object
                                         : m.sender == c.script_object)
      continue;
    lua_pushlstring(L, m.data.data(), m.data.size());
    lua_pushinteger(L, m.sender.IsNull() ? kHandleWorld : m.sender.ToInteger());
    if (!r.has_geometry) return 2;
    lua_pushnumber(L, r.distance);
    lua_pushnumber(L, r.bearing);
    return 4;
  }
  return 0;
}

// --- Signals ---------------------------------------------------------------------------

// A string argument with every byte (a NUL too).
std::string ArgBytes(lua_State* L, int arg) {
  size_t length = 0;
  const char* text = ArgString(L, arg, &length);
  return std::string(text, length);
}

int SetSignal(lua_State* L) {
  LuaContext& c = Context(L);
  const int type = lua_type(L, 2);
  if (type != LUA_TNUMBER && type != LUA_TBOOLEAN && type != LUA_TSTRING && type != LUA_TNIL)
    throw Error(std::string("a signal is a number, boolean or string (got ") + luaL_typename(L, 2) +
                ")");
  // Charged until the signal is overwritten or cleared (Messaging).
  size_t name_size = 0, text_size = 0;
  ArgString(L, 1, &name_size);
  if (type == LUA_TSTRING) lua_tolstring(L, 2, &text_size);
  ChargeScriptData(L, SignalBytes(name_size, text_size), "the signal");
  std::string name = ArgBytes(L, 1);
  switch (type) {
    case LUA_TNUMBER:
      c.mail->signal_writes.emplace_back(std::move(name), lua_tonumber(L, 2));
      break;
    case LUA_TBOOLEAN:
      c.mail->signal_writes.emplace_back(std::move(name), lua_toboolean(L, 2) != 0);
      break;
    case LUA_TSTRING: c.mail->signal_writes.emplace_back(std::move(name), ArgBytes(L, 2)); break;
    default: c.mail->signal_writes.emplace_back(std::move(name), std::nullopt); break;
  }
  return 0;
}
int ClearSignal(lua_State* L) {
  size_t name_size = 0;
  ArgString(L, 1, &name_size);
  ChargeScriptData(L, SignalBytes(name_size, 0), "the signal");
  Context(L).mail->signal_writes.emplace_back(ArgBytes(L, 1), std::nullopt);
  return 0;
}
int GetSignal(lua_State* L) {
  size_t length = 0;
  const char* name = ArgString(L, 1, &length);
  const auto& signals = Context(L).world->messaging().signals();
  auto it = signals.find(std::string_view(name, length));
  if (it == signals.end()) {
    lua_pushnil(L);
    return 1;
  }
  PushParamValue(L, it->second.value);  // integral numbers as Lua integers
  return 1;
}

// --- Packing ---------------------------------------------------------------------------

// The packed string is charged to the robot while the call builds it
// (CallCharge: as it grows) and pushed in protected mode (PushBytes). It
// grows element by element, never sized from #t: a table whose length is a
// border far past its entries ({[1] = 1, [2^40] = 1} may have #t = 2^40)
// fails at its first missing element, whatever the memory limits.
template <typename T>
int PackArray(lua_State* L) {
  ArgType(L, 1, LUA_TTABLE);
  const lua_Integer n = static_cast<lua_Integer>(lua_rawlen(L, 1));
  CallCharge charge(L, "the packed string");
  std::string out;
  for (lua_Integer i = 1; i <= n; ++i) {
    lua_rawgeti(L, 1, i);
    T v;
    if constexpr (std::is_integral_v<T>) {
      int ok = 0;
      const lua_Integer x = lua_tointegerx(L, -1, &ok);
      if (!ok || x < INT32_MIN || x > INT32_MAX)
        throw Error("element " + std::to_string(i) + " is not a 32-bit integer");
      v = static_cast<T>(x);
    } else {
      int ok = 0;
      v = static_cast<T>(lua_tonumberx(L, -1, &ok));
      if (!ok) throw Error("element " + std::to_string(i) + " is not a number");
    }
    lua_pop(L, 1);
    charge.Hold(out.size() + sizeof(T));
    out.append(reinterpret_cast<const char*>(&v), sizeof(T));
  }
  PushBytes(L, out);
  return 1;
}

template <typename T>
int UnpackArray(lua_State* L) {
  size_t length = 0;
  const char* data = ArgString(L, 1, &length);
  if (length % sizeof(T) != 0)
    throw Error("the string's length (" + std::to_string(length) + ") is not a multiple of " +
                std::to_string(sizeof(T)));
  const int n = static_cast<int>(length / sizeof(T));
  lua_createtable(L, n, 0);
  for (int i = 0; i < n; ++i) {
    T v;
    std::memcpy(&v, data + i * sizeof(T), sizeof(T));
    if constexpr (std::is_integral_v<T>)
      lua_pushinteger(L, v);
    else
      lua_pushnumber(L, v);
    lua_rawseti(L, -2, i + 1);
  }
  return 1;
}

// packTable format: a tag byte per value: 'n' double, 'i' int64, 's' u32
// length + bytes, 'T'/'F' booleans, 't' u32 pair count + key/value pairs.
// Tables nest at most kMaxTableDepth levels (the outer table is level 1),
// which also stops a cycle. Each level holds a key and a value on the Lua
// stack, beyond the LUA_MINSTACK slots a C function is given: every level
// reserves its slots first.
constexpr int kMaxTableDepth = 32;
constexpr int kStackSlotsPerLevel = 3;  // key and value (packing); table, key and value (unpacking)

void ReserveStack(lua_State* L) {
  if (!lua_checkstack(L, kStackSlotsPerLevel))
    throw Error("not enough memory for the Lua stack of a nested table");
}

// The packed string as it grows, charged to the robot (a table that holds
// one long string many times packs to many copies of it).
struct Packed {
  explicit Packed(lua_State* L) : charge(L, "the packed table") {}
  void Append(const void* p, size_t n) {
    charge.Hold(bytes.size() + n);
    bytes.append(static_cast<const char*>(p), n);
  }
  void Append(char tag) { Append(&tag, 1); }
  CallCharge charge;
  std::string bytes;
};

void PackValue(lua_State* L, int index, int depth, Packed* out) {
  switch (lua_type(L, index)) {
    case LUA_TNUMBER:
      if (lua_isinteger(L, index)) {
        const int64_t v = lua_tointeger(L, index);
        out->Append('i');
        out->Append(&v, sizeof v);
      } else {
        const double v = lua_tonumber(L, index);
        out->Append('n');
        out->Append(&v, sizeof v);
      }
      break;
    case LUA_TBOOLEAN: out->Append(lua_toboolean(L, index) ? 'T' : 'F'); break;
    case LUA_TSTRING: {
      size_t length = 0;
      const char* s = lua_tolstring(L, index, &length);
      if (length > UINT32_MAX) throw Error("cannot pack a string of 4 GiB or more");
      const uint32_t n = static_cast<uint32_t>(length);
      out->Append('s');
      out->Append(&n, sizeof n);
      out->Append(s, length);
      break;
    }
    case LUA_TTABLE: {
      if (depth >= kMaxTableDepth)
        throw Error("the table is nested more than " + std::to_string(kMaxTableDepth) +
                    " levels deep (or has a cycle)");
      ReserveStack(L);
      index = lua_absindex(L, index);
      uint32_t count = 0;
      for (lua_pushnil(L); lua_next(L, index) != 0; lua_pop(L, 1)) ++count;
      out->Append('t');
      out->Append(&count, sizeof count);
      for (lua_pushnil(L); lua_next(L, index) != 0; lua_pop(L, 1)) {
        PackValue(L, -2, depth + 1, out);
        PackValue(L, -1, depth + 1, out);
      }
      break;
    }
    default:
      throw Error(std::string("cannot pack a ") + luaL_typename(L, index) +
                  " (numbers, strings, booleans and tables only)");
  }
}

int PackTable(lua_State* L) {
  ArgType(L, 1, LUA_TTABLE);
  lua_settop(L, 1);
  Packed out(L);
  try {
    PackValue(L, 1, 0, &out);
  } catch (...) {
    lua_settop(L, 1);  // the keys and values of the levels left, for the error message's room
    throw;
  }
  PushBytes(L, out.bytes);
  return 1;
}

struct Reader {
  const char* p;
  const char* end;
  void Read(void* v, size_t n) {
    if (static_cast<size_t>(end - p) < n) throw Error("the string is not a packed table");
    std::memcpy(v, p, n);
    p += n;
  }
};

void UnpackValue(lua_State* L, Reader* r, int depth) {
  char tag = 0;
  r->Read(&tag, 1);
  switch (tag) {
    case 'n': {
      double v;
      r->Read(&v, sizeof v);
      lua_pushnumber(L, v);
      break;
    }
    case 'i': {
      int64_t v;
      r->Read(&v, sizeof v);
      lua_pushinteger(L, v);
      break;
    }
    case 'T': lua_pushboolean(L, 1); break;
    case 'F': lua_pushboolean(L, 0); break;
    case 's': {
      uint32_t n = 0;
      r->Read(&n, sizeof n);
      if (static_cast<size_t>(r->end - r->p) < n) throw Error("the string is not a packed table");
      lua_pushlstring(L, r->p, n);
      r->p += n;
      break;
    }
    case 't': {
      if (depth >= kMaxTableDepth)
        throw Error("the packed table is nested more than " + std::to_string(kMaxTableDepth) +
                    " levels deep");
      ReserveStack(L);
      uint32_t count = 0;
      r->Read(&count, sizeof count);
      lua_createtable(L, 0, 0);
      for (uint32_t i = 0; i < count; ++i) {
        UnpackValue(L, r, depth + 1);
        UnpackValue(L, r, depth + 1);
        // Keys Lua refuses (lua_rawset would raise a Lua error here).
        if (lua_isnil(L, -2) || (lua_type(L, -2) == LUA_TNUMBER && std::isnan(lua_tonumber(L, -2))))
          throw Error("the string is not a packed table");
        lua_rawset(L, -3);
      }
      break;
    }
    default: throw Error("the string is not a packed table");
  }
}

int UnpackTable(lua_State* L) {
  size_t length = 0;
  const char* data = ArgString(L, 1, &length);
  lua_settop(L, 1);
  Reader r{data, data + length};
  try {
    UnpackValue(L, &r, 0);
  } catch (...) {
    lua_settop(L, 1);  // the tables of the levels left, for the error message's room
    throw;
  }
  if (r.p != r.end || !lua_istable(L, -1)) throw Error("the string is not a packed table");
  return 1;
}

}  // namespace

void RegisterMessagesApi(lua_State* L) {
  static constexpr luaL_Reg kFunctions[] = {
      {"sendGlobalMessage", Guarded<SendGlobalMessage, "sim.sendGlobalMessage">},
      {"sendLocalMessage", Guarded<SendLocalMessage, "sim.sendLocalMessage">},
      {"sendDirectMessage", Guarded<SendDirectMessage, "sim.sendDirectMessage">},
      {"sendRangeMessage", Guarded<SendRangeMessage, "sim.sendRangeMessage">},
      {"receiveMessage", Guarded<ReceiveMessage, "sim.receiveMessage">},
      {"setSignal", Guarded<SetSignal, "sim.setSignal">},
      {"getSignal", Guarded<GetSignal, "sim.getSignal">},
      {"clearSignal", Guarded<ClearSignal, "sim.clearSignal">},
      {"packFloats", Guarded<PackArray<float>, "sim.packFloats">},
      {"unpackFloats", Guarded<UnpackArray<float>, "sim.unpackFloats">},
      {"packDoubles", Guarded<PackArray<double>, "sim.packDoubles">},
      {"unpackDoubles", Guarded<UnpackArray<double>, "sim.unpackDoubles">},
      {"packInt32s", Guarded<PackArray<int32_t>, "sim.packInt32s">},
      {"unpackInt32s", Guarded<UnpackArray<int32_t>, "sim.unpackInt32s">},
      {"packTable", Guarded<PackTable, "sim.packTable">},
      {"unpackTable", Guarded<UnpackTable, "sim.unpackTable">},
      {nullptr, nullptr},
  };
  luaL_setfuncs(L, kFunctions, 0);
}

}  // namespace swarmsim
