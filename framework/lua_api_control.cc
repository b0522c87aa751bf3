// sim.* control: child scripts, threads and the main script's phases.
//
//   sim.handleChildScript(handle, ...) -> ...  runs an explicit script
//   sim.step() / sim.switchThread()            a threaded script yields until the next step
//   sim.setThreadSwitchTiming(ms)              a thread's time slice per step
//   sim.handleSensing(), sim.handleChildScripts([pass, ...]), sim.handleActuation(),
//   sim.handleDynamics()                       the phases of a step, for the world's main script
//
// These need the host's scripts (script_state.h); the phases are the
// world's, run through LuaContext::phases (phase_handlers.h).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <utility>
#include <vector>

#include "framework/error.h"
#include "framework/lua_api.h"
#include "framework/phase_handlers.h"
#include "framework/scene.h"
#include "framework/script_calls.h"
#include "framework/script_hooks.h"
#include "framework/script_state.h"
#include "framework/world.h"

namespace swarmsim {
namespace {

using lua_host::Callback;
using lua_host::Disable;
using lua_host::ErrorText;
using lua_host::kActuation;
using lua_host::kCallbackNames;
using lua_host::kInstructionsPerMs;
using lua_host::kSensing;
using lua_host::RootOf;
using lua_host::Runs;
using lua_host::Script;
using lua_host::ScriptState;
using lua_host::SetBudget;
using lua_host::SetCurrent;
using lua_host::SliceHook;
using lua_host::SliceInstructions;

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
  if (!lua_checkstack(L, 2)) throw Error("not enough memory for the call");
  lua_rawgeti(L, LUA_REGISTRYINDEX, script.callbacks[callback]);
  lua_insert(L, 2);
  lua_pushcfunction(L, lua_host::LocateError);  // errors name the child's line
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
  const int status = lua_pcall(L, nargs, LUA_MULTRET, 2);
  script.running = false;
  SetCurrent(state, *caller);
  lua_remove(L, 2);  // the message handler
  if (status != LUA_OK) {
    std::string error = CutErrorText(c.budget_exhausted ? c.budget_error : ErrorText(L, status)) +
                        " (in " + kCallbackNames[callback] + " of the explicit script of " + path +
                        ")";
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
  if (Context(L).budget_exhausted) FailCallback(L);  // the thread failed: no yield
  const lua_State* thread = Context(L).thread;
  if (thread != nullptr && L != thread)
    return luaL_error(
        L, "sim.step: call it from sysCall_thread itself, not from a coroutine of your own");
  if (thread == nullptr)
    return luaL_error(L, "sim.step: only a threaded script (sysCall_thread) can yield");
  if (!lua_isyieldable(L))  // the thread's own, but under a C function's callback
    return luaL_error(
        L,
        "sim.step: not from inside a callback of a C function (table.sort's "
        "comparison, string.gsub's replacement, a metamethod): it cannot yield there");
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
  script->slice_instructions = SliceInstructions(ms * kInstructionsPerMs, c.instruction_budget);
  if (script->thread == L) lua_sethook(L, SliceHook, LUA_MASKCOUNT, script->slice_instructions);
  return 0;
}

// The main script's handlers: the phases of a step, robots in parallel.
// The phases run in the main script's sysCall_step only: elsewhere (its
// sysCall_init, say) they would step the world outside the step count.
void CheckPhasesAllowed(const LuaContext& c) {
  if (!c.is_main) throw Error("only the world's main script may run the phases");
  if (!c.in_main_step)
    throw Error(
        "the phases run in the main script's sysCall_step only (its other callbacks "
        "would step the world outside the run's count of steps)");
}

template <void (*F)(PhaseHandlers*)>
int MainHandler(lua_State* L) {
  LuaContext& c = Context(L);
  CheckPhasesAllowed(c);
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
  CheckPhasesAllowed(c);
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
  CheckPhasesAllowed(c);
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

}  // namespace swarmsim
