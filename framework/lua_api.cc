// The sim.* API: helpers shared by the API areas, and the one list of areas.
#include "framework/lua_api.h"

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <string>
#include <variant>
#include <vector>

#include "framework/error.h"
#include "framework/object_type.h"
#include "framework/registry.h"
#include "framework/suggest.h"
#include "framework/world.h"

namespace swarmsim {

namespace {

// One sim.* entry: a C function or a constant.
struct SimEntry {
  std::string name;
  int type = LUA_TNIL;
  lua_CFunction function = nullptr;
  lua_Integer integer = 0;
  lua_Number number = 0;
  bool is_integer = false;
  std::string text;
  bool boolean = false;
};

void RegisterAreas(lua_State* L);

// Every sim.* entry, by name, and the globals the areas define. Built once per process from a
// scratch state: the API areas keep registering the usual way (luaL_setfuncs), and each robot's
// state fills its own `sim` table lazily from this list. A robot then holds only the functions its
// scripts use, instead of a hash table of ~100 entries (about 2-4 KiB per robot at 10,000 robots).
struct ApiTables {
  std::vector<SimEntry> sim;                                   // sorted by name
  std::vector<std::pair<std::string, lua_CFunction>> globals;  // e.g. print
};

const ApiTables& Tables() {
  static const ApiTables tables = [] {
    ApiTables t;
    std::vector<SimEntry>& out = t.sim;
    lua_State* L = luaL_newstate();  // no libraries: its globals are what the areas set
    lua_newtable(L);
    RegisterAreas(L);
    lua_pushglobaltable(L);
    lua_pushnil(L);
    while (lua_next(L, -2) != 0) {
      if (lua_type(L, -2) == LUA_TSTRING && lua_tocfunction(L, -1) != nullptr)
        t.globals.emplace_back(lua_tostring(L, -2), lua_tocfunction(L, -1));
      lua_pop(L, 1);
    }
    lua_pop(L, 1);
    lua_pushnil(L);
    while (lua_next(L, -2) != 0) {
      if (lua_type(L, -2) == LUA_TSTRING) {
        SimEntry e;
        e.name = lua_tostring(L, -2);
        e.type = lua_type(L, -1);
        switch (e.type) {
          case LUA_TFUNCTION: e.function = lua_tocfunction(L, -1); break;
          case LUA_TNUMBER:
            e.is_integer = lua_isinteger(L, -1);
            e.integer = lua_tointeger(L, -1);
            e.number = lua_tonumber(L, -1);
            break;
          case LUA_TSTRING: e.text = lua_tostring(L, -1); break;
          case LUA_TBOOLEAN: e.boolean = lua_toboolean(L, -1); break;
          default: break;
        }
        if (e.type != LUA_TFUNCTION || e.function != nullptr) out.push_back(std::move(e));
      }
      lua_pop(L, 1);
    }
    lua_close(L);
    std::sort(out.begin(), out.end(),
              [](const SimEntry& a, const SimEntry& b) { return a.name < b.name; });
    return t;
  }();
  return tables;
}

// sim.wait and sim.waitUntil, in Lua over sim.step (threaded scripts only).
// Loaded into a state when a script first looks either up: most robots never
// do, and the chunk's functions and strings would cost each ~1.5 KB.
constexpr char kThreadHelpers[] = R"(local sim, yieldable = ...
local step, now = sim.step, sim.getSimulationTime
local function threaded(name)  -- errors name the caller's line, not this chunk's
  local ok, why = yieldable()
  if not ok then error(name .. ': ' .. why, 3) end
end
local function seconds_arg(name, arg, what, s)  -- a finite number >= 0 (not NaN)
  if type(s) ~= 'number' then
    error(name .. ': bad argument #' .. arg .. ' (number expected, got ' .. type(s) .. ')', 3)
  end
  if not (s >= 0 and s - s == 0) then
    error(name .. ': ' .. what .. ' must be a finite number of seconds >= 0 (got ' ..
          (s ~= s and 'nan' or tostring(s)) .. ')', 3)  -- 0/0 prints as -nan
  end
end
function sim.wait(seconds)
  threaded('sim.wait')
  seconds_arg('sim.wait', 1, 'the time', seconds)
  local t_end = now() + seconds - 1e-9
  while now() < t_end do step() end
end
function sim.waitUntil(condition, timeout)
  threaded('sim.waitUntil')
  if type(condition) ~= 'function' then
    error('sim.waitUntil: bad argument #1 (function expected, got ' .. type(condition) .. ')', 2)
  end
  if timeout ~= nil then seconds_arg('sim.waitUntil', 2, 'the timeout', timeout) end
  local t_end = timeout and now() + timeout - 1e-9
  while not condition() do
    if t_end and now() >= t_end then return false end
    step()
  end
  return true
end
)";

// true, or false and why not: sim.step (under sim.wait) yields the script's
// own thread only, not a coroutine the script made (it said "sim:21").
int IsYieldable(lua_State* L) {
  const lua_State* thread = Context(L).thread;
  if (thread != nullptr && L != thread) {
    lua_pushboolean(L, 0);
    lua_pushliteral(L, "call it from sysCall_thread itself, not from a coroutine of your own");
    return 2;
  }
  if (thread == nullptr) {
    lua_pushboolean(L, 0);
    lua_pushliteral(L, "only a threaded script (sysCall_thread) can wait");
    return 2;
  }
  if (!lua_isyieldable(L)) {  // the thread's own, but under a C function's callback
    lua_pushboolean(L, 0);
    lua_pushliteral(L,
                    "not from inside a callback of a C function (table.sort's comparison, "
                    "string.gsub's replacement, a metamethod): it cannot wait there");
    return 2;
  }
  lua_pushboolean(L, 1);
  return 1;
}

// Pushes the entry `key` of one Lua area (an object type's or a module's
// register_lua), if the area has it.
bool PushAreaEntry(lua_State* L, void (*register_lua)(lua_State*), std::string_view key) {
  lua_newtable(L);
  register_lua(L);
  lua_pushlstring(L, key.data(), key.size());
  lua_rawget(L, -2);
  if (!lua_isnil(L, -1)) {
    lua_remove(L, -2);
    return true;
  }
  lua_pop(L, 2);
  return false;
}

// Pushes the entry `key` of the Lua area of an object type or a module the
// world's registry holds (object_type.h, module.h), if one has it. A name
// no area has is remembered as missing (a table per Lua state, in the
// registry): looking for it again costs one lookup, not a table built per
// area (65 us: `if sim.x then` in a loop, or a fuzzed script recursing
// through a misspelt name, took seconds).
bool PushRegisteredTypeFunction(lua_State* L, std::string_view key) {
  const LuaContext& c = Context(L);
  if (c.world == nullptr) return false;
  static const char kMissing = 0;  // its address: the registry key
  if (lua_rawgetp(L, LUA_REGISTRYINDEX, &kMissing) != LUA_TTABLE) {
    lua_pop(L, 1);
    lua_newtable(L);
    lua_pushvalue(L, -1);
    lua_rawsetp(L, LUA_REGISTRYINDEX, &kMissing);
  }
  lua_pushlstring(L, key.data(), key.size());
  const bool known_missing = lua_rawget(L, -2) != LUA_TNIL;
  lua_pop(L, 1);  // the missing table stays below, for the end
  if (!known_missing) {
    for (const ObjectTypeDescriptor* type : c.world->registry().object_types())
      if (type->register_lua != nullptr && PushAreaEntry(L, type->register_lua, key)) {
        lua_remove(L, -2);
        return true;
      }
    for (const auto& module : c.world->registry().module_descriptors())
      if (module->register_lua != nullptr && PushAreaEntry(L, module->register_lua, key)) {
        lua_remove(L, -2);
        return true;
      }
    lua_pushlstring(L, key.data(), key.size());
    lua_pushboolean(L, 1);
    lua_rawset(L, -3);
  }
  lua_pop(L, 1);
  return false;
}

// __index of a robot's `sim` table: fetch the entry, keep it in the table.
int LazySimIndex(lua_State* L) {
  if (lua_type(L, 2) != LUA_TSTRING) return 0;
  const std::string_view key = lua_tostring(L, 2);
  if (key == "wait" || key == "waitUntil") {  // kThreadHelpers defines both
    if (luaL_loadbufferx(L, kThreadHelpers, sizeof kThreadHelpers - 1, "=sim", "t") != LUA_OK)
      lua_error(L);
    lua_pushvalue(L, 1);
    lua_pushcfunction(L, IsYieldable);
    lua_call(L, 2, 0);
    lua_pushvalue(L, 2);
    lua_rawget(L, 1);
    return 1;
  }
  const std::vector<SimEntry>& entries = Tables().sim;
  auto it = std::lower_bound(entries.begin(), entries.end(), key,
                             [](const SimEntry& e, std::string_view k) { return e.name < k; });
  if (it == entries.end() || it->name != key) {
    // A registered object type's function, or a plugin's command
    // (lua_api_plugins.cc), kept like the others.
    if (!PushRegisteredTypeFunction(L, key) && !PushPluginCommand(L, key)) return 0;
    lua_pushvalue(L, 2);
    lua_pushvalue(L, -2);
    lua_rawset(L, 1);
    return 1;
  }
  switch (it->type) {
    case LUA_TFUNCTION: lua_pushcfunction(L, it->function); break;
    case LUA_TNUMBER:
      if (it->is_integer)
        lua_pushinteger(L, it->integer);
      else
        lua_pushnumber(L, it->number);
      break;
    case LUA_TSTRING: lua_pushlstring(L, it->text.data(), it->text.size()); break;
    case LUA_TBOOLEAN: lua_pushboolean(L, it->boolean); break;
    default: return 0;
  }
  lua_pushvalue(L, 2);
  lua_pushvalue(L, -2);
  lua_rawset(L, 1);
  return 1;
}

}  // namespace

