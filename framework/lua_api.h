// Internal to the Lua host: included only by script_*.cc and lua_*.cc.
//
// The per-state context every sim.* function reads, helpers shared by the
// API areas, and the list of API areas. The rest of swarmsim never sees a
// lua_State.
//
// Lua is Debian's C build (liblua5.4): a Lua error or a coroutine yield is a
// longjmp (a yield costs ~70 ns; the C++ build's throw costs ~3 us). A
// longjmp skips C++ destructors, so every C function Lua calls is wrapped in
// Guarded<> and reports errors by throwing C++ exceptions (RaiseError, the
// Arg* checks below, swarmsim::Error from the Scene); Guarded turns them
// into the Lua error once no C++ object is alive. Inside a guarded
// function, never call what can raise a Lua error (luaL_check*,
// luaL_error, lua_call of user code, metamethod-invoking gets/sets) while a
// C++ object with a destructor is alive.
#pragma once

#include <cstddef>
#include <cstdint>
#include <exception>
#include <functional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "framework/handle.h"
#include "framework/math.h"
#include "framework/parameters.h"
#include "lua.hpp"

namespace swarmsim {

class PhaseHandlers;
class Scene;
class ScriptMemory;
class World;
struct DeferredWrite;
struct RobotMail;
struct RobotRuntime;

// A script's read position in its robot's inbox (sim.receiveMessage).
struct ScriptMailbox {
  uint64_t round = 0;  // Messaging::round() the position refers to
  uint32_t next = 0;   // next inbox entry to look at
};

// What a sim.* function needs to know about its caller. One per lua_State,
// reached through lua_getextraspace (coroutines inherit it). The host sets
// the script fields before each callback.
struct LuaContext {
  World* world = nullptr;
  PhaseHandlers* phases = nullptr;  // the world's, which sim.handleSensing(), ... run
  Scene* scene = nullptr;
  RobotRuntime* runtime = nullptr;  // the robot's, or the world's scene runtime
  RobotMail* mail = nullptr;        // the robot's, or the scene's (Messaging)
  ScriptMemory* memory = nullptr;   // the robot's account, or the scene's (script_memory.h)
  int instance = -1;                // robot index; -1 for the scene state
  std::string name;                 // "footbot#12", or "scene"
  std::string log_prefix;           // "[footbot#12] ", or "[scene] "
  // The script being run.
  ObjectId script_object;
  int script_env_ref = LUA_NOREF;  // its environment table, in the registry
  ScriptMailbox* mailbox = nullptr;
  void* host_state = nullptr;   // the host's ScriptState (script_state.h)
  void* host_script = nullptr;  // the host's Script being run (script_state.h)
  bool is_main = false;         // the main script's state
  // Whether closing the state could run code or write: io was opened (file
  // handles flush and close in their finalizers), or the sandbox is lifted.
  // Sandboxed scripts cannot set __gc otherwise (lua_sandbox.cc).
  bool may_finalize = false;
  bool in_sensing = false;        // running a sysCall_sensing (sim.handleChildScript follows it)
  bool dynamics_handled = false;  // the main script called sim.handleDynamics() this step
  bool in_main_step = false;      // the main script's sysCall_step is running (the phases' place)
  int64_t slice_fires = 0;        // time-slice hook calls since the thread was resumed
  // The instruction budget of a callback (simulation.instruction_budget; 0:
  // none), and how its error names what ran and the setting that raises it.
  int64_t instruction_budget = 0;
  const char* budget_subject = "the callback";
  const char* budget_setting = "simulation.instruction_budget";  // "": no setting to name
  lua_State* thread = nullptr;  // the script thread being resumed, else null
  // The coroutine the sandbox's coroutine.resume/wrap/close is running (the
  // innermost one), else null: the running callback's root (RootOf). The
  // allocator names its line when it refuses (LimitedAlloc).
  lua_State* running = nullptr;
  // The running callback (or thread resume) used up its instruction budget:
  // every further instruction raises budget_error, and the host reports it.
  bool budget_exhausted = false;
  bool slice_yielded = false;   // the thread being resumed yielded from its time-slice hook
  bool data_collected = false;  // ChargeScriptData collected garbage in this callback
  std::string budget_error;     // "file:line: the callback ran more than ..."
  std::string pending_error;    // a World error raised through the main script, verbatim
};

inline LuaContext& Context(lua_State* L) {
  return **static_cast<LuaContext**>(lua_getextraspace(L));
}
inline void SetContext(lua_State* L, LuaContext* context) {
  *static_cast<LuaContext**>(lua_getextraspace(L)) = context;
}

// Thrown by guarded functions: a Lua error "file:line: message" located at
// the Lua caller of the running C function, without Guarded's name prefix.
struct LuaError : std::runtime_error {
  using std::runtime_error::runtime_error;
};
// Thrown by guarded functions when the Lua error value is already on top of
// the stack (from a lua_pcall of user code): raised as it is.
struct LuaErrorOnStack {};

// Thrown by guarded functions for what the sandbox refuses: like LuaError,
// but it ends the running callback (FailCallback), so pcall cannot turn a
// refusal into a silently missing file or command.
struct LuaRefusal : LuaError {
  using LuaError::LuaError;
};

// Throws LuaError(message); only inside a guarded function.
[[noreturn]] void RaiseError(lua_State* L, const std::string& message);
// Throws LuaRefusal(message); only inside a guarded function.
[[noreturn]] void RaiseRefusal(lua_State* L, const std::string& message);

// Ends the running callback with the error message on top of L's stack, the
// way a spent instruction budget does: every further instruction raises
// again, so pcall and xpcall cannot swallow it, and the host reports the
// message (script_hooks.cc).
[[noreturn]] void FailCallback(lua_State* L);

// Runs `f`; if it throws, leaves the error value on the stack and returns -1
// (a std::exception becomes "file:line: name: what", with no prefix for an
// empty name or a LuaError), or kRefused for a LuaRefusal. Out of line: the
// C++ handlers live in one place.
constexpr int kRefused = -2;
int CallProtected(lua_State* L, lua_CFunction f, const char* name) noexcept;

// A function name as a template argument: Guarded<F, "sim.getObject">.
template <size_t N>
struct FunctionName {
  constexpr FunctionName(const char (&name)[N]) {  // NOLINT: implicit on purpose
    for (size_t i = 0; i < N; ++i) text[i] = name[i];
  }
  char text[N];
};

// Every C function Lua calls: runs F, and raises what it threw as a Lua
// error after every C++ object of F is destroyed.
template <lua_CFunction F, FunctionName kName>
int Guarded(lua_State* L) {
  const int results = CallProtected(L, F, kName.text);
  if (results == kRefused) FailCallback(L);
  return results >= 0 ? results : lua_error(L);
}

// Argument checks for guarded functions: like luaL_check*, but they throw,
// so the error message is "name: bad argument #2 (number expected, got nil)".
lua_Integer ArgInteger(lua_State* L, int arg);
lua_Number ArgNumber(lua_State* L, int arg);
// A string (a number is converted in place, as luaL_checklstring does).
const char* ArgString(lua_State* L, int arg, size_t* length = nullptr);
void ArgType(lua_State* L, int arg, int type);
// The index of `arg` (a string) in the null-terminated `options`; `def` if
// the argument is absent and def is not null. Anything else is an error
// listing the options (and the nearest, for a typo).
int ArgOption(lua_State* L, int arg, const char* def, const char* const options[]);

// The array readers' protocol (sim.readProximitySensors, readGroundSensors,
// readLightSensors): argument 1 is a table of handles, argument 2 an
// optional table filled in place (entries 1 .. #handles; the rest left
// alone), so that a script passing the same table every step allocates
// nothing, else a new table. push(id) pushes one handle's value; an entry
// that is not a handle, or that push rejects by throwing, is an error
// naming it ("handles[2]: ..."). Leaves the filled table at index 2.
// (HandleArrayError in lua_api.cc builds the messages.)
[[noreturn]] void HandleArrayError(lua_State* L, lua_Integer i, const char* why);
template <class Push>
void FillFromHandles(lua_State* L, Push&& push) {
  ArgType(L, 1, LUA_TTABLE);
  if (lua_isnoneornil(L, 2)) {
    lua_settop(L, 1);
    lua_createtable(L, static_cast<int>(lua_rawlen(L, 1)), 0);
  } else {
    ArgType(L, 2, LUA_TTABLE);
    lua_settop(L, 2);
  }
  const lua_Integer n = static_cast<lua_Integer>(lua_rawlen(L, 1));
  for (lua_Integer i = 1; i <= n; ++i) {
    lua_rawgeti(L, 1, i);
    int ok = 0;
    const lua_Integer handle = lua_tointegerx(L, -1, &ok);
    if (!ok) HandleArrayError(L, i, nullptr);
    lua_pop(L, 1);
    try {
      push(ObjectId::FromInteger(handle));
    } catch (const std::exception& e) {
      HandleArrayError(L, i, e.what());
    }
    lua_rawseti(L, 2, i);
  }
}

// Charges `bytes` of the calling script's data that C++ keeps for it to its
// robot's account (ScriptMemory: lines printed, metrics, messages, signals,
// custom data, deferred writes). When they do not fit, collects the state's
// garbage and tries again; then throws an Error naming `what` and the
// limit ("the signal would take the scripts past 256 MiB ...").
void ChargeScriptData(lua_State* L, uint64_t bytes, const char* what);

// Bytes C++ holds for the calling script only while one sim.* call runs (a
// string being packed, a copy of an array): charged to its robot's account
// as they grow, as ChargeScriptData charges (and refuses), and released
// when the call returns or throws.
class CallCharge {
 public:
  CallCharge(lua_State* L, const char* what) : L_(L), what_(what) {}
  ~CallCharge();
  CallCharge(const CallCharge&) = delete;
  CallCharge& operator=(const CallCharge&) = delete;
  // Holds at least `bytes` from now on: charged a quarter ahead, so that a
  // growing buffer is charged now and then, not at every append.
  void Hold(uint64_t bytes) {
    if (bytes > held_) Grow(bytes);
  }

