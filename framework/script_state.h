// Internal to the Lua host (script_*.cc, lua_api_control.cc): one Lua state
// of the host and its scripts, and the errors that name them.
//
// The host's internals live in namespace lua_host rather than in an
// anonymous namespace per file, since several files share them; the
// namespace keeps generic names (Script, Call, Runs) from meeting another
// file's.
#pragma once

#include <algorithm>
#include <climits>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <string_view>
#include <vector>

#include "framework/handle.h"
#include "framework/lua_api.h"
#include "framework/parameters.h"
#include "framework/scene.h"
#include "framework/script_memory.h"

namespace swarmsim::lua_host {

enum Callback : int { kInit, kSensing, kActuation, kCleanup, kThread, kStep, kCallbackCount };
inline constexpr const char* kCallbackNames[kCallbackCount] = {
    "sysCall_init",    "sysCall_sensing", "sysCall_actuation",
    "sysCall_cleanup", "sysCall_thread",  "sysCall_step"};

// Lua instructions per millisecond of thread time slice: PUC Lua 5.4 runs
// roughly 100 to 300 million simple VM instructions a second on a current
// core, so 100,000 per ms errs on the short side. The default slice, 2 ms
// (CoppeliaSim's), is 200,000 instructions.
inline constexpr int64_t kInstructionsPerMs = 100'000;
inline constexpr int kDefaultSliceInstructions = 200'000;
inline constexpr double kMinSliceInstructions = 1000;

// The time slice of a thread asking for `instructions`: at least 1,000, and
// at most the world's instruction budget (when it has one), so that a
// thread runs no more Lua in a step than a callback may.
inline int SliceInstructions(double instructions, int64_t budget) {
  double slice = std::clamp(instructions, kMinSliceInstructions, static_cast<double>(INT_MAX));
  if (budget > 0) slice = std::min(slice, static_cast<double>(budget));
  return static_cast<int>(slice);
}

// A script attached to one object (or the main script: no object).
struct Script {  // 88 bytes
  uint32_t slot = 0;
  ObjectId object;
  int env_ref = LUA_NOREF;  // environment table, in the registry
  const ScriptSource* source = nullptr;
  int callbacks[kCallbackCount] = {LUA_NOREF, LUA_NOREF, LUA_NOREF,
                                   LUA_NOREF, LUA_NOREF, LUA_NOREF};
  bool initialized = false;        // sysCall_init returned: sysCall_cleanup is due
  bool explicit_handling = false;  // runs only through sim.handleChildScript
  bool disabled = false;           // failed under on_script_error: disable_script
  bool running = false;            // inside a call (no re-entry through handleChildScript)
  bool slice_yielded = false;      // the thread's last yield was its time slice's (SliceHook)
  uint16_t slice_streak = 0;       // steps in a row its slice ran out (kStuckThreadSteps)
  lua_State* thread = nullptr;     // sysCall_thread's coroutine, while it runs
  int thread_ref = LUA_NOREF;      // keeps `thread` alive, in the registry
  int slice_instructions = kDefaultSliceInstructions;
  ScriptMailbox mailbox;
};
static_assert(sizeof(Script) == 88);

// What a Lua state holds, counted in its robot's account (`account`, with
// the data the sim.* calls keep for the robot's scripts: script_memory.h)
// against simulation.script_memory_mb. Past the limit an allocation still
// succeeds (up to kMemorySlack more) but arms a count hook on the state's
// threads; at the next instruction the hook collects garbage and, if the
// account still holds too much, fails the script with its file and line.
// Past limit + slack, or past what the run may still give
// (simulation.run_script_memory_mb), allocations fail (Lua then collects
// and retries, and reports out of memory) and arm the same hook, which then
// fails the callback: a pcall loop around a huge allocation would otherwise
// go on (each refusal costs a full collection). The hooks and the
// allocator are in script_hooks.cc.
struct LuaMemory {
  size_t used = 0;               // bytes of this state's Lua heap
  ScriptMemory own;              // the account of a state that has no robot's (LimitedLua)
  ScriptMemory* account = &own;  // the robot's (World::script_memory)
  bool refused_by_run = false;   // the last allocation refused was refused by the run's limit
  size_t refused_bytes = 0;  // the size of a refused allocation MemoryHook has not reported, or 0
  // The refused request (block and new size) while Lua may retry it after
  // its emergency collection: the next growing call. Equal and granted: the
  // refusal is forgotten (refused_bytes 0). retry_size 0: none pending.
  const void* retry_block = nullptr;
  size_t retry_size = 0;
  // The last allocation refused in the running callback, for the error Lua
  // raises then (LUA_ERRMEM: Lua calls no message handler for it, and the
  // host sees its stack unwound): its size, and where it was asked for.
  // Plain data: written inside the allocator (RecordRefusalPlace).
  size_t refusal_bytes = 0;                  // 0: none in this callback
  char refusal_where[LUA_IDSIZE + 16] = "";  // "file:line: " of the innermost Lua function, or ""
  int refusal_script_line = 0;               // the running script's own innermost line, or 0
  const Script* refusal_script = nullptr;    // that script
  // How the errors name what holds the memory and the limit's setting.
  const char* holder = "the scripts";
  bool plural = true;  // "the scripts hold", "the expression holds"
  const char* setting = "simulation.script_memory_mb; raise it if the data is real";
};
inline constexpr size_t kMemorySlack = size_t{16} << 20;

// Bytes of the generator behind math.random (Lua 5.4's xoshiro256**: 32);
// checked against Lua's when a shared state is made.
inline constexpr size_t kGeneratorBytes = 32;

// A global named sysCall_* that no one calls (a typo, a CoppeliaSim-only
// callback), found at load (script_hints.cc).
struct UncalledSysCall {
  std::string file, name;
  int line = 0;         // where the file defines the function; 0: not a function of its own
  std::string warning;  // the line to log
};

// A lua_State and its heap: one robot's, or several robots' when they
// share a state (simulation.robots_per_lua_state), or the scene's. The
// allocator's `ud`. Robots sharing a state run on one thread at a time
// (`mutex`); `current` is the robot whose script runs or is being set up
// (its context is the state's extra space then: SetContext).
struct LuaHeap {
  lua_State* L = nullptr;
  LuaMemory memory;
  struct ScriptState* current = nullptr;
  bool shared = false;  // several robots' (the mutex is taken)
  std::mutex mutex;
  // Shared states only: their account (the limit is the robots' limits
  // together; memory.account points here), the name the memory errors give
  // them ("the scripts of footbot#0 .. footbot#63"), and math.random's
  // generator (a userdata: each robot's own is copied in while it runs).
  ScriptMemory account;
  std::string holder;
  void* generator = nullptr;
  bool may_finalize = false;     // a member's closing could run code (LuaContext::may_finalize)
  bool leave_to_system = false;  // the process ends: not closed (LuaScriptHost::Stop)
};

// One robot's scripts (or the scene's), in a Lua state of their own or one
// they share with other robots (`heap`).
struct ScriptState {
  std::shared_ptr<LuaHeap> heap;  // set with L (NewState, LimitedLua)
  lua_State* L = nullptr;         // heap->L
  LuaContext context;
  std::vector<Script> scripts;  // hierarchy order
  // With a main script: the LuaScriptHost::main_steps_ of the step whose
  // sim.handleChildScripts resumed the threads (once a step).
  uint64_t threads_resumed_step = 0;
  // The main script's state only: the host's arguments for the child
  // callbacks, which sim.handleChildScripts(pass, ...) sets for its call.
  std::vector<ParamValue>* child_args = nullptr;
  // Start only: sysCall_* names no one calls, for LuaScriptHost::Start to log
  // once per file and name.
  std::vector<UncalledSysCall> warnings;
  // In a shared state: this robot's math.random generator, while another
  // robot's is in the state (LuaHeap::generator).
  alignas(8) unsigned char generator[kGeneratorBytes] = {};

