// The Lua scripting host.
//
// One lua_State per robot (model instance) and one for the scripts outside
// any robot. Each script runs in its own environment table whose __index is
// the state's shared globals (sim, the safe libraries), so globals of one
// script do not leak into another. A source is compiled once per state as
// `function(_ENV, ...) <code> end` and called once per script with that
// script's environment; the callbacks it defines are looked up once, kept as
// registry references, and called without string lookups every step.
#include "framework/script_host.h"

#include <algorithm>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "framework/error.h"
#include "framework/lua_api.h"
#include "framework/scene.h"
#include "framework/scheduler.h"
#include "framework/world.h"

namespace swarmsim {
namespace {

enum Callback : int { kInit, kSensing, kActuation, kCleanup, kCallbackCount };
constexpr const char* kCallbackNames[kCallbackCount] = {"sysCall_init", "sysCall_sensing",
                                                        "sysCall_actuation", "sysCall_cleanup"};

// Robots started per task: starting one compiles its scripts and runs their
// bodies and sysCall_init, a few tens of microseconds.
constexpr int64_t kStartGrain = 4;

// Registry key of the metatable shared by the script environments of a state.
const char kEnvironmentMetatableKey = 0;

// A script attached to one object.
struct Script {  // 36 bytes
  uint32_t slot = 0;
  ObjectId object;
  int env_ref = LUA_NOREF;  // environment table, in the registry
  int callbacks[kCallbackCount] = {LUA_NOREF, LUA_NOREF, LUA_NOREF, LUA_NOREF};
  bool initialized = false;  // sysCall_init returned: sysCall_cleanup is due
};

// One lua_State and its scripts: a robot's, or the scene's.
struct ScriptState {
  lua_State* L = nullptr;
  LuaContext context;
  std::vector<Script> scripts;  // hierarchy order

