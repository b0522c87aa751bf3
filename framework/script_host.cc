// The Lua scripting host.
//
// One lua_State per robot (model instance) and one for the scripts outside
// any robot. Each script runs in its own environment table whose __index is
// the state's shared globals (sim, the safe libraries), so globals of one
// script do not leak into another. A source is compiled once per state as
// `function(_ENV, ...) <code> end` and called once per script with that
// script's environment; the callbacks it defines are looked up once, kept as
// registry references, and called without string lookups every step.
//
// Child scripts run in hierarchy order (a parent's before its descendants',
// siblings in scene order). An explicit script runs only when an ancestor's
// script calls sim.handleChildScript(handle, ...). A script defining
// sysCall_thread runs it as a coroutine, resumed once a step with the
// actuation callbacks (with a main script calling sim.handleChildScripts
// more than once a step, in the first pass that runs them) until it yields
// (sim.step/sim.switchThread) or its time slice runs out: a count hook that
// yields, so the slice is a number of Lua instructions (kInstructionsPerMs
// per millisecond of sim.setThreadSwitchTiming, at most the instruction
// budget) and results do not depend on machine speed.
// Only the script's thread itself is yielded: a coroutine the script makes
// inherits the hook but runs under the instruction budget instead.
// Every non-threaded callback runs under an instruction budget (count hook
// that raises an error); explicit scripts run on their caller's. Once a
// callback used up its budget every further instruction raises again, so
// pcall cannot catch it, and the host reports the budget error whatever
// error value the callback returns.
#include "framework/script_host.h"

#include <algorithm>
#include <atomic>
#include <cctype>
#include <climits>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <mutex>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "framework/error.h"
#include "framework/lua_api.h"
#include "framework/scene.h"
#include "framework/scheduler.h"
#include "framework/suggest.h"
#include "framework/world.h"

namespace swarmsim {
namespace {

enum Callback : int { kInit, kSensing, kActuation, kCleanup, kThread, kStep, kCallbackCount };
constexpr const char* kCallbackNames[kCallbackCount] = {"sysCall_init",      "sysCall_sensing",
                                                        "sysCall_actuation", "sysCall_cleanup",
                                                        "sysCall_thread",    "sysCall_step"};

// The callbacks each kind of script gets called: child scripts (a robot's,
// the scene's), explicit child scripts (through sim.handleChildScript) and
// the world's main script.
constexpr Callback kChildCallbacks[] = {kInit, kSensing, kActuation, kCleanup, kThread};
constexpr Callback kExplicitCallbacks[] = {kInit, kSensing, kActuation, kCleanup};
constexpr Callback kMainCallbacks[] = {kInit, kStep, kCleanup};

// Lua instructions per millisecond of thread time slice: PUC Lua 5.4 runs
// roughly 100 to 300 million simple VM instructions a second on a current
// core, so 100,000 per ms errs on the short side. The default slice, 2 ms
// (CoppeliaSim's), is 200,000 instructions.
constexpr int64_t kInstructionsPerMs = 100'000;
constexpr int kDefaultSliceInstructions = 200'000;
constexpr double kMinSliceInstructions = 1000;

// The time slice of a thread asking for `instructions`: at least 1,000, and
// at most the world's instruction budget (when it has one), so that a
// thread runs no more Lua in a step than a callback may.
int SliceInstructions(double instructions, int64_t budget) {
  double slice = std::clamp(instructions, kMinSliceInstructions, static_cast<double>(INT_MAX));
  if (budget > 0) slice = std::min(slice, static_cast<double>(budget));
  return static_cast<int>(slice);
}

// Robots started per task: starting one compiles its scripts and runs their
// bodies and sysCall_init, a few tens of microseconds.
constexpr int64_t kStartGrain = 4;

// Registry key of the metatable shared by the script environments of a state.
const char kEnvironmentMetatableKey = 0;

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
  lua_State* thread = nullptr;     // sysCall_thread's coroutine, while it runs
  int thread_ref = LUA_NOREF;      // keeps `thread` alive, in the registry
  int slice_instructions = kDefaultSliceInstructions;
  ScriptMailbox mailbox;
};
static_assert(sizeof(Script) == 88);

// What a Lua state holds, against simulation.script_memory_limit. Past the
// limit an allocation still succeeds (up to kMemorySlack more) but arms a
// count hook on the state's threads; at the next instruction the hook
// collects garbage and, if the state still holds too much, fails the
// script with its file and line. Past limit + slack allocations fail (Lua
// then collects and retries, and reports out of memory) and arm the same
// hook, which then fails the callback: a pcall loop around a huge
// allocation would otherwise go on (each refusal costs a full collection).
struct LuaMemory {
  size_t used = 0;           // bytes
  size_t limit = 0;          // bytes; 0: no limit
  bool refused = false;      // the last allocation was refused (limit + slack)
  size_t refused_bytes = 0;  // the size of a refused allocation MemoryHook has not reported, or 0
};
constexpr size_t kMemorySlack = size_t{16} << 20;

// A global named sysCall_* that no one calls (a typo, a CoppeliaSim-only
// callback), found at load.
struct UncalledSysCall {
  std::string file, name;
  int line = 0;         // where the file defines the function; 0: not a function of its own
  std::string warning;  // the line to log
};

// One lua_State and its scripts: a robot's, or the scene's.
struct ScriptState {
  lua_State* L = nullptr;
  LuaContext context;
  std::vector<Script> scripts;  // hierarchy order
  LuaMemory memory;
  // With a main script: the LuaScriptHost::main_steps_ of the step whose
  // sim.handleChildScripts resumed the threads (once a step).
  uint64_t threads_resumed_step = 0;
  // The main script's state only: the host's arguments for the child
  // callbacks, which sim.handleChildScripts(pass, ...) sets for its call.
  std::vector<ParamValue>* child_args = nullptr;
  // Start only: sysCall_* names no one calls, for LuaScriptHost::Start to log
  // once per file and name.
  std::vector<UncalledSysCall> warnings;