  ScriptState() = default;
  ScriptState(const ScriptState&) = delete;
  ScriptState& operator=(const ScriptState&) = delete;
  // Releases the scripts' references; the last robot of a state closes it.
  ~ScriptState();
};

// Makes `state` the robot its Lua state runs: its context in the state's
// extra space, its math.random generator in the state (a shared state).
void MakeCurrent(ScriptState& state);

// The lua_State the host called or resumed for the running callback: the
// script's thread, or the state's main thread.
inline lua_State* RootOf(const LuaContext& c) {
  return c.thread != nullptr ? c.thread : static_cast<const ScriptState*>(c.host_state)->L;
}

// Does `script` run (not disabled, its object alive and its script enabled)?
inline bool Runs(const Scene& scene, const Script& script) {
  if (script.disabled) return false;
  if (script.slot == UINT32_MAX) return true;  // the main script
  if (!scene.IsValid(script.object)) return false;
  const ScriptAttachment* attachment = scene.script_at(script.slot);
  return attachment != nullptr && attachment->enabled;
}

// "1.0 GiB", "300 MiB", "12 KiB".
std::string FormatBytes(uint64_t bytes);

// "4 MiB of Lua memory (simulation.script_memory_mb; ...)", the end of the
// memory-limit messages (with the data the sim.* calls keep, when there is some).
std::string MemoryLimitTail(const LuaMemory& memory);
// "the run's scripts past 4096 MiB (simulation.run_script_memory_mb)".
std::string RunLimitTail(const ScriptMemory& account);

// The text of the error value on top of the stack; of an allocation the
// memory limit refused (LUA_ERRMEM), where it was asked for and what it
// would have taken.
std::string ErrorText(lua_State* L, int status);

// "file:line: an allocation of 953 MiB would take the scripts past ...":
// the last allocation refused in the running callback, where it was asked
// for (the running script's own line in front when that is another file's).
std::string RefusalText(const ScriptState& state);

// Notes in state.memory where the allocation being refused was asked for:
// the innermost Lua function of `running` (the thread running Lua code).
// Called inside the allocator: reads the stack with lua_getstack and
// lua_getinfo("Sl"), which allocate nothing.
void RecordRefusalPlace(ScriptState& state, lua_State* running);

// Message handler of the host's protected calls of script code (lua_pcall's
// msgh): the error's text (a value that is not a string named by its type),
// with the file:line of the innermost Lua function that has one when the
// text has no position (error(), error({}), math.max(nil, 1), a yield
// outside a thread), and the running script's own file:line in front when
// the position is another file's (a module it required).
int LocateError(lua_State* L);
// The same text for a coroutine that died of an error (its stack is not
// unwound): a sysCall_thread.
std::string LocatedErrorText(lua_State* co, int status, const Script& script);

// Throws "footbot#12: <message> [in <what> of /footbot#12/body]", the
// script's file in front of a message that does not start with it, the
// message cut to kMaxErrorTextBytes (framework/error.h).
[[noreturn]] void ThrowScriptError(const ScriptState& state, const Script& script,
                                   std::string message, std::string_view what);

// Under on_script_error: disable_script, disables `script` and logs `error`
// once; returns false (the caller rethrows) under stop, and for the main script.
bool Disable(ScriptState& state, Script& script, const std::string& error);

}  // namespace swarmsim::lua_host