  ScriptState() = default;
  ScriptState(const ScriptState&) = delete;
  ScriptState& operator=(const ScriptState&) = delete;
  ~ScriptState() {
    if (L != nullptr) lua_close(L);
  }
};

// An error outside any protected call (out of memory while setting a state
// up) would otherwise abort the process. With the C++ build of Lua, throwing
// from the panic function is the documented way out.
int ThrowOnPanic(lua_State* L) {
  const char* message = lua_tostring(L, -1);
  throw Error(std::string("Lua: ") + (message != nullptr ? message : "unprotected error"));
}

// The text of the error value on top of the stack.
std::string ErrorText(lua_State* L, int status) {
  if (status == LUA_ERRMEM) return "not enough memory";
  if (status != LUA_ERRRUN && status != LUA_ERRSYNTAX && status != LUA_ERRERR)
    return "internal error: a C++ exception crossed a Lua frame (please report this)";
  if (lua_type(L, -1) == LUA_TSTRING) return lua_tostring(L, -1);
  return std::string("(error object is a ") + luaL_typename(L, -1) + " value)";
}

[[noreturn]] void ThrowScriptError(const ScriptState& state, ObjectId object, std::string message,
                                   std::string_view what) {
  lua_settop(state.L, 0);
  const Scene& scene = *state.context.scene;
  const std::string path = scene.IsValid(object) ? scene.PathOf(object) : std::string("?");
  throw Error(state.context.name + ": " + message + " [in " + std::string(what) + " of " + path +
              "]");
}

// Calls the function below `nargs` arguments on the stack as `script`.
// Throws swarmsim::Error naming the robot, file:line, `what` and the object.
void Call(ScriptState& state, const Script& script, int nargs, std::string_view what) {
  state.context.script_object = script.object;
  state.context.script_env_ref = script.env_ref;
  const int status = lua_pcall(state.L, nargs, 0, 0);
  if (status != LUA_OK) ThrowScriptError(state, script.object, ErrorText(state.L, status), what);
}

// Protected part of creating a state. Arguments: two integers seeding math.random.
int SetUpState(lua_State* L) {
  OpenSafeLibraries(L);
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
// inherited from the shared globals), or LUA_NOREF.
int FindCallback(lua_State* L, const Script& script, const char* name) {
  lua_rawgeti(L, LUA_REGISTRYINDEX, script.env_ref);
  lua_pushstring(L, name);
  lua_rawget(L, -2);
  const int ref = lua_isfunction(L, -1) ? luaL_ref(L, LUA_REGISTRYINDEX) : LUA_NOREF;
  lua_settop(L, 0);
  return ref;
}

bool Runs(const Scene& scene, const Script& script) {
  if (!scene.IsValid(script.object)) return false;
  const ScriptAttachment* attachment = scene.script_at(script.slot);
  return attachment != nullptr && attachment->enabled;
}

// A state for the enabled scripts on `slots` (hierarchy order), or null if
// there are none.
std::unique_ptr<ScriptState> NewState(World* world, int instance, RobotRuntime* runtime,
                                      std::string name, const std::vector<uint32_t>& slots) {
  Scene& scene = world->scene();
  auto state = std::make_unique<ScriptState>();
  for (uint32_t slot : slots) {
    const ScriptAttachment* attachment = scene.script_at(slot);
    if (attachment == nullptr || !attachment->enabled) continue;
    state->scripts.push_back({slot, scene.IdAt(slot)});
  }
  if (state->scripts.empty()) return nullptr;
  LuaContext& c = state->context;
  c.world = world;
  c.scene = &scene;
  c.runtime = runtime;
  c.instance = instance;
  c.log_prefix = "[" + name + "] ";
  c.name = std::move(name);
  lua_State* L = luaL_newstate();
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
  const Scene& scene = *state->context.scene;
  // Bodies. Each distinct source is compiled once for the state.
  std::vector<std::pair<const ScriptSource*, int>> factories;
  for (Script& script : state->scripts) {
    const ScriptSource& source = *scene.script_at(script.slot)->source;
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
    Call(*state, script, 1, "the main chunk");
  }
  // The bodies' code is not needed any more (the callbacks they defined
  // keep their own prototypes).
  for (const auto& factory : factories) luaL_unref(L, LUA_REGISTRYINDEX, factory.second);
  // sysCall_init, then the per-step callbacks (sysCall_init may define them).
  for (Script& script : state->scripts) {
    if (const int init = FindCallback(L, script, kCallbackNames[kInit]); init != LUA_NOREF) {
      lua_rawgeti(L, LUA_REGISTRYINDEX, init);
      luaL_unref(L, LUA_REGISTRYINDEX, init);
      Call(*state, script, 0, kCallbackNames[kInit]);
    }
    script.initialized = true;
    for (int callback : {kSensing, kActuation, kCleanup})
      script.callbacks[callback] = FindCallback(L, script, kCallbackNames[callback]);
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

void RunCallback(ScriptState* state, Callback callback) {
  const Scene& scene = *state->context.scene;
  for (const Script& script : state->scripts) {
    const int ref = script.callbacks[callback];
    if (ref == LUA_NOREF || !Runs(scene, script)) continue;
    lua_rawgeti(state->L, LUA_REGISTRYINDEX, ref);
    Call(*state, script, 0, kCallbackNames[callback]);
  }
}

// sysCall_cleanup of the scripts whose sysCall_init returned. Every script
// gets its cleanup; the first error is thrown afterwards.
void Cleanup(ScriptState* state) {
  std::string first_error;
  for (const Script& script : state->scripts) {
    if (!script.initialized || script.callbacks[kCleanup] == LUA_NOREF) continue;
    lua_rawgeti(state->L, LUA_REGISTRYINDEX, script.callbacks[kCleanup]);
    try {
      Call(*state, script, 0, kCallbackNames[kCleanup]);
    } catch (const Error& e) {
      if (first_error.empty()) first_error = e.what();
    }
  }
  if (!first_error.empty()) throw Error(first_error);
}

size_t StateBytes(const ScriptState* state) {
  if (state == nullptr || state->L == nullptr) return 0;
  return static_cast<size_t>(lua_gc(state->L, LUA_GCCOUNT)) * 1024 +
         static_cast<size_t>(lua_gc(state->L, LUA_GCCOUNTB));
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

}  // namespace

struct ScriptHost::Impl {
  World* world;
  std::vector<std::unique_ptr<ScriptState>> robots;  // by instance; null: no scripts
  std::unique_ptr<ScriptState> scene;                // null: no scene scripts
  bool started = false;
  bool stopped = false;
};

ScriptHost::ScriptHost(World* world) : impl_(std::make_unique<Impl>()) { impl_->world = world; }
ScriptHost::~ScriptHost() = default;

void ScriptHost::Start() {
  Impl& h = *impl_;
  if (h.started) return;
  h.started = true;
  World& world = *h.world;
  const Scene& scene = world.scene();
  // Robots in parallel: each touches only its own state and runtime. The
  // lowest robot's error is reported, whatever the thread count.
  const int robot_count = world.robot_count();
  h.robots.resize(robot_count);
  std::vector<std::string> errors(robot_count);
  world.scheduler().ParallelFor(0, robot_count, kStartGrain, [&](int64_t begin, int64_t end) {
    for (int64_t r = begin; r < end; ++r) {
      const ModelInstance& instance = scene.instance(static_cast<int>(r));
      if (!instance.alive) continue;
      try {
        h.robots[r] = NewState(&world, static_cast<int>(r), &world.runtime(static_cast<int>(r)),
                               instance.name, instance.objects);
        if (h.robots[r]) Initialize(h.robots[r].get());
      } catch (const std::exception& e) {
        errors[r] = e.what();
      }
    }
  });
  for (const std::string& error : errors)
    if (!error.empty()) throw Error(error);
  // Then the scene's scripts, on this thread.
  h.scene = NewState(&world, -1, &world.scene_runtime(), "scene", SceneObjectSlots(scene));
  if (h.scene) Initialize(h.scene.get());
}

void ScriptHost::RunInstance(int instance) {
  Impl& h = *impl_;
  if (h.stopped || instance < 0 || instance >= static_cast<int>(h.robots.size())) return;
  ScriptState* state = h.robots[instance].get();
  if (state == nullptr) return;
  RunCallback(state, kSensing);
  RunCallback(state, kActuation);
}

void ScriptHost::RunSceneScripts() {
  Impl& h = *impl_;
  if (h.stopped || !h.scene) return;
  RunCallback(h.scene.get(), kSensing);
  RunCallback(h.scene.get(), kActuation);
}

void ScriptHost::Stop() {
  Impl& h = *impl_;
  if (!h.started || h.stopped) return;
  h.stopped = true;
  // Robots in index order of their errors, then the scene; every state closes.
  const int robot_count = static_cast<int>(h.robots.size());
  std::vector<std::string> errors(robot_count + 1);
  h.world->scheduler().ParallelFor(0, robot_count, kStartGrain, [&](int64_t begin, int64_t end) {
    for (int64_t r = begin; r < end; ++r) {
      if (!h.robots[r]) continue;
      try {
        Cleanup(h.robots[r].get());
      } catch (const std::exception& e) {
        errors[r] = e.what();
      }
      h.robots[r].reset();
    }
  });
  if (h.scene) {
    try {
      Cleanup(h.scene.get());
    } catch (const std::exception& e) {
      errors[robot_count] = e.what();
    }
    h.scene.reset();
  }
  for (const std::string& error : errors)
    if (!error.empty()) throw Error(error);
}

size_t ScriptHost::MemoryBytes() const {
  size_t total = StateBytes(impl_->scene.get());
  for (const auto& state : impl_->robots) total += StateBytes(state.get());
  return total;
}

}  // namespace swarmsim