  ScriptState() = default;
  ScriptState(const ScriptState&) = delete;
  ScriptState& operator=(const ScriptState&) = delete;
  ~ScriptState() {
    if (L != nullptr) lua_close(L);
  }
};

// An error outside any protected call (out of memory while setting a state
// up) would otherwise abort the process. Throwing from the panic function
// unwinds through Lua's C frames (built with unwind tables on Debian); the
// state is not used again.
int ThrowOnPanic(lua_State* L) {
  const char* message = lua_tostring(L, -1);
  throw Error(std::string("Lua: ") + (message != nullptr ? message : "unprotected error"));
}

// The text of the error value on top of the stack.
// "4 MiB of Lua memory (simulation.script_memory_mb; ...)", the end of both
// memory-limit messages.
std::string MemoryLimitTail(const LuaMemory& memory) {
  return std::to_string(memory.limit >> 20) +
         " MiB of Lua memory (simulation.script_memory_mb; raise it if the data is real)";
}
// "1.0 GiB", "300 MiB", "12 KiB": a refused allocation's size.
std::string FormatBytes(size_t bytes) {
  char text[32];
  if (bytes >= (size_t{1} << 30))
    std::snprintf(text, sizeof text, "%.1f GiB", static_cast<double>(bytes) / (1 << 30));
  else if (bytes >= (size_t{1} << 20))
    std::snprintf(text, sizeof text, "%zu MiB", bytes >> 20);
  else
    std::snprintf(text, sizeof text, "%zu KiB", (bytes + 1023) >> 10);
  return text;
}
std::string MemoryLimitText(const LuaMemory& memory) {
  return "the scripts hold more than " + MemoryLimitTail(memory);
}
std::string ErrorText(lua_State* L, int status) {
  if (status == LUA_ERRMEM) {
    const auto* state = static_cast<const ScriptState*>(Context(L).host_state);
    if (state != nullptr && state->memory.refused)
      return "an allocation would take the scripts past " + MemoryLimitTail(state->memory);
    return "not enough memory";
  }
  if (status != LUA_ERRRUN && status != LUA_ERRSYNTAX && status != LUA_ERRERR)
    return "internal error: a C++ exception crossed a Lua frame (please report this)";
  if (lua_type(L, -1) == LUA_TSTRING) return lua_tostring(L, -1);
  return std::string("(error object is a ") + luaL_typename(L, -1) + " value)";
}

[[noreturn]] void ThrowScriptError(const ScriptState& state, ObjectId object, std::string message,
                                   std::string_view what) {
  lua_settop(state.L, 0);
  const Scene& scene = *state.context.scene;
  const std::string path = scene.IsValid(object)   ? scene.PathOf(object)
                           : state.context.is_main ? std::string("the main script")
                                                   : std::string("?");
  throw Error(state.context.name + ": " + message + " [in " + std::string(what) + " of " + path +
              "]");
}

// "file:line: " of the Lua function a hook interrupted, or "".
std::string HookWhere(lua_State* L, lua_Debug* ar) {
  if (lua_getinfo(L, "Sl", ar) == 0 || ar->currentline <= 0) return "";
  return std::string(ar->short_src) + ":" + std::to_string(ar->currentline) + ": ";
}

// The lua_State the host called or resumed for the running callback: the
// script's thread, or the state's main thread.
lua_State* RootOf(const LuaContext& c) {
  return c.thread != nullptr ? c.thread : static_cast<const ScriptState*>(c.host_state)->L;
}

// Count hook once the running callback has used up its budget: every further
// instruction raises again, so pcall and xpcall cannot swallow the error.
// It is raised as Lua's memory error (lua_error recognizes Lua's own "not
// enough memory" string): an error raised from a hook would otherwise call
// xpcall's message handler with hooks off, free to loop forever. The Lua
// code sees "not enough memory"; the host reports budget_error.
void ExhaustedHook(lua_State* L, lua_Debug*) {
  lua_pushliteral(L, "not enough memory");
  lua_error(L);
}

// The running callback used up its budget: records `message` (the first
// one), arms ExhaustedHook on L and on the callback's root state (so that
// neither a new coroutine, which copies its creator's hook, nor the caller
// gets a fresh count) and raises. Call() and ResumeThread() report
// budget_error whatever error value reaches them.
template <typename MakeMessage>
void ExhaustBudget(lua_State* L, MakeMessage make_message) {
  LuaContext& c = Context(L);
  if (!c.budget_exhausted) {
    c.budget_exhausted = true;
    c.budget_error = make_message();  // a member: nothing is left to destroy at the longjmp
  }
  lua_sethook(L, ExhaustedHook, LUA_MASKCOUNT, 1);
  lua_sethook(RootOf(c), ExhaustedHook, LUA_MASKCOUNT, 1);
  ExhaustedHook(L, nullptr);
}

}  // namespace

void FailCallback(lua_State* L) {
  ExhaustBudget(L, [&] {
    size_t length = 0;
    const char* message = lua_tolstring(L, -1, &length);
    return message != nullptr ? std::string(message, length) : std::string("refused");
  });
  // ExhaustBudget raises (lua_error does not return, though Lua does not
  // declare it so).
  __builtin_unreachable();
}

namespace {

// Count hook of non-threaded callbacks: the budget is used up.
void BudgetHook(lua_State* L, lua_Debug* ar) {
  ExhaustBudget(L, [&] {
    return HookWhere(L, ar) + "the callback ran more than " +
           std::to_string(Context(L).world->settings().instruction_budget) +
           " Lua instructions without returning (an endless loop?); if the work is real, raise "
           "simulation.instruction_budget";
  });
}

// A fresh budget for the next callback on L. Without a budget (0), a spent
// one's ExhaustedHook (left by the memory limit) goes, or it would fail every
// later callback of the state.
void SetBudget(lua_State* L, const LuaContext& c) {
  const int64_t budget = c.world->settings().instruction_budget;
  if (budget > 0)
    lua_sethook(L, BudgetHook, LUA_MASKCOUNT, static_cast<int>(std::min<int64_t>(budget, INT_MAX)));
  else if (lua_gethook(L) == ExhaustedHook)
    lua_sethook(L, nullptr, 0, 0);
}

// Count hook of threads: the time slice is used up; yield if Lua can and L
// is the script's thread itself. A coroutine of the script's own inherits
// the hook (lua_newthread copies it) but is never yielded: that would hand
// control back to its resumer, not to the simulation. There, and inside a
// call that cannot yield (a C function calling Lua, e.g. a table.sort
// comparator), the instruction budget applies instead.
void SliceHook(lua_State* L, lua_Debug* ar) {
  LuaContext& c = Context(L);
  if (c.thread == nullptr) {
    // A coroutine made by the thread, resumed from a non-threaded callback:
    // that callback's budget regime applies from now on.
    SetBudget(L, c);
    return;
  }
  if (L == c.thread && lua_isyieldable(L)) {
    c.slice_yielded = true;
    lua_yield(L, 0);
    return;
  }
  const int64_t budget = c.world->settings().instruction_budget;
  const int count = lua_gethookcount(L);
  if (budget > 0 && ++c.slice_fires * count > budget) {
    ExhaustBudget(L, [&] {
      return HookWhere(L, ar) + "the thread ran more than " + std::to_string(budget) +
             " Lua instructions in a coroutine of its own or a call that cannot yield";
    });
  }
}

// Count hook armed when a state's memory passed the limit (LuaMemory).
void MemoryHook(lua_State* L, lua_Debug* ar) {
  auto* state = static_cast<ScriptState*>(Context(L).host_state);
  if (const size_t refused = std::exchange(state->memory.refused_bytes, 0); refused > 0) {
    ExhaustBudget(L, [&] {
      return HookWhere(L, ar) + "an allocation of " + FormatBytes(refused) +
             " would take the scripts past " + MemoryLimitTail(state->memory);
    });
  }
  lua_gc(L, LUA_GCCOLLECT);
  // Still too much: fails the callback as a spent budget does, so pcall and
  // xpcall's handler cannot catch it and go on allocating.
  if (state->memory.used > state->memory.limit)
    ExhaustBudget(L, [&] { return HookWhere(L, ar) + MemoryLimitText(state->memory); });
  // Garbage only: the threads get their usual hooks back (the exhausted
  // budget's, if it ran out).
  SetBudget(state->L, state->context);
  for (const Script& script : state->scripts)
    if (script.thread != nullptr)
      lua_sethook(script.thread, SliceHook, LUA_MASKCOUNT, script.slice_instructions);
  if (state->context.budget_exhausted) {
    lua_sethook(L, ExhaustedHook, LUA_MASKCOUNT, 1);
    lua_sethook(RootOf(state->context), ExhaustedHook, LUA_MASKCOUNT, 1);
  }
}

// lua_Alloc of every state: realloc/free, counting against the limit.
void* LimitedAlloc(void* ud, void* ptr, size_t osize, size_t nsize) {
  auto* state = static_cast<ScriptState*>(ud);
  LuaMemory& m = state->memory;
  const size_t old = ptr != nullptr ? osize : 0;
  if (nsize == 0) {
    std::free(ptr);
    m.used -= old;
    return nullptr;
  }
  if (m.limit > 0 && nsize > old) {
    const size_t after = m.used + (nsize - old);
    const bool refuse = after > m.limit + kMemorySlack || after < m.used;
    if (refuse) {
      m.refused = true;
      m.refused_bytes = nsize - old;
    }
    if ((after > m.limit || refuse) && state->L != nullptr) {
      // Armed on every thread whose hook is another (a callback's budget hook
      // set since would otherwise leave only the hard cap). lua_sethook may
      // be called at any point (even from a signal handler).
      const auto arm = [](lua_State* T) {
        if (lua_gethook(T) != MemoryHook) lua_sethook(T, MemoryHook, LUA_MASKCOUNT, 1);
      };
      arm(state->L);
      for (const Script& script : state->scripts)
        if (script.thread != nullptr) arm(script.thread);
    }
    if (refuse) return nullptr;
  }
  void* p = std::realloc(ptr, nsize);
  if (p == nullptr) return nullptr;
  m.used = m.used - old + nsize;
  m.refused = false;
  return p;
}

// --- Calls in progress (ScriptCallsInProgress) ------------------------------------------
// Each thread that runs scripts keeps a record of the innermost call it is
// in. The records are never freed (a thread may end; its record stays, idle),
// so a watchdog can read them at any time.
struct CallRecord {
  std::atomic<const ScriptState*> state{nullptr};
  std::atomic<const Script*> script{nullptr};
  std::atomic<const char*> what{nullptr};
};
std::mutex g_call_records_mutex;
std::vector<CallRecord*>& CallRecords() {
  static auto* records = new std::vector<CallRecord*>;  // leaked on purpose, as the records
  return *records;
}
CallRecord& ThisThreadsRecord() {
  thread_local CallRecord* record = [] {
    auto* r = new CallRecord;
    const std::lock_guard lock(g_call_records_mutex);
    CallRecords().push_back(r);
    return r;
  }();
  return *record;
}

// Marks the calling thread as running `what` of a script of `state` for the
// scope's duration (SetCurrent names the script); restores the outer call.
class CallInProgress {
 public:
  CallInProgress(const ScriptState& state, const char* what)
      : record_(ThisThreadsRecord()),
        state_(record_.state.load(std::memory_order_relaxed)),
        script_(record_.script.load(std::memory_order_relaxed)),
        what_(record_.what.load(std::memory_order_relaxed)) {
    record_.what.store(what, std::memory_order_relaxed);
    record_.state.store(&state, std::memory_order_release);
  }
  ~CallInProgress() {
    record_.state.store(state_, std::memory_order_relaxed);
    record_.script.store(script_, std::memory_order_relaxed);
    record_.what.store(what_, std::memory_order_relaxed);
  }
  CallInProgress(const CallInProgress&) = delete;
  CallInProgress& operator=(const CallInProgress&) = delete;

