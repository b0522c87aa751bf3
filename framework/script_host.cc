// The Lua scripting host: the life of its states (script_host.h).
//
// One lua_State per robot (model instance), or per n robots with
// simulation.robots_per_lua_state (robots r / n share one: LuaHeap), and one
// for the scripts outside any robot. Each script runs in its own environment
// table whose __index is the state's shared globals (sim, the safe
// libraries), so globals of one script do not leak into another. Robots
// sharing a state keep their own context (the state's extra space while
// one runs: MakeCurrent), math.random generator (copied in and out of the
// state's), required modules (lua_sandbox.cc) and threads; a state's robots
// are started, run and stopped on one thread at a time (its mutex), so
// results are those of a state per robot for scripts that leave the
// library tables alone. A source is compiled once as
// `function(_ENV, ...) <code> end` (the robots' states load its bytecode,
// dumped by the first state that compiled it: no parsing per robot) and
// called once per script with that script's environment; the callbacks it defines are looked up
// once, kept as registry references, and called without string lookups every step.
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
//
// The rest of the host, one topic a file: script_state.h (a state, its
// scripts, their errors), script_hooks.h (budget, time slice and memory
// hooks; resuming a thread), script_calls.h (the calls in progress, for the watchdog),
// script_hints.h (sysCall_* names never called), lua_api_control.cc (the
// sim.* functions that run scripts and phases).
#include "framework/script_host.h"

#include <algorithm>
#include <atomic>
#include <climits>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <string_view>
#include <unordered_map>
#include <utility>
#include <vector>

#include "framework/error.h"
#include "framework/lua_api.h"
#include "framework/memory_forecast.h"
#include "framework/sanitizers.h"
#include "framework/scene.h"
#include "framework/scheduler.h"
#include "framework/script_calls.h"
#include "framework/script_chunks.h"
#include "framework/script_hints.h"
#include "framework/script_hooks.h"
#include "framework/script_state.h"
#include "framework/world.h"