void RaiseError(lua_State*, const std::string& message) { throw LuaError(message); }
void RaiseRefusal(lua_State*, const std::string& message) { throw LuaRefusal(message); }

int CallProtected(lua_State* L, lua_CFunction f, const char* name) noexcept {
  // After the running callback failed, every sim.* and sandbox function
  // fails again: a C function called without a Lua instruction between
  // (a __close handler run while the error unwinds) gets no count hook.
  if (Context(L).budget_exhausted) return kRefused;
  // The message is built in a plain buffer: nothing with a destructor may be
  // alive when the caller raises the Lua error.
  char message[kMaxErrorTextBytes];
  const auto format = [&](const char* prefix, const char* what) {
    const int length = prefix[0] != '\0'
                           ? std::snprintf(message, sizeof message, "%s: %s", prefix, what)
                           : std::snprintf(message, sizeof message, "%s", what);
    if (length < static_cast<int>(sizeof message)) return;
    // Cut between UTF-8 characters, and said so (the note takes < 40 bytes).
    size_t end = sizeof message - 40;
    while (end > 0 && (static_cast<unsigned char>(message[end]) & 0xC0) == 0x80) --end;
    std::snprintf(message + end, sizeof message - end, " ... (%d bytes cut)",
                  length - static_cast<int>(end));
  };
  bool refused = false;
  try {
    return f(L);
  } catch (const LuaErrorOnStack&) {
    return -1;
  } catch (const LuaError& e) {
    refused = dynamic_cast<const LuaRefusal*>(&e) != nullptr;
    format("", e.what());
  } catch (const std::exception& e) {
    format(name, e.what());
  } catch (...) {
    format(name, "unknown C++ exception");
  }
  // Room for the message whatever `f` left on the stack (it is discarded).
  lua_settop(L, 0);
  // Where the script called from: a refusal ends the callback, so it names
  // the nearest Lua line even when a C function (pcall) made the call.
  int level = 1;
  lua_Debug ar;
  if (refused)
    while (lua_getstack(L, level, &ar) && lua_getinfo(L, "l", &ar) && ar.currentline <= 0) ++level;
  luaL_where(L, level);
  lua_pushstring(L, message);
  lua_concat(L, 2);
  return refused ? kRefused : -1;
}