 private:
  CallRecord& record_;
  const ScriptState* state_;
  const Script* script_;
  const char* what_;
};

void SetCurrent(ScriptState& state, Script& script) {
  state.context.script_object = script.object;
  state.context.script_env_ref = script.env_ref;
  state.context.mailbox = &script.mailbox;
  state.context.host_script = &script;
  ThisThreadsRecord().script.store(&script, std::memory_order_relaxed);
}

// Calls the function below `nargs` arguments on the stack as `script`,
// under the instruction budget. Throws swarmsim::Error naming the robot,
// file:line, `what` and the object. Once the budget ran out, that is the
// error reported, whatever error value the call returns.
void Call(ScriptState& state, Script& script, int nargs, const char* what) {
  const CallInProgress in_progress(state, what);
  SetCurrent(state, script);
  state.context.budget_exhausted = false;
  state.memory.refused_bytes = 0;  // reported with the callback that made it
  SetBudget(state.L, state.context);
  script.running = true;
  const int status = lua_pcall(state.L, nargs, 0, 0);
  script.running = false;
  if (!state.context.pending_error.empty()) {
    // A World error passed up through the main script: report it as is,
    // also when the script caught it (pcall(sim.handleDynamics)): the world
    // is broken and must not go on.
    std::string error;
    error.swap(state.context.pending_error);
    lua_settop(state.L, 0);
    throw Error(error);
  }
  if (status != LUA_OK) {
    if (state.context.budget_exhausted)
      ThrowScriptError(state, script.object, state.context.budget_error, what);
    ThrowScriptError(state, script.object, ErrorText(state.L, status), what);
  }
}

// Under on_script_error: disable_script, disables `script` and logs `error`
// once; returns false (the caller rethrows) under stop, and for the main script.
bool Disable(ScriptState& state, Script& script, const std::string& error) {
  if (state.context.world->settings().on_script_error != ScriptErrorPolicy::kDisableScript ||
      state.context.is_main)
    return false;
  script.disabled = true;
  state.context.runtime->log.Add("error, script disabled: " + error);
  state.context.runtime->disabled.push_back(error);
  return true;
}

// Protected part of creating a state. Arguments: two integers seeding math.random.
int SetUpState(lua_State* L) {
  OpenSandbox(L);
  RegisterAllApis(L);
  // Lua's own math.random, reproducible per robot.
  lua_getglobal(L, LUA_MATHLIBNAME);
  lua_getfield(L, -1, "randomseed");
  lua_pushvalue(L, 1);
  lua_pushvalue(L, 2);
  lua_call(L, 2, 0);
  lua_pop(L, 1);
  // Script environments read what they do not define from the shared globals.
  lua_createtable(L, 0, 1);
  lua_pushglobaltable(L);
  lua_setfield(L, -2, "__index");
  lua_rawsetp(L, LUA_REGISTRYINDEX, &kEnvironmentMetatableKey);
  return 0;
}

// Feeds lua_load the wrapped source without copying it.
struct ChunkPieces {
  std::string_view pieces[3];
  int next = 0;
};
const char* ReadPieces(lua_State*, void* data, size_t* size) {
  auto* chunk = static_cast<ChunkPieces*>(data);
  while (chunk->next < 3 && chunk->pieces[chunk->next].empty()) ++chunk->next;
  if (chunk->next == 3) {
    *size = 0;
    return nullptr;
  }
  const std::string_view piece = chunk->pieces[chunk->next++];
  *size = piece.size();
  return piece.data();
}

// Compiles `source` into a function(_ENV, ...) running its code, left on
// the stack. The prefix shares the first line, so line numbers in messages
// are the file's own. Returns "" or the compiler's message (for a broken
// source, the message of compiling it as it is, so that it reads naturally).
std::string CompileFactory(lua_State* L, const ScriptSource& source) {
  const std::string chunkname = "@" + (source.path.empty() ? std::string("?") : source.path);
  ChunkPieces chunk{{"return function(_ENV, ...) ", source.code, "\nend"}};
  int status = lua_load(L, ReadPieces, &chunk, chunkname.c_str(), "t");
  if (status == LUA_OK) status = lua_pcall(L, 0, 1, 0);
  if (status == LUA_OK && lua_isfunction(L, -1)) {
    // The function must end at our own 'end': a source like "end, function()"
    // would otherwise close it early and compile into something else.
    lua_Debug ar;
    lua_pushvalue(L, -1);
    lua_getinfo(L, ">S", &ar);
    const int last_line =
        2 + static_cast<int>(std::count(source.code.begin(), source.code.end(), '\n'));
    if (ar.linedefined == 1 && ar.lastlinedefined == last_line) return "";
  }
  std::string message = status == LUA_OK ? std::string() : ErrorText(L, status);
  lua_pop(L, 1);
  status = luaL_loadbufferx(L, source.code.data(), source.code.size(), chunkname.c_str(), "t");
  if (status != LUA_OK) message = ErrorText(L, status);
  lua_pop(L, 1);
  return message.empty() ? chunkname.substr(1) + ": the script does not compile" : message;
}

// A registry reference to the callback `name` the script defines (not one
// inherited from the shared globals), or LUA_NOREF. CheckSysCallNames has
// made sure that the ones the script gets called are functions.
int FindCallback(lua_State* L, const Script& script, const char* name) {
  lua_rawgeti(L, LUA_REGISTRYINDEX, script.env_ref);
  lua_pushstring(L, name);
  lua_rawget(L, -2);
  const int ref = lua_isfunction(L, -1) ? luaL_ref(L, LUA_REGISTRYINDEX) : LUA_NOREF;
  lua_settop(L, 0);
  return ref;
}

// Throws "<file>: sysCall_init must be a function (got number)" (with the
// robot and object) if the script's global `name` is neither nil nor a function.
void CheckIsFunction(ScriptState& state, const Script& script, const char* name) {
  lua_State* L = state.L;
  lua_rawgeti(L, LUA_REGISTRYINDEX, script.env_ref);
  lua_pushstring(L, name);
  const int type = lua_rawget(L, -2);
  lua_settop(L, 0);
  if (type == LUA_TNIL || type == LUA_TFUNCTION) return;
  ThrowScriptError(
      state, script.object,
      script.source->path + ": " + name + " must be a function (got " + lua_typename(L, type) + ")",
      "loading the script");
}

// CoppeliaSim callbacks a ported script may define, which swarmsim never
// calls, and what to do instead.
struct PortedCallback {
  const char* name;
  const char* hint;
};
constexpr PortedCallback kCoppeliaSimCallbacks[] = {
    {"sysCall_beforeSimulation", "put its code in sysCall_init"},
    {"sysCall_afterSimulation", "put its code in sysCall_cleanup"},
    {"sysCall_nonSimulation", "scripts run only while simulating"},
    {"sysCall_beforeMainScript", "a world's own main script is simulation.main_script"},
    {"sysCall_suspend", "a run is never paused"},
    {"sysCall_suspended", "a run is never paused"},
    {"sysCall_resume", "a run is never paused"},
    {"sysCall_realTimeIdle", "a run is never paused"},
    {"sysCall_beforeInstanceSwitch", "there is one scene"},
    {"sysCall_afterInstanceSwitch", "there is one scene"},
    {"sysCall_beforeSave", "scenes are never saved"},
    {"sysCall_afterSave", "scenes are never saved"},
    {"sysCall_afterLoad", "put its code in sysCall_init"},
    {"sysCall_beforeCopy", "scripts are not told of copies"},
    {"sysCall_afterCopy", "scripts are not told of copies"},
    {"sysCall_afterCreate", "put its code in sysCall_init"},
    {"sysCall_beforeDelete", "scripts are not told of deletions"},
    {"sysCall_afterDelete", "scripts are not told of deletions"},
    {"sysCall_dynCallback", "the physics engines call no scripts"},
    {"sysCall_jointCallback",
     "the physics engines call no scripts; drive joints with sim.setJointTargetVelocity/Position"},
    {"sysCall_contactCallback", "the physics engines call no scripts"},
    {"sysCall_vision", "there are no vision sensors"},
    {"sysCall_trigger", "read proximity sensors with sim.readProximitySensor"},
    {"sysCall_userConfig", "runs are headless"},
    {"sysCall_selChange", "runs are headless"},
    {"sysCall_msg", "read messages with sim.receiveMessage"},
    {"sysCall_event", "runs are headless"},
    {"sysCall_addOnScriptSuspend", "there are no add-ons"},
    {"sysCall_addOnScriptResume", "there are no add-ons"},
    {"sysCall_moduleEntry", "there are no add-ons"},
};

// Why swarmsim never calls the script's global `name` (a sysCall_* it does
// not call for this kind of script), as the end of a warning.
std::string UncalledHint(std::string_view name, std::span<const Callback> called, bool is_main,
                         bool explicit_handling) {
  for (const PortedCallback& ported : kCoppeliaSimCallbacks)
    if (name == ported.name) return std::string("it is CoppeliaSim's; ") + ported.hint;
  if (name == kCallbackNames[kStep])
    return "only the world's main script, simulation.main_script, has a sysCall_step";
  if (is_main && (name == kCallbackNames[kSensing] || name == kCallbackNames[kActuation] ||
                  name == kCallbackNames[kThread]))
    return "the main script runs sysCall_init, sysCall_step and sysCall_cleanup; it runs the "
           "robots' callbacks with sim.handleChildScripts";
  if (explicit_handling && name == kCallbackNames[kThread])
    return "an explicit script runs only through sim.handleChildScript, which calls its "
           "sysCall_sensing or sysCall_actuation";
  std::vector<std::string> names;
  for (Callback callback : called) names.emplace_back(kCallbackNames[callback]);
  if (const std::string* nearest = NearestName(name, names))
    return "did you mean " + *nearest + "?";
  std::string list = "it calls ";
  for (size_t i = 0; i < names.size(); ++i)
    list += (i == 0 ? "" : i + 1 == names.size() ? " and " : ", ") + names[i];
  return list;
}

// Once per script at load, after sysCall_init (which may define callbacks):
// a callback the script gets called must be a function (else a script error
// naming the file and the callback); any other global named sysCall_*
// (case aside: a typo, a CoppeliaSim callback) gets a warning in
// state.warnings, which LuaScriptHost::Start logs once per file. Warnings are
// in line order, then name order (the table's order is not deterministic);
// names that are not functions of the file's own come last.
void CheckSysCallNames(ScriptState& state, const Script& script) {
  lua_State* L = state.L;
  const bool is_main = state.context.is_main;
  const std::span<const Callback> called = is_main ? std::span<const Callback>(kMainCallbacks)
                                           : script.explicit_handling
                                               ? std::span<const Callback>(kExplicitCallbacks)
                                               : std::span<const Callback>(kChildCallbacks);
  std::vector<UncalledSysCall> uncalled;
  const std::string& path = script.source->path;
  lua_rawgeti(L, LUA_REGISTRYINDEX, script.env_ref);
  lua_pushnil(L);
  while (lua_next(L, -2) != 0) {
    size_t length = 0;
    const char* key = lua_type(L, -2) == LUA_TSTRING ? lua_tolstring(L, -2, &length) : nullptr;
    constexpr std::string_view kPrefix = "syscall_";
    if (key == nullptr || length < kPrefix.size() ||
        !std::equal(kPrefix.begin(), kPrefix.end(), key, [](char a, char b) {
          return a == std::tolower(static_cast<unsigned char>(b));
        })) {
      lua_pop(L, 1);
      continue;
    }
    const std::string_view name(key, length);
    const bool is_called = std::any_of(called.begin(), called.end(), [&](Callback callback) {
      return name == kCallbackNames[callback];
    });
    if (is_called) {
      if (lua_type(L, -1) != LUA_TFUNCTION) {
        const std::string message = path + ": " + std::string(name) + " must be a function (got " +
                                    luaL_typename(L, -1) + ")";
        ThrowScriptError(state, script.object, message, "loading the script");
      }
    } else {
      UncalledSysCall& u = uncalled.emplace_back(UncalledSysCall{path, std::string(name), 0, {}});
      if (lua_isfunction(L, -1)) {
        lua_Debug ar;
        lua_pushvalue(L, -1);
        lua_getinfo(L, ">S", &ar);  // pops the copy
        if (ar.source[0] == '@' && path == ar.source + 1 && ar.linedefined > 0)
          u.line = ar.linedefined;
      }
    }
    lua_pop(L, 1);
  }
  lua_settop(L, 0);
  std::sort(uncalled.begin(), uncalled.end(),
            [](const UncalledSysCall& a, const UncalledSysCall& b) {
              const int line_a = a.line > 0 ? a.line : INT_MAX;
              const int line_b = b.line > 0 ? b.line : INT_MAX;
              return line_a != line_b ? line_a < line_b : a.name < b.name;
            });
  for (UncalledSysCall& u : uncalled) {
    u.warning = "warning: " + path;
    if (u.line > 0) u.warning += ":" + std::to_string(u.line) + ":";
    u.warning += " defines " + u.name + ", which swarmsim never calls (" +
                 UncalledHint(u.name, called, is_main, script.explicit_handling) + ")";
    state.warnings.push_back(std::move(u));
  }
}

bool Runs(const Scene& scene, const Script& script) {
  if (script.disabled) return false;
  if (script.slot == UINT32_MAX) return true;  // the main script
  if (!scene.IsValid(script.object)) return false;
  const ScriptAttachment* attachment = scene.script_at(script.slot);
  return attachment != nullptr && attachment->enabled;
}

// A state for the enabled scripts on `slots` (hierarchy order), or null if
// there are none.
std::unique_ptr<ScriptState> NewState(World* world, int instance, RobotRuntime* runtime,
                                      std::string name, const std::vector<uint32_t>& slots,
                                      const ScriptSource* main_source = nullptr) {
  Scene& scene = world->scene();
  auto state = std::make_unique<ScriptState>();
  for (uint32_t slot : slots) {
    const ScriptAttachment* attachment = scene.script_at(slot);
    if (attachment == nullptr || !attachment->enabled) continue;
    Script script;
    script.slot = slot;
    script.object = scene.IdAt(slot);
    script.source = attachment->source.get();
    script.explicit_handling = attachment->explicit_handling;
    state->scripts.push_back(script);
  }
  if (main_source != nullptr) {
    Script script;
    script.slot = UINT32_MAX;
    script.source = main_source;
    state->scripts.push_back(script);
    state->context.is_main = true;
  }
  if (state->scripts.empty()) return nullptr;
  LuaContext& c = state->context;
  c.world = world;
  c.phases = world;
  c.scene = &scene;
  c.runtime = runtime;
  c.instance = instance;
  c.log_prefix = "[" + name + "] ";
  c.name = std::move(name);
  c.host_state = state.get();
  state->memory.limit =
      static_cast<size_t>(std::max<int64_t>(world->settings().script_memory_limit, 0));
  lua_State* L = lua_newstate(LimitedAlloc, state.get());
  if (L == nullptr) throw Error(c.name + ": not enough memory for a Lua state");
  state->L = L;
  lua_atpanic(L, ThrowOnPanic);
  SetContext(L, &c);
  lua_pushcfunction(L, SetUpState);
  lua_pushinteger(L, static_cast<lua_Integer>(runtime->rng.NextU64()));
  lua_pushinteger(L, static_cast<lua_Integer>(runtime->rng.NextU64()));
  if (const int status = lua_pcall(L, 2, 0, 0); status != LUA_OK)
    throw Error(c.name + ": cannot set up the Lua state: " + ErrorText(L, status));
  return state;
}

// Runs every script's body, then every sysCall_init, in hierarchy order.
void Initialize(ScriptState* state) {
  lua_State* L = state->L;
  // Bodies. Each distinct source is compiled once for the state.
  std::vector<std::pair<const ScriptSource*, int>> factories;
  for (Script& script : state->scripts) {
    const ScriptSource& source = *script.source;
    auto it = std::find_if(factories.begin(), factories.end(),
                           [&](const auto& f) { return f.first == &source; });
    if (it == factories.end()) {
      std::string message = CompileFactory(L, source);
      if (!message.empty())
        ThrowScriptError(*state, script.object, std::move(message), "loading the script");
      factories.emplace_back(&source, luaL_ref(L, LUA_REGISTRYINDEX));
      it = factories.end() - 1;
    }
    lua_createtable(L, 0, 4);
    lua_rawgetp(L, LUA_REGISTRYINDEX, &kEnvironmentMetatableKey);
    lua_setmetatable(L, -2);
    // _G is the script's own environment too. `sim` is copied in: a direct
    // hit instead of a miss then __index saves ~15% of a sensor-heavy step.
    lua_pushvalue(L, -1);
    lua_setfield(L, -2, "_G");
    lua_getglobal(L, "sim");
    lua_setfield(L, -2, "sim");
    script.env_ref = luaL_ref(L, LUA_REGISTRYINDEX);
    lua_rawgeti(L, LUA_REGISTRYINDEX, it->second);
    lua_rawgeti(L, LUA_REGISTRYINDEX, script.env_ref);
    try {
      Call(*state, script, 1, "the main chunk");
    } catch (const Error& e) {
      if (!Disable(*state, script, e.what())) throw;
    }
  }
  // The bodies' code is not needed any more (the callbacks they defined
  // keep their own prototypes).
  for (const auto& factory : factories) luaL_unref(L, LUA_REGISTRYINDEX, factory.second);
  // sysCall_init, then the per-step callbacks (sysCall_init may define them).
  for (Script& script : state->scripts) {
    if (script.disabled) continue;  // its main chunk failed (disable_script)
    try {
      CheckIsFunction(*state, script, kCallbackNames[kInit]);
      if (const int init = FindCallback(L, script, kCallbackNames[kInit]); init != LUA_NOREF) {
        lua_rawgeti(L, LUA_REGISTRYINDEX, init);
        luaL_unref(L, LUA_REGISTRYINDEX, init);
        Call(*state, script, 0, kCallbackNames[kInit]);
      }
      script.initialized = true;
      CheckSysCallNames(*state, script);
    } catch (const Error& e) {
      if (!Disable(*state, script, e.what())) throw;
      continue;
    }
    for (int callback : {kSensing, kActuation, kCleanup, kThread, kStep})
      script.callbacks[callback] = FindCallback(L, script, kCallbackNames[callback]);
    // sysCall_thread becomes a coroutine, first resumed in the first step.
    if (script.callbacks[kThread] != LUA_NOREF && !state->context.is_main) {
      script.thread = lua_newthread(L);
      script.thread_ref = luaL_ref(L, LUA_REGISTRYINDEX);
      lua_rawgeti(script.thread, LUA_REGISTRYINDEX, script.callbacks[kThread]);
      // The default slice (or one sim.setThreadSwitchTiming set already), capped.
      script.slice_instructions = SliceInstructions(
          script.slice_instructions, state->context.world->settings().instruction_budget);
    }
  }
  // Generational collection keeps a robot's heap within ~20% of what it
  // holds (the incremental default lets it double between cycles: 10,000
  // robots would carry ~20 KB of garbage each). In Lua 5.4.4 a full
  // collection in generational mode leaves the next target at twice the
  // heap; one young step after it sets the target from the live size.
  lua_gc(L, LUA_GCGEN, 0, 0);
  lua_gc(L, LUA_GCCOLLECT);
  lua_gc(L, LUA_GCSTEP, 0);
}

// Resumes a script's thread until it yields, returns or fails.
void ResumeThread(ScriptState* state, Script& script) {
  lua_State* co = script.thread;
  LuaContext& c = state->context;
  const CallInProgress in_progress(*state, kCallbackNames[kThread]);
  SetCurrent(*state, script);
  c.thread = co;
  c.budget_exhausted = false;
  state->memory.refused_bytes = 0;  // reported with the callback that made it
  c.slice_fires = 0;
  c.slice_yielded = false;
  // A fresh slice. After a yield from the hook, Lua itself left it so: it
  // set the count to 1 and marked the interrupted instruction, which is
  // executed again on resume; that execution resets the count to the slice
  // and, seeing the mark, skips the hook. Resetting the count here would let
  // the mark swallow the next firing instead: two slices in that step.
  if (!script.slice_yielded || lua_gethook(co) != SliceHook ||
      lua_gethookcount(co) != script.slice_instructions)
    lua_sethook(co, SliceHook, LUA_MASKCOUNT, script.slice_instructions);
  int results = 0;
  script.running = true;
  const int status = lua_resume(co, state->L, 0, &results);
  script.running = false;
  c.thread = nullptr;
  script.slice_yielded = c.slice_yielded;
  if (status == LUA_YIELD) {
    lua_pop(co, results);
    return;
  }
  std::string error;
  if (c.budget_exhausted)
    error = c.budget_error;
  else if (status != LUA_OK)
    error = ErrorText(co, status);
  // Finished or failed: the coroutine is not resumed again.
  lua_settop(co, 0);
  luaL_unref(state->L, LUA_REGISTRYINDEX, script.thread_ref);
  script.thread = nullptr;
  script.thread_ref = LUA_NOREF;
  if (!error.empty()) ThrowScriptError(*state, script.object, std::move(error), "sysCall_thread");
}

// Pushes the callback `ref` of `script` and `args` (from
// sim.handleChildScripts), growing the stack for them: Lua guarantees only
// LUA_MINSTACK free slots, and writing past them corrupts the state.
void PushCallback(ScriptState& state, const Script& script, int ref, Callback callback,
                  const std::vector<ParamValue>& args) {
  lua_State* L = state.L;
  if (!args.empty() &&
      (args.size() >= INT_MAX || !lua_checkstack(L, 1 + static_cast<int>(args.size()))))
    ThrowScriptError(state, script.object,
                     "sim.handleChildScripts: " + std::to_string(args.size()) +
                         " arguments do not fit on Lua's stack",
                     kCallbackNames[callback]);
  lua_rawgeti(L, LUA_REGISTRYINDEX, ref);
  for (const ParamValue& v : args) PushParamValue(L, v);
}

// One callback of every script in hierarchy order (explicit ones are left
// to their ancestors); with the actuation callbacks, the threads, unless
// they already ran in step `step` (0: no main script, once a step anyway).
// `args` (from sim.handleChildScripts) are passed to each callback.
void RunCallback(ScriptState* state, Callback callback, const std::vector<ParamValue>& args = {},
                 uint64_t step = 0) {
  const Scene& scene = *state->context.scene;
  state->context.in_sensing = callback == kSensing;
  bool resume_threads = callback == kActuation;
  if (resume_threads && step != 0) {
    resume_threads = state->threads_resumed_step != step;
    state->threads_resumed_step = step;
  }
  for (Script& script : state->scripts) {
    if (script.explicit_handling || !Runs(scene, script)) continue;
    try {
      if (const int ref = script.callbacks[callback]; ref != LUA_NOREF) {
        PushCallback(*state, script, ref, callback, args);
        Call(*state, script, static_cast<int>(args.size()), kCallbackNames[callback]);
      }
      if (resume_threads && script.thread != nullptr) ResumeThread(state, script);
    } catch (const Error& e) {
      if (!Disable(*state, script, e.what())) throw;
    }
  }
}

// sysCall_cleanup of the scripts whose sysCall_init returned. Every script
// gets its cleanup; under disable_script a failing one is disabled (logged
// and listed), else the first error is thrown afterwards.
void Cleanup(ScriptState* state) {
  std::string first_error;
  for (Script& script : state->scripts) {
    if (!script.initialized || script.disabled || script.callbacks[kCleanup] == LUA_NOREF) continue;
    lua_rawgeti(state->L, LUA_REGISTRYINDEX, script.callbacks[kCleanup]);
    try {
      Call(*state, script, 0, kCallbackNames[kCleanup]);
    } catch (const Error& e) {
      if (!Disable(*state, script, e.what()) && first_error.empty()) first_error = e.what();
    }
  }
  if (!first_error.empty()) throw Error(first_error);
}

// "; main.lua:3 defines sysCall_stpe: did you mean sysCall_step?" when the
// main script defines a name near sysCall_step (not one of swarmsim's or
// CoppeliaSim's own callbacks), else "".
std::string MisspeltStepHint(const std::vector<UncalledSysCall>& uncalled) {
  std::vector<std::string> names;
  for (const UncalledSysCall& u : uncalled) {
    const bool known =
        std::any_of(std::begin(kCallbackNames), std::end(kCallbackNames),
                    [&](const char* n) { return u.name == n; }) ||
        std::any_of(std::begin(kCoppeliaSimCallbacks), std::end(kCoppeliaSimCallbacks),
                    [&](const PortedCallback& p) { return u.name == p.name; });
    names.push_back(known ? std::string() : u.name);  // "" is never near
  }
  const std::string* nearest = NearestName(kCallbackNames[kStep], names);
  if (nearest == nullptr) return "";
  const UncalledSysCall& u = uncalled[static_cast<size_t>(nearest - names.data())];
  return "; " + u.file + (u.line > 0 ? ":" + std::to_string(u.line) : std::string()) + " defines " +
         u.name + ": did you mean " + kCallbackNames[kStep] + "?";
}

size_t StateBytes(const ScriptState* state) {
  if (state == nullptr || state->L == nullptr) return 0;
  return state->memory.used;
}

// Slots of the objects outside any robot, hierarchy order (roots in slot
// order, as Scene orders them). Robot subtrees belong to the robots' states.
std::vector<uint32_t> SceneObjectSlots(const Scene& scene) {
  std::vector<uint32_t> out;
  std::vector<uint32_t> stack;
  for (uint32_t root = 0; root < scene.slot_count(); ++root) {
    if (!scene.alive_at(root) || scene.parent_at(root) >= 0) continue;
    stack.push_back(root);
    while (!stack.empty()) {
      const uint32_t slot = stack.back();
      stack.pop_back();
      if (scene.instance_of_at(slot) >= 0) continue;
      out.push_back(slot);
      const std::vector<ObjectId> children = scene.children(scene.IdAt(slot));
      for (auto it = children.rbegin(); it != children.rend(); ++it) stack.push_back(it->index());
    }
  }
  return out;
}

// --- sim.* functions that need the host's scripts ----------------------------------

// Is `object` a strict descendant of `ancestor`?
bool IsDescendant(const Scene& scene, ObjectId object, ObjectId ancestor) {
  for (ObjectId p = scene.parent(object); !p.IsNull(); p = scene.parent(p))
    if (p == ancestor) return true;
  return false;
}

// sim.handleChildScript(handle, ...) -> the script's return values. Runs the
// explicit script on object `handle` (a descendant of the caller's object,
// in the same model): its sysCall_sensing when called from a sensing
// callback, else its sysCall_actuation, with the given arguments.
int HandleChildScript(lua_State* L) {
  LuaContext& c = Context(L);
  ScriptState& state = *static_cast<ScriptState*>(c.host_state);
  Script* caller = static_cast<Script*>(c.host_script);
  const ObjectId target = CheckObject(L, 1);
  const Scene& scene = *c.scene;
  const std::string path = scene.PathOf(target);  // throws for a stale handle
  auto it = std::find_if(state.scripts.begin(), state.scripts.end(),
                         [&](const Script& s) { return s.object == target; });
  if (it == state.scripts.end())
    throw Error("no script of this model is attached to '" + path + "'");
  Script& script = *it;
  if (!script.explicit_handling)
    throw Error("the script of '" + path +
                "' is not explicit: it runs by itself (mark it 'explicit: true' in the model)");
  if (caller == nullptr || !IsDescendant(scene, target, caller->object))
    throw Error("'" + path + "' is not a descendant of the calling script's object");
  if (script.running) throw Error("the script of '" + path + "' is already running");
  if (!script.initialized || !Runs(scene, script)) return 0;
  const Callback callback = c.in_sensing ? kSensing : kActuation;
  if (script.callbacks[callback] == LUA_NOREF) return 0;
  // Call it with the arguments after the handle; return all it returns.
  const int nargs = lua_gettop(L) - 1;
  lua_rawgeti(L, LUA_REGISTRYINDEX, script.callbacks[callback]);
  lua_insert(L, 2);
  // The script runs on its caller's count: the caller's budget, or its
  // thread's slice (it cannot yield: the budget applies there). Re-arming a
  // budget here would give a caller calling it in a loop endless instructions.
  const lua_Hook hook = lua_gethook(L);
  const int hook_count = lua_gethookcount(L);
  SetCurrent(state, script);
  script.running = true;
  // Lua makes room for all the results of a LUA_MULTRET call (and the
  // arguments are the caller's, already on this stack): nothing to grow here.
  const int status = lua_pcall(L, nargs, LUA_MULTRET, 0);
  script.running = false;
  SetCurrent(state, *caller);
  if (status != LUA_OK) {
    std::string error = (c.budget_exhausted ? c.budget_error : ErrorText(L, status)) + " (in " +
                        kCallbackNames[callback] + " of the explicit script of " + path + ")";
    lua_pop(L, 1);
    if (Disable(state, script, c.name + ": " + error)) {
      if (c.budget_exhausted) {
        // The disabled script will not run again: its caller goes on, on a
        // count of its own again.
        c.budget_exhausted = false;
        lua_sethook(L, hook, LUA_MASKCOUNT, hook_count);
        if (lua_State* root = RootOf(c); root != L) {
          if (c.thread != nullptr)
            lua_sethook(root, SliceHook, LUA_MASKCOUNT, caller->slice_instructions);
          else
            SetBudget(root, c);
        }
      }
      return 0;
    }
    lua_pushlstring(L, error.data(), error.size());
    throw LuaErrorOnStack{};  // raised by Guarded once `error` and `path` are gone
  }
  return lua_gettop(L) - 1;
}

// sim.step() / sim.switchThread(): a threaded script gives up the rest of
// this step; it resumes in the next one. Only the script's thread itself yields: in a coroutine of
// the script's own, lua_yield would return to that coroutine's resumer, not to the simulation.
int SwitchThread(lua_State* L) {
  const lua_State* thread = Context(L).thread;
  if (thread != nullptr && L != thread)
    return luaL_error(
        L, "sim.step: call it from sysCall_thread itself, not from a coroutine of your own");
  if (thread == nullptr || !lua_isyieldable(L))
    return luaL_error(L, "sim.step: only a threaded script (sysCall_thread) can yield");
  return lua_yield(L, 0);  // not guarded: nothing here has a destructor
}

// sim.setThreadSwitchTiming(ms): the thread's time slice per step, after
// which it is switched out automatically. Deterministic: measured as
// ms x 100,000 Lua instructions, not wall time; at least 1,000 and at most
// simulation.instruction_budget (when it is not 0) instructions.
int SetThreadSwitchTiming(lua_State* L) {
  LuaContext& c = Context(L);
  const double ms = ArgNumber(L, 1);
  if (!std::isfinite(ms) || !(ms > 0)) {
    char given[32];
    std::snprintf(given, sizeof given, "%g", ms);
    throw Error("the time slice must be a finite positive number of milliseconds (got " +
                std::string(std::isnan(ms) ? "nan" : given) + ")");
  }
  Script* script = static_cast<Script*>(c.host_script);
  if (script == nullptr) return 0;
  script->slice_instructions =
      SliceInstructions(ms * kInstructionsPerMs, c.world->settings().instruction_budget);
  if (script->thread == L) lua_sethook(L, SliceHook, LUA_MASKCOUNT, script->slice_instructions);
  return 0;
}

// The main script's handlers: the phases of a step, robots in parallel.
template <void (*F)(PhaseHandlers*)>
int MainHandler(lua_State* L) {
  LuaContext& c = Context(L);
  if (!c.is_main) throw Error("only the world's main script may run the phases");
  // After a World error (caught by the script) no phase runs again.
  if (!c.pending_error.empty()) RaiseError(L, "stopped by an error");
  try {
    F(c.phases);
  } catch (const std::exception& e) {
    c.pending_error = e.what();
  }
  if (!c.pending_error.empty()) RaiseError(L, "stopped by an error");
  return 0;
}
void Sensing(PhaseHandlers* p) { p->HandleSensing(); }
void Actuation(PhaseHandlers* p) { p->HandleActuation(); }
void Dynamics(PhaseHandlers* p) { p->HandleDynamics(); }

// sim.handleDynamics(): once per step (LuaScriptHost::RunMainScript resets the
// flag), checked here so that the error names the main script's line.
int HandleDynamics(lua_State* L) {
  LuaContext& c = Context(L);
  if (c.is_main) {
    if (c.dynamics_handled) throw Error("may run only once per step");
    c.dynamics_handled = true;
  }
  return MainHandler<Dynamics>(L);
}

// sim.handleChildScripts([pass [, ...]]): the child scripts of every robot,
// then the scene's. pass: 'sensing', 'actuation' (with the threads) or 'all'
// (default). Further arguments (numbers, booleans, strings: the states are
// separate) are passed to every sysCall_sensing / sysCall_actuation called.
int HandleChildScripts(lua_State* L) {
  static const char* const kPasses[] = {"sensing", "actuation", "all", nullptr};
  const ScriptPass pass = static_cast<ScriptPass>(ArgOption(L, 1, "all", kPasses));
  LuaContext& c = Context(L);
  if (!c.is_main) throw Error("only the world's main script may run the phases");
  std::vector<ParamValue> args;
  for (int i = 2; i <= lua_gettop(L); ++i) {
    switch (lua_type(L, i)) {
      case LUA_TNUMBER: args.emplace_back(lua_tonumber(L, i)); break;
      case LUA_TBOOLEAN: args.emplace_back(static_cast<bool>(lua_toboolean(L, i))); break;
      case LUA_TSTRING: args.emplace_back(std::string(lua_tostring(L, i))); break;
      default:
        throw Error("argument " + std::to_string(i) +
                    " must be a number, boolean or string (each robot has its own Lua state; "
                    "pack tables with sim.packTable), got " +
                    luaL_typename(L, i));
    }
  }
  if (!c.pending_error.empty()) RaiseError(L, "stopped by an error");
  std::vector<ParamValue>& child_args = *static_cast<ScriptState*>(c.host_state)->child_args;
  child_args = std::move(args);
  try {
    c.phases->HandleChildScripts(pass);
  } catch (const std::exception& e) {
    c.pending_error = e.what();
  }
  child_args = {};
  if (!c.pending_error.empty()) RaiseError(L, "stopped by an error");
  return 0;
}

}  // namespace