namespace swarmsim {
namespace lua_host {
namespace {

// Robots started per task: starting one compiles its scripts and runs their
// bodies and sysCall_init, a few tens of microseconds.
constexpr int64_t kStartGrain = 4;

// Registry key of the metatable shared by the script environments of a state.
const char kEnvironmentMetatableKey = 0;

// An error outside any protected call (out of memory while setting a state
// up) would otherwise abort the process. Throwing from the panic function
// unwinds through Lua's C frames (built with unwind tables on Debian); the
// state is not used again.
int ThrowOnPanic(lua_State* L) {
  const char* message = lua_tostring(L, -1);
  throw Error(std::string("Lua: ") + (message != nullptr ? message : "unprotected error"));
}

// Calls the function below `nargs` arguments on the stack as `script`,
// under the instruction budget. Throws swarmsim::Error naming the robot,
// file:line, `what` and the object. Once the budget ran out, that is the
// error reported, whatever error value the call returns.
void Call(ScriptState& state, Script& script, int nargs, const char* what) {
  const CallInProgress in_progress(state, what);
  MakeCurrent(state);
  SetCurrent(state, script);
  state.context.budget_exhausted = false;
  state.context.data_collected = false;
  state.context.running = nullptr;
  state.heap->memory.refused_bytes = 0;  // reported with the callback that made it
  state.heap->memory.refusal_bytes = 0;
  SetBudget(state.L, state.context);
  script.running = true;
  // LocateError below the function: errors name a line where Lua has one.
  lua_State* L = state.L;
  const int handler = lua_gettop(L) - nargs;
  lua_pushcfunction(L, LocateError);
  lua_insert(L, handler);
  const int status = lua_pcall(L, nargs, 0, handler);
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
      ThrowScriptError(state, script, state.context.budget_error, what);
    ThrowScriptError(state, script, ErrorText(L, status), what);
  }
  lua_settop(L, handler - 1);
}

// Seeds math.random, reproducibly per robot: a robot's own state's, or its
// generator in a shared state (MakeCurrent). Arguments: two integers.
int SeedRandom(lua_State* L) {
  lua_getglobal(L, LUA_MATHLIBNAME);
  lua_getfield(L, -1, "randomseed");
  lua_pushvalue(L, 1);
  lua_pushvalue(L, 2);
  lua_call(L, 2, 0);
  lua_pop(L, 1);
  return 0;
}

// Protected part of creating a state. Arguments: two integers seeding
// math.random, and for a state robots share, its LuaHeap (light userdata),
// whose generator it notes.
int SetUpState(lua_State* L) {
  OpenSandbox(L);
  RegisterAllApis(L);
  SeedRandom(L);
  // Script environments read what they do not define from the shared globals.
  // Their metatable is one per state, so it is protected: getmetatable(_G)
  // gives false and setmetatable(_G, ...) is an error (a robot that hooked
  // its __newindex read and wrote the other robots' globals in a shared state).
  lua_createtable(L, 0, 2);
  lua_pushglobaltable(L);
  lua_setfield(L, -2, "__index");
  lua_pushboolean(L, 0);
  lua_setfield(L, -2, "__metatable");
  lua_rawsetp(L, LUA_REGISTRYINDEX, &kEnvironmentMetatableKey);
  if (auto* heap = static_cast<LuaHeap*>(lua_touserdata(L, 3)); heap != nullptr) {
    size_t bytes = 0;
    heap->generator = PinRandomGenerator(L, &bytes);
    if (heap->generator == nullptr || bytes != kGeneratorBytes)
      return luaL_error(L, "math.random's generator is not Lua 5.4's (%d bytes)",
                        static_cast<int>(bytes));
  }
  return 0;
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
      state, script,
      script.source->path + ": " + name + " must be a function (got " + lua_typename(L, type) + ")",
      "loading the script");
}

// A state for the enabled scripts on `slots` (hierarchy order), or null if
// there are none. With `group`, the robot shares the Lua state *group
// (robots_per_lua_state), made here if null.
std::unique_ptr<ScriptState> NewState(World* world, int instance, RobotRuntime* runtime,
                                      std::string name, const std::vector<uint32_t>& slots,
                                      const ScriptSource* main_source = nullptr,
                                      std::shared_ptr<LuaHeap>* group = nullptr) {
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
  c.mail =
      instance >= 0 ? &world->messaging().robot_mail(instance) : &world->messaging().scene_mail();
  c.instance = instance;
  c.log_prefix = "[" + name + "] ";
  c.name = std::move(name);
  c.host_state = state.get();
  c.instruction_budget = world->settings().instruction_budget;
  // The robot's account (the scene's for the scene's scripts and the main
  // script), which the data its sim.* calls keep charges too; a shared
  // state's heap has an account of its own.
  ScriptMemory& account = world->script_memory(instance);
  c.memory = &account;
  const lua_Integer seeds[2] = {static_cast<lua_Integer>(runtime->rng.NextU64()),
                                static_cast<lua_Integer>(runtime->rng.NextU64())};
  if (group != nullptr && (*group)->L != nullptr) {
    // Joins the group's state: its own generator, seeded as its own state's.
    state->heap = *group;
    state->L = state->heap->L;
    lua_State* L = state->L;
    MakeCurrent(*state);
    lua_pushcfunction(L, SeedRandom);
    lua_pushinteger(L, seeds[0]);
    lua_pushinteger(L, seeds[1]);
    if (const int status = lua_pcall(L, 2, 0, 0); status != LUA_OK)
      throw Error(c.name + ": cannot set up the Lua state: " + ErrorText(L, status));
    return state;
  }
  // A state of its own, or the first of a shared one (made by StartRobots).
  state->heap = group != nullptr ? *group : std::make_shared<LuaHeap>();
  LuaHeap& heap = *state->heap;
  if (!heap.shared) heap.memory.account = &account;
  lua_State* L = lua_newstate(LimitedAlloc, &heap);
  if (L == nullptr) throw Error(c.name + ": not enough memory for a Lua state");
  state->L = heap.L = L;
  heap.current = state.get();
  lua_atpanic(L, ThrowOnPanic);
  SetContext(L, &c);
  lua_pushcfunction(L, SetUpState);
  lua_pushinteger(L, seeds[0]);
  lua_pushinteger(L, seeds[1]);
  lua_pushlightuserdata(L, heap.shared ? &heap : nullptr);
  if (const int status = lua_pcall(L, 3, 0, 0); status != LUA_OK)
    throw Error(c.name + ": cannot set up the Lua state: " + ErrorText(L, status));
  return state;
}

// Has any of `slots` an enabled script (NewState makes a state for it)?
bool HasScripts(const Scene& scene, const std::vector<uint32_t>& slots) {
  return std::any_of(slots.begin(), slots.end(), [&](uint32_t slot) {
    const ScriptAttachment* attachment = scene.script_at(slot);
    return attachment != nullptr && attachment->enabled;
  });
}

// The heap the robots `members` (two or more, with scripts) will share:
// its memory limit is their limits together, and its errors name them.
std::shared_ptr<LuaHeap> SharedHeap(World& world, const std::vector<int64_t>& members) {
  auto heap = std::make_shared<LuaHeap>();
  heap->shared = true;
  ScriptMemory& first = world.script_memory(static_cast<int>(members.front()));
  heap->account.Attach(first.run(), first.limit() * members.size());
  heap->memory.account = &heap->account;
  const Scene& scene = world.scene();
  heap->holder = "the scripts of " + scene.instance(static_cast<int>(members.front())).name +
                 " .. " + scene.instance(static_cast<int>(members.back())).name + " (" +
                 std::to_string(members.size()) + " robots sharing a Lua state)";
  heap->memory.holder = heap->holder.c_str();
  heap->memory.setting =
      "simulation.script_memory_mb, times the robots sharing the state "
      "(simulation.robots_per_lua_state); raise it if the data is real";
  return heap;
}

// The sources compiled in a state (registry references to their factories).
using Factories = std::vector<std::pair<const ScriptSource*, int>>;

// Drops a state's factories and leaves its collector in generational mode,
// once its robots are initialized.
void Settle(lua_State* L, Factories& factories) {
  // The bodies' code is not needed any more (the callbacks they defined
  // keep their own prototypes).
  for (const auto& factory : factories) luaL_unref(L, LUA_REGISTRYINDEX, factory.second);
  factories.clear();
  // Generational collection keeps a robot's heap within ~20% of what it
  // holds (the incremental default lets it double between cycles: 10,000
  // robots would carry ~20 KB of garbage each). In Lua 5.4.4 a full
  // collection in generational mode leaves the next target at twice the
  // heap; one young step after it sets the target from the live size. A
  // full incremental collection first: without it the diffusion robot's
  // heap settles 0.56 KiB higher for good (17.11 vs 16.55 KiB, measured
  // over 30 steps) since its libraries are no longer opened in full.
  lua_gc(L, LUA_GCCOLLECT);
  lua_gc(L, LUA_GCGEN, 0, 0);
  lua_gc(L, LUA_GCCOLLECT);
  lua_gc(L, LUA_GCSTEP, 0);
}

// Runs every script's body, then every sysCall_init, in hierarchy order.
// `chunks`: the sources compiled by the other states, and where this one's
// go. With `group` (a robot sharing its state), the factories compiled in
// the state so far, kept for the next robot; the caller settles the state.
void Initialize(ScriptState* state, CompiledChunks* chunks = nullptr, Factories* group = nullptr) {
  lua_State* L = state->L;
  MakeCurrent(*state);
  // Bodies. Each distinct source is compiled once for the state.
  Factories own;
  Factories& factories = group != nullptr ? *group : own;
  for (Script& script : state->scripts) {
    const ScriptSource& source = *script.source;
    auto it = std::find_if(factories.begin(), factories.end(),
                           [&](const auto& f) { return f.first == &source; });
    if (it == factories.end()) {
      std::string message = CompileFactory(L, source, chunks);
      if (!message.empty())
        ThrowScriptError(*state, script, std::move(message), "loading the script");
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
      script.slice_instructions =
          SliceInstructions(script.slice_instructions, state->context.instruction_budget);
    }
  }
  if (group == nullptr) Settle(L, own);
}

// Pushes the callback `ref` of `script` and `args` (from
// sim.handleChildScripts), growing the stack for them: Lua guarantees only
// LUA_MINSTACK free slots, and writing past them corrupts the state (and
// Call adds its message handler).
void PushCallback(ScriptState& state, const Script& script, int ref, Callback callback,
                  const std::vector<ParamValue>& args) {
  lua_State* L = state.L;
  if (!args.empty() &&
      (args.size() >= INT_MAX - 2 || !lua_checkstack(L, 2 + static_cast<int>(args.size()))))
    ThrowScriptError(state, script,
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

// Holds a shared state's mutex (robots sharing a state may be run from
// different threads), or nothing.
std::unique_lock<std::mutex> Lock(ScriptState& state) {
  if (!state.heap->shared) return {};
  return std::unique_lock<std::mutex>(state.heap->mutex);
}

size_t StateBytes(const ScriptState* state) {
  if (state == nullptr || state->L == nullptr) return 0;
  return state->heap->memory.used;
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

// World's ScriptHost (phase_handlers.h).
class LuaScriptHost final : public ScriptHost {
 public:
  explicit LuaScriptHost(World* world) : world_(world) {}

  void Start() override;
  void StartInstances(int first) override;
  void StopInstance(int instance) override;
  void RunInstance(int instance, ScriptPass pass) override;
  void RunSceneScripts(ScriptPass pass) override;
  bool has_main_script() const override { return main_ != nullptr; }
  void RunMainScript() override;
  void Stop() override;
  size_t MemoryBytes() const override;

 private:
  // States for robots `first` .. robot_count - 1, their scripts initialized,
  // in parallel; throws the lowest robot's error.
  void StartRobots(int first);

  World* world_;
  std::vector<std::unique_ptr<ScriptState>> robots_;  // by instance; null: no scripts
  std::unique_ptr<ScriptState> scene_;                // null: no scene scripts
  std::unique_ptr<ScriptState> main_;                 // null: the default main script
  std::vector<ParamValue> child_args_;                // of the running sim.handleChildScripts
  CompiledChunks chunks_;                             // the robots' sources, compiled once
  uint64_t main_steps_ = 0;                           // sysCall_step calls of the main script
  bool started_ = false;
  bool stopped_ = false;
};

void LuaScriptHost::Start() {
  if (started_) return;
  started_ = true;
  World& world = *world_;
  const Scene& scene = world.scene();
  if (world.settings().trust_scripts && world.settings().robots_per_lua_state > 1 &&
      world.robot_count() > 1)
    world.Log(
        "warning: --trust-scripts: every robot gets a Lua state of its own "
        "(simulation.robots_per_lua_state " +
        std::to_string(world.settings().robots_per_lua_state) +
        " is not used: with the sandbox lifted, Lua's own require, load and package would "
        "be shared by the robots of a state)");
  StartRobots(0);
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

void LuaScriptHost::StartRobots(int first) {
  World& world = *world_;
  const Scene& scene = world.scene();
  // Robots in parallel: each touches only its own state and runtime. The
  // lowest robot's error is reported, whatever the thread count.
  const int robot_count = world.robot_count();
  robots_.resize(robot_count);
  std::vector<std::string> errors(robot_count);
  // A world whose states will not fit in memory stops with a message (not
  // the kernel's out-of-memory kill); the robots not yet started are skipped.
  // It counts the robots that get a state: those with scripts (a world of
  // native controllers has none, and nothing to forecast).
  std::atomic<int64_t> scripted{0};
  constexpr int64_t kCountGrain = 4096;  // robots a task: a few objects' flags each
  world.scheduler().ParallelFor(first, robot_count, kCountGrain, [&](int64_t begin, int64_t end) {
    int64_t n = 0;
    for (int64_t r = begin; r < end; ++r) {
      const ModelInstance& instance = scene.instance(static_cast<int>(r));
      n += instance.alive && HasScripts(scene, instance.objects) ? 1 : 0;
    }
    scripted.fetch_add(n);
  });
  MemoryForecast forecast("robots' Lua states", scripted.load(), world.settings().max_memory);
  std::atomic<int64_t> started{0};
  std::string refusal;
  std::atomic<bool> refused{false};
  // The run asked to stop (World::CheckStop threw on a worker): the robots
  // not yet started are skipped, and it throws again here on this thread.
  std::atomic<bool> stop{false};
  const auto stopping = [&] {
    if (stop.load(std::memory_order_relaxed)) return true;
    try {
      world.CheckStop();
    } catch (...) {
      stop.store(true);
      refused.store(true);
      return true;
    }
    return false;
  };
  // Robots r / n share a state (robots_per_lua_state: n), those of them
  // that have scripts; each state is built on one thread. Not with the
  // sandbox lifted: Lua's own require, load and package keep one copy per
  // state, which robots would then share (Start says so).
  const int64_t n = world.settings().trust_scripts ? 1 : world.settings().robots_per_lua_state;
  const auto start = [&](int64_t r, std::shared_ptr<LuaHeap>* group, Factories* factories) {
    const ModelInstance& instance = scene.instance(static_cast<int>(r));
    if (!instance.alive) return;
    try {
      robots_[r] = NewState(&world, static_cast<int>(r), &world.runtime(static_cast<int>(r)),
                            instance.name, instance.objects, nullptr, group);
      if (robots_[r]) Initialize(robots_[r].get(), &chunks_, factories);
    } catch (const std::exception& e) {
      errors[r] = e.what();
    }
    if (!robots_[r]) return;  // no scripts, no state: not what the forecast counts
    if (std::string why = forecast.Built(started.fetch_add(1) + 1); !why.empty()) {
      refusal = std::move(why);  // one thread only: the forecast says it once
      refused.store(true);
    }
  };
  if (n <= 1) {
    world.scheduler().ParallelFor(first, robot_count, kStartGrain, [&](int64_t begin, int64_t end) {
      for (int64_t r = begin; r < end; ++r) {
        if (refused.load(std::memory_order_relaxed) || stopping()) return;
        start(r, nullptr, nullptr);
      }
    });
  } else {
    world.scheduler().ParallelFor(
        first / n, (robot_count + n - 1) / n, 1, [&](int64_t begin, int64_t end) {
          for (int64_t g = begin; g < end; ++g) {
            if (stopping()) return;
            std::vector<int64_t> members;
            for (int64_t r = std::max<int64_t>(first, g * n);
                 r < std::min<int64_t>(robot_count, (g + 1) * n); ++r) {
              const ModelInstance& instance = scene.instance(static_cast<int>(r));
              if (instance.alive && HasScripts(scene, instance.objects))
                members.push_back(r);
              else
                start(r, nullptr, nullptr);  // no state: counted
            }
            if (members.size() < 2) {  // a state of its own
              for (int64_t r : members) start(r, nullptr, nullptr);
              continue;
            }
            std::shared_ptr<LuaHeap> group = SharedHeap(world, members);
            Factories factories;
            for (int64_t r : members) {
              if (refused.load(std::memory_order_relaxed)) break;
              start(r, &group, &factories);
            }
            if (group->L != nullptr) Settle(group->L, factories);
          }
        });
  }
  if (stop.load()) {
    world.CheckStop();  // throws again (the signal stays noted)
    throw Error("the start was stopped");
  }
  if (refused.load()) throw Error(refusal);
  for (const std::string& error : errors)
    if (!error.empty()) throw Error(error);
}

void LuaScriptHost::StartInstances(int first) {
  if (!started_ || stopped_) return;
  // The world's runtimes and mail may have moved as they grew.
  for (size_t r = 0; r < robots_.size(); ++r) {
    if (!robots_[r]) continue;
    robots_[r]->context.runtime = &world_->runtime(static_cast<int>(r));
    robots_[r]->context.mail = &world_->messaging().robot_mail(static_cast<int>(r));
  }
  StartRobots(first);
  // Copies load the scripts of robots that were loaded at Start: their
  // warnings were logged then.
  for (size_t r = static_cast<size_t>(first); r < robots_.size(); ++r)
    if (robots_[r]) std::vector<UncalledSysCall>().swap(robots_[r]->warnings);
}

void LuaScriptHost::StopInstance(int instance) {
  if (!started_ || stopped_ || instance < 0 || instance >= static_cast<int>(robots_.size())) return;
  std::unique_ptr<ScriptState> state = std::move(robots_[instance]);
  if (!state) return;
  std::unique_lock lock = Lock(*state);
  try {
    Cleanup(state.get());
  } catch (...) {
    // ~ScriptState takes it. Only a shared state's lock holds a mutex: an
    // empty lock's unlock() threw std::system_error ("Operation not
    // permitted"), which replaced the cleanup's error, robot, script and line.
    if (lock.owns_lock()) lock.unlock();
    throw;  // the state closes as `state` goes (the last robot's), error or not
  }
}

void LuaScriptHost::RunMainScript() {
  if (stopped_ || !main_) return;
  Script& script = main_->scripts[0];
  ++main_steps_;
  main_->context.dynamics_handled = false;
  lua_rawgeti(main_->L, LUA_REGISTRYINDEX, script.callbacks[kStep]);
  main_->context.in_main_step = true;
  try {
    Call(*main_, script, 0, kCallbackNames[kStep]);
  } catch (...) {
    main_->context.in_main_step = false;
    throw;
  }
  main_->context.in_main_step = false;
}

void LuaScriptHost::RunInstance(int instance, ScriptPass pass) {
  if (stopped_ || instance < 0 || instance >= static_cast<int>(robots_.size())) return;
  ScriptState* state = robots_[instance].get();
  if (state == nullptr) return;
  const std::unique_lock lock = Lock(*state);
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
      {
        const std::unique_lock lock = Lock(*robots_[r]);
        try {
          Cleanup(robots_[r].get());
        } catch (const std::exception& e) {
          errors[r] = e.what();
        }
        // The process ends next (swarmsim run): a state whose closing runs
        // no code is left to the system rather than freed one object at a
        // time (1.3 s of a 100,000-robot run's end). Not under ASan (leak
        // checks). ~ScriptState looks at may_finalize.
        if (!kAddressSanitizer && world_->process_ends_after_stop())
          robots_[r]->heap->leave_to_system = true;
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
  const LuaHeap* last = nullptr;  // robots sharing a state are neighbours
  for (const auto& state : robots_) {
    if (!state || state->heap.get() == last) continue;
    last = state->heap.get();
    total += StateBytes(state.get());
  }
  return total;
}

}  // namespace

}  // namespace lua_host

std::unique_ptr<ScriptHost> MakeScriptHost(World* world) {
  return std::make_unique<lua_host::LuaScriptHost>(world);
}

std::vector<std::string> ScriptCallsInProgress() { return lua_host::DescribeCallsInProgress(); }

}  // namespace swarmsim