namespace {
[[noreturn]] void ArgError(lua_State* L, int arg, const char* expected) {
  throw Error("bad argument #" + std::to_string(arg) + " (" + expected + " expected, got " +
              luaL_typename(L, arg) + ")");
}
}  // namespace

lua_Integer ArgInteger(lua_State* L, int arg) {
  int ok = 0;
  const lua_Integer value = lua_tointegerx(L, arg, &ok);
  if (ok) return value;
  if (lua_isnumber(L, arg))
    throw Error("bad argument #" + std::to_string(arg) + " (number has no integer representation)");
  ArgError(L, arg, "number");
}

lua_Number ArgNumber(lua_State* L, int arg) {
  int ok = 0;
  const lua_Number value = lua_tonumberx(L, arg, &ok);
  if (!ok) ArgError(L, arg, "number");
  return value;
}

const char* ArgString(lua_State* L, int arg, size_t* length) {
  const char* text = lua_tolstring(L, arg, length);
  if (text == nullptr) ArgError(L, arg, "string");
  return text;
}

void ArgType(lua_State* L, int arg, int type) {
  if (lua_type(L, arg) != type) ArgError(L, arg, lua_typename(L, type));
}

void HandleArrayError(lua_State* L, lua_Integer i, const char* why) {
  if (why == nullptr)
    throw Error("handles[" + std::to_string(i) + "] is not an object handle (got " +
                luaL_typename(L, -1) + ")");
  throw Error("handles[" + std::to_string(i) + "]: " + why);
}

int ArgOption(lua_State* L, int arg, const char* def, const char* const options[]) {
  const char* name = def != nullptr && lua_isnoneornil(L, arg) ? def : ArgString(L, arg);
  for (int i = 0; options[i] != nullptr; ++i)
    if (std::strcmp(options[i], name) == 0) return i;
  // The valid options, and the nearest one if `name` looks like a typo of it.
  std::vector<std::string> valid;
  for (int i = 0; options[i] != nullptr; ++i) valid.emplace_back(options[i]);
  std::string expected;
  for (size_t i = 0; i < valid.size(); ++i)
    expected += (i == 0 ? "'" : i + 1 == valid.size() ? " or '" : ", '") + valid[i] + "'";
  const std::string* nearest = NearestName(name, valid);
  throw Error("bad argument #" + std::to_string(arg) + " (invalid option '" + name +
              "'; expected " + expected +
              (nearest != nullptr ? "; did you mean '" + *nearest + "'?" : std::string()) + ")");
}