void RegisterControlApi(lua_State* L) {
  static constexpr luaL_Reg kFunctions[] = {
      {"handleChildScript", Guarded<HandleChildScript, "sim.handleChildScript">},
      {"step", SwitchThread},
      {"switchThread", SwitchThread},
      {"setThreadSwitchTiming", Guarded<SetThreadSwitchTiming, "sim.setThreadSwitchTiming">},
      {"handleSensing", Guarded<MainHandler<Sensing>, "sim.handleSensing">},
      {"handleChildScripts", Guarded<HandleChildScripts, "sim.handleChildScripts">},
      {"handleActuation", Guarded<MainHandler<Actuation>, "sim.handleActuation">},
      {"handleDynamics", Guarded<HandleDynamics, "sim.handleDynamics">},
      {nullptr, nullptr},
  };
  luaL_setfuncs(L, kFunctions, 0);
}

namespace {

// World's ScriptHost (phase_handlers.h).
class LuaScriptHost final : public ScriptHost {
 public:
  explicit LuaScriptHost(World* world) : world_(world) {}

  void Start() override;
  void RunInstance(int instance, ScriptPass pass) override;
  void RunSceneScripts(ScriptPass pass) override;
  bool has_main_script() const override { return main_ != nullptr; }
  void RunMainScript() override;
  void Stop() override;
  size_t MemoryBytes() const override;