 private:
  void Grow(uint64_t bytes);
  lua_State* L_;
  const char* what_;
  uint64_t held_ = 0;
};

// lua_pushlstring in protected mode, for a guarded function that holds C++
// objects: a refused allocation throws (LuaErrorOnStack) instead of a
// longjmp past their destructors.
void PushBytes(lua_State* L, std::string_view bytes);

// Queues a write to an object another robot (or the scene) owns, applied
// after the control phase (RobotRuntime::deferred), charged to the robot.
void PushDeferredWrite(lua_State* L, const DeferredWrite& write);

// Queues `add` to run on the scene when the caller's copies and removals
// of robots are applied (after the control phase, robots in index order):
// how a module's Lua area makes objects (sim.createPath) the same way for
// any thread count (lua_api_models.cc). `bytes`, what the queued objects
// hold (kSceneObjectBytes each, and their rows' data), are charged to the
// caller's robot for its lifetime (refused as ChargeScriptData refuses,
// naming `what`), released when the robot is removed.
void QueueSceneAddition(lua_State* L, std::function<void(Scene*)> add, uint64_t bytes,
                        const char* what);
// What one object a script makes costs beyond its row's own data: its slot
// in the scene's arrays, its name, its row, the queued closure.
inline constexpr uint64_t kSceneObjectBytes = 512;

// An object handle argument (an integer, ObjectId::ToInteger()).
inline ObjectId CheckObject(lua_State* L, int arg) {
  return ObjectId::FromInteger(ArgInteger(L, arg));
}
// The optional "relative to" argument: nil or sim.handle_world give null.
ObjectId OptRelativeTo(lua_State* L, int arg);

// A colour argument {r, g, b}, each a number from 0 to 1 (paint nozzles,
// LEDs); anything else throws, naming what is expected.
Vec3 ArgColor(lua_State* L, int arg);

// Pushes a new array {v[0], ..., v[n-1]}.
void PushNumberArray(lua_State* L, const double* v, int n);

// Pushes a number a script gave as a value (a parameter, a signal, an
// argument of sim.handleChildScripts), stored as a double: integral and
// within +-2^53 (exact in a double) as a Lua integer, so 10 stays 10 and
// '/st#' .. (i % n) reads '/st#3', not '/st#3.0'; otherwise as a float.
inline void PushValueNumber(lua_State* L, double value) {
  constexpr double kMaxExactInteger = 9007199254740992.0;  // 2^53
  // NaN fails the range test; a cast back detects a fractional part.
  if (value >= -kMaxExactInteger && value <= kMaxExactInteger &&
      static_cast<double>(static_cast<lua_Integer>(value)) == value)
    lua_pushinteger(L, static_cast<lua_Integer>(value));
  else
    lua_pushnumber(L, value);
}
// Pushes a parameter or signal value: number (PushValueNumber), boolean or string.
void PushParamValue(lua_State* L, const ParamValue& value);

// Each API area adds its functions to the `sim` table on top of the stack
// (and, for base-library replacements such as print, to the globals).
void RegisterObjectsApi(lua_State* L);
void RegisterJointsApi(lua_State* L);
void RegisterSimApi(lua_State* L);
void RegisterMessagesApi(lua_State* L);
void RegisterControlApi(lua_State* L);
void RegisterDynamicsApi(lua_State* L);
void RegisterCustomDataApi(lua_State* L);
void RegisterPluginSensorApi(lua_State* L);
void RegisterModelsApi(lua_State* L);

// Pushes the plugin command `name` (registered in the world's
// ModuleRegistry) as a function and returns true; false if there is none.
bool PushPluginCommand(lua_State* L, std::string_view name);

// Creates the global `sim` table and calls every Register...Api above.
void RegisterAllApis(lua_State* L);

// The libraries of a script state: the safe ones plus the sandboxed io,
// os, require (lua_sandbox.cc), or all of Lua's under trust_scripts.
void OpenSandbox(lua_State* L);

// The generator behind the state's math.random (a userdata; `bytes` its
// size), kept alive by a registry reference whatever the scripts do to
// math; null if math.random is not Lua's. May raise (memory): protected.
void* PinRandomGenerator(lua_State* L, size_t* bytes);

// Constant shared with scripts.
constexpr lua_Integer kHandleWorld = -1;
// A script's own collections (lua_api_collections.cc): kScriptCollectionBase
// for its robot's first, then one lower each.
constexpr lua_Integer kScriptCollectionBase = -1000;
// The slots of the collection or object at argument `arg`: a script's
// collection or a collection object stands for its objects, any other object
// for itself and everything below it. Ascending. Throws for a bad handle.
std::vector<uint32_t> CollectionArgSlots(lua_State* L, int arg);

}  // namespace swarmsim