namespace {
int PushBytesUnprotected(lua_State* L) {
  const auto* bytes = static_cast<const std::string_view*>(lua_touserdata(L, 1));
  lua_pushlstring(L, bytes->data(), bytes->size());
  return 1;
}
}  // namespace

void PushBytes(lua_State* L, std::string_view bytes) {
  // A light C function and a light userdata: neither allocates.
  lua_pushcfunction(L, PushBytesUnprotected);
  lua_pushlightuserdata(L, &bytes);
  if (lua_pcall(L, 1, 1, 0) != LUA_OK) throw LuaErrorOnStack{};
}

void PushDeferredWrite(lua_State* L, const DeferredWrite& write) {
  ChargeScriptData(L, sizeof(DeferredWrite), "the write to another robot's object");
  Context(L).runtime->deferred.push_back(write);  // released by World::Actuate
}

ObjectId OptRelativeTo(lua_State* L, int arg) {
  if (lua_isnoneornil(L, arg)) return {};
  const lua_Integer h = ArgInteger(L, arg);
  if (h == kHandleWorld) return {};
  return ObjectId::FromInteger(h);
}

Vec3 ArgColor(lua_State* L, int arg) {
  ArgType(L, arg, LUA_TTABLE);
  double rgb[3];
  for (int i = 0; i < 3; ++i) {
    lua_rawgeti(L, arg, i + 1);
    int ok = 0;
    rgb[i] = lua_tonumberx(L, -1, &ok);
    lua_pop(L, 1);
    if (!ok || !(rgb[i] >= 0 && rgb[i] <= 1))
      throw Error("the colour must be {r, g, b} with each component between 0 and 1");
  }
  return {rgb[0], rgb[1], rgb[2]};
}

void PushNumberArray(lua_State* L, const double* v, int n) {
  lua_createtable(L, n, 0);
  for (int i = 0; i < n; ++i) {
    lua_pushnumber(L, v[i]);
    lua_rawseti(L, -2, i + 1);
  }
}

void PushParamValue(lua_State* L, const ParamValue& value) {
  if (const double* d = std::get_if<double>(&value)) {
    PushValueNumber(L, *d);
  } else if (const bool* b = std::get_if<bool>(&value)) {
    lua_pushboolean(L, *b);
  } else {
    const std::string& s = std::get<std::string>(value);
    lua_pushlstring(L, s.data(), s.size());
  }
}

namespace {
void RegisterAreas(lua_State* L) {
  // One API area per file; a new area adds one line here (an object type's
  // area is named by its descriptor instead).
  static constexpr void (*kAreas[])(lua_State*) = {
      RegisterSimApi,         // lua_api_sim.cc: time, parameters, random, metrics, print
      RegisterObjectsApi,     // lua_api_objects.cc: lookup, names, tree, poses
      RegisterMessagesApi,    // lua_api_messages.cc: messages, signals, packing
      RegisterControlApi,     // lua_api_control.cc: child scripts, threads, main-script handlers
      RegisterDynamicsApi,    // lua_api_dynamics.cc: dynamic/kinematic switch, joint forces
      RegisterCustomDataApi,  // lua_api_custom_data.cc: custom data blocks
      RegisterModelsApi,      // lua_api_models.cc: copying and removing robots at run time
  };
  lua_pushinteger(L, kHandleWorld);
  lua_setfield(L, -2, "handle_world");
  for (auto area : kAreas) area(L);
  // Each built-in object type's own area (joints, plugin sensors:
  // framework/types/, object_type.h); the types and modules of a world's
  // registry add theirs on first use (PushRegisteredTypeFunction).
  for (const ObjectTypeDescriptor* type : CoreObjectTypes())
    if (type->register_lua != nullptr) type->register_lua(L);
}
}  // namespace

void RegisterAllApis(lua_State* L) {
  lua_newtable(L);  // sim, filled on first use of each name
  lua_createtable(L, 0, 1);
  lua_pushcfunction(L, (Guarded<LazySimIndex, "sim">));
  lua_setfield(L, -2, "__index");
  lua_setmetatable(L, -2);
  lua_setglobal(L, "sim");
  for (const auto& [name, function] : Tables().globals) {
    lua_pushcfunction(L, function);
    lua_setglobal(L, name.c_str());
  }
}

}  // namespace swarmsim