 private:
  World* world_;
  std::vector<std::unique_ptr<ScriptState>> robots_;  // by instance; null: no scripts
  std::unique_ptr<ScriptState> scene_;                // null: no scene scripts
  std::unique_ptr<ScriptState> main_;                 // null: the default main script
  std::vector<ParamValue> child_args_;                // of the running sim.handleChildScripts
  uint64_t main_steps_ = 0;                           // sysCall_step calls of the main script
  bool started_ = false;
  bool stopped_ = false;
};

void LuaScriptHost::Start() {
  if (started_) return;
  started_ = true;
  World& world = *world_;
  const Scene& scene = world.scene();
  // Robots in parallel: each touches only its own state and runtime. The
  // lowest robot's error is reported, whatever the thread count.
  const int robot_count = world.robot_count();
  robots_.resize(robot_count);
  std::vector<std::string> errors(robot_count);
  world.scheduler().ParallelFor(0, robot_count, kStartGrain, [&](int64_t begin, int64_t end) {
    for (int64_t r = begin; r < end; ++r) {
      const ModelInstance& instance = scene.instance(static_cast<int>(r));
      if (!instance.alive) continue;
      try {
        robots_[r] = NewState(&world, static_cast<int>(r), &world.runtime(static_cast<int>(r)),
                              instance.name, instance.objects);
        if (robots_[r]) Initialize(robots_[r].get());
      } catch (const std::exception& e) {
        errors[r] = e.what();
      }
    }
  });
  for (const std::string& error : errors)
    if (!error.empty()) throw Error(error);
  // Then the scene's scripts, on this thread.
  scene_ = NewState(&world, -1, &world.scene_runtime(), "scene", SceneObjectSlots(scene));
  if (scene_) Initialize(scene_.get());
  // Last, the world's own main script, in a state of its own.
  if (const auto& source = world.settings().main_script) {
    main_ = NewState(&world, -1, &world.scene_runtime(), "main", {}, source.get());
    main_->child_args = &child_args_;
    Initialize(main_.get());
    if (main_->scripts[0].callbacks[kStep] == LUA_NOREF)
      throw Error("main: " + source->path +
                  ": the main script must define sysCall_step() (it runs one step: "
                  "sim.handleSensing(), sim.handleChildScripts(), sim.handleActuation(), "
                  "sim.handleDynamics())" +
                  MisspeltStepHint(main_->warnings));
  }
  // sysCall_* names no one calls: one warning per script file and name, not
  // per robot, in robot order, then the scene's, then the main script's.
  std::vector<std::pair<std::string, std::string>> warned;  // file, name
  const auto log_warnings = [&](ScriptState* state) {
    if (state == nullptr) return;
    for (UncalledSysCall& u : state->warnings) {
      std::pair<std::string, std::string> key(std::move(u.file), std::move(u.name));
      if (std::find(warned.begin(), warned.end(), key) != warned.end()) continue;
      warned.push_back(std::move(key));
      world.Log(u.warning);
    }
    std::vector<UncalledSysCall>().swap(state->warnings);
  };
  for (const auto& state : robots_) log_warnings(state.get());
  log_warnings(scene_.get());
  log_warnings(main_.get());
}

void LuaScriptHost::RunMainScript() {
  if (stopped_ || !main_) return;
  Script& script = main_->scripts[0];
  ++main_steps_;
  main_->context.dynamics_handled = false;
  lua_rawgeti(main_->L, LUA_REGISTRYINDEX, script.callbacks[kStep]);
  Call(*main_, script, 0, kCallbackNames[kStep]);
}

void LuaScriptHost::RunInstance(int instance, ScriptPass pass) {
  if (stopped_ || instance < 0 || instance >= static_cast<int>(robots_.size())) return;
  ScriptState* state = robots_[instance].get();
  if (state == nullptr) return;
  if (pass != ScriptPass::kActuation) RunCallback(state, kSensing, child_args_);
  if (pass != ScriptPass::kSensing) RunCallback(state, kActuation, child_args_, main_steps_);
}

void LuaScriptHost::RunSceneScripts(ScriptPass pass) {
  if (stopped_ || !scene_) return;
  if (pass != ScriptPass::kActuation) RunCallback(scene_.get(), kSensing, child_args_);
  if (pass != ScriptPass::kSensing) RunCallback(scene_.get(), kActuation, child_args_, main_steps_);
}

void LuaScriptHost::Stop() {
  if (!started_ || stopped_) return;
  stopped_ = true;
  // Robots in index order of their errors, then the scene; every state closes.
  const int robot_count = static_cast<int>(robots_.size());
  std::vector<std::string> errors(robot_count + 1);
  world_->scheduler().ParallelFor(0, robot_count, kStartGrain, [&](int64_t begin, int64_t end) {
    for (int64_t r = begin; r < end; ++r) {
      if (!robots_[r]) continue;
      try {
        Cleanup(robots_[r].get());
      } catch (const std::exception& e) {
        errors[r] = e.what();
      }
      robots_[r].reset();
    }
  });
  for (std::unique_ptr<ScriptState>* state : {&scene_, &main_}) {
    if (!*state) continue;
    try {
      Cleanup(state->get());
    } catch (const std::exception& e) {
      if (errors[robot_count].empty()) errors[robot_count] = e.what();
    }
    state->reset();
  }
  for (const std::string& error : errors)
    if (!error.empty()) throw Error(error);
}

size_t LuaScriptHost::MemoryBytes() const {
  size_t total = StateBytes(scene_.get()) + StateBytes(main_.get());
  for (const auto& state : robots_) total += StateBytes(state.get());
  return total;
}

}  // namespace

std::unique_ptr<ScriptHost> MakeScriptHost(World* world) {
  return std::make_unique<LuaScriptHost>(world);
}

std::vector<std::string> ScriptCallsInProgress() {
  std::vector<std::string> out;
  const std::lock_guard lock(g_call_records_mutex);
  for (const CallRecord* record : CallRecords()) {
    const ScriptState* state = record->state.load(std::memory_order_acquire);
    if (state == nullptr) continue;
    const Script* script = record->script.load(std::memory_order_relaxed);
    const char* what = record->what.load(std::memory_order_relaxed);
    std::string line = state->context.name;
    if (script != nullptr && script->source != nullptr) line += ": " + script->source->path;
    if (what != nullptr) line += std::string(", in ") + what;
    const Scene& scene = *state->context.scene;
    if (script != nullptr && scene.IsValid(script->object))
      line += " of " + scene.PathOf(script->object);
    out.push_back(std::move(line));
  }
  return out;
}

}  // namespace swarmsim
