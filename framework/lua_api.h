// Internal to the Lua host: included only by script_host.cc and lua_*.cc.
//
// The per-state context every sim.* function reads, helpers shared by the
// API areas, and the list of API areas. The rest of swarmsim never sees a
// lua_State.
//
// Lua is the Debian C++ build (liblua5.4-c++): compiled as C++, so a Lua
// error is a C++ throw and RAII holds in API functions, but with C linkage,
// so its headers are included through lua.hpp (extern "C").
#pragma once

#include <cstddef>
#include <cstdint>
#include <exception>
#include <string>
#include <string_view>

#include "framework/handle.h"
#include "lua.hpp"

namespace swarmsim {

class Scene;
class World;
struct RobotRuntime;

// A script's read position in its robot's inbox (sim.receiveMessage).
struct ScriptMailbox {
  uint64_t round = 0;  // World::message_round() the position refers to
  uint32_t next = 0;   // next inbox entry to look at
};

// What a sim.* function needs to know about its caller. One per lua_State,
// reached through lua_getextraspace (coroutines inherit it). The host sets
// the script fields before each callback.
struct LuaContext {
  World* world = nullptr;
  Scene* scene = nullptr;
  RobotRuntime* runtime = nullptr;  // the robot's, or the world's scene runtime
  int instance = -1;                // robot index; -1 for the scene state
  std::string name;                 // "footbot#12", or "scene"
  std::string log_prefix;           // "[footbot#12] ", or "[scene] "
  // The script being run.
  ObjectId script_object;
  int script_env_ref = LUA_NOREF;  // its environment table, in the registry
  ScriptMailbox* mailbox = nullptr;
  void* host_state = nullptr;   // the host's ScriptState (script_host.cc)
  void* host_script = nullptr;  // the host's Script being run (script_host.cc)
  bool is_main = false;         // the main script's state
  bool in_sensing = false;      // running a sysCall_sensing (sim.handleChildScript follows it)
  int64_t slice_fires = 0;      // time-slice hook calls since the thread was resumed
  std::string pending_error;    // a World error raised through the main script, verbatim
};

inline LuaContext& Context(lua_State* L) {
  return **static_cast<LuaContext**>(lua_getextraspace(L));
}
inline void SetContext(lua_State* L, LuaContext* context) {
  *static_cast<LuaContext**>(lua_getextraspace(L)) = context;
}

// Raises a Lua error "file:line: message" located at the Lua caller of the
// running C function.
[[noreturn]] void RaiseError(lua_State* L, const std::string& message);

// A function name as a template argument: Guarded<F, "sim.getObject">.
template <size_t N>
struct FunctionName {
  constexpr FunctionName(const char (&name)[N]) {  // NOLINT: implicit on purpose
    for (size_t i = 0; i < N; ++i) text[i] = name[i];
  }
  char text[N];
};

// Runs an API function, turning a C++ exception (swarmsim::Error from the
// Scene, std::bad_alloc, ...) into a Lua error "file:line: name: message" at
// the caller's line. Without this, Lua's own catch(...) would swallow the
// message. Lua's own errors (a thrown lua_longjmp*) pass through untouched.
template <lua_CFunction F, FunctionName kName>
int Guarded(lua_State* L) {
  std::string message;
  try {
    return F(L);
  } catch (const std::exception& e) {
    message = std::string(kName.text) + ": " + e.what();
  }
  RaiseError(L, message);
}

// An object handle argument (an integer, ObjectId::ToInteger()).
inline ObjectId CheckObject(lua_State* L, int arg) {
  return ObjectId::FromInteger(luaL_checkinteger(L, arg));
}
// The optional "relative to" argument: nil or sim.handle_world give null.
ObjectId OptRelativeTo(lua_State* L, int arg);

// Pushes a new array {v[0], ..., v[n-1]}.
void PushNumberArray(lua_State* L, const double* v, int n);

// Each API area adds its functions to the `sim` table on top of the stack
// (and, for base-library replacements such as print, to the globals).
void RegisterObjectsApi(lua_State* L);
void RegisterJointsApi(lua_State* L);
void RegisterSensorsApi(lua_State* L);
void RegisterSimApi(lua_State* L);
void RegisterMessagesApi(lua_State* L);
void RegisterControlApi(lua_State* L);
void RegisterDynamicsApi(lua_State* L);
void RegisterIkApi(lua_State* L);
void RegisterForceSensorApi(lua_State* L);
void RegisterPaintApi(lua_State* L);
void RegisterCustomDataApi(lua_State* L);
void RegisterPluginApi(lua_State* L);

// Pushes the plugin command `name` (registered in the world's
// ModuleRegistry) as a function and returns true; false if there is none.
bool PushPluginCommand(lua_State* L, std::string_view name);

// Creates the global `sim` table and calls every Register...Api above.
void RegisterAllApis(lua_State* L);

// Opens the safe standard libraries (base without file access or binary
// chunks, string, table, math, coroutine, utf8) into the globals.
void OpenSafeLibraries(lua_State* L);
// The libraries of a script state: the safe ones plus the sandboxed io,
// os, require (lua_sandbox.cc), or all of Lua's under trust_scripts.
void OpenSandbox(lua_State* L);

// Constant shared with scripts.
constexpr lua_Integer kHandleWorld = -1;

}  // namespace swarmsim
