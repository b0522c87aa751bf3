// The Lua scripting host.
//
// One lua_State per model instance (robot); each script attached to an
// object of the robot is a separate environment in it. Scripts outside any
// model share one scene state that runs on the calling thread. Lua types
// stay inside the host's .cc files (lua_api.h is internal to them).
//
// The sim.* API is in lua_api_*.cc, one file per area; each function's
// comment is its reference. A Lua error becomes a swarmsim::Error reading
// "footbot#12: scripts/x.lua:23: <message> [in sysCall_actuation of
// /footbot#12/body]".
#pragma once

#include <cstddef>
#include <memory>
#include <string>
#include <vector>

#include "framework/world.h"

namespace swarmsim {

class ScriptHost {
 public:
  explicit ScriptHost(World* world);
  ~ScriptHost();
  ScriptHost(const ScriptHost&) = delete;
  ScriptHost& operator=(const ScriptHost&) = delete;

  // Creates the Lua states, loads every enabled script and runs its body,
  // then every sysCall_init, each robot's scripts in hierarchy order; then
  // the scene's scripts likewise. Robots start in parallel (each touches
  // only its own state); their prints and errors come out in robot order.
  // Throws swarmsim::Error on a script error (the lowest robot's), or under
  // on_script_error: disable_script disables the failing script (an error
  // in its main chunk or sysCall_init, a sysCall_* callback that is not a
  // function). Logs one warning per script file and name for globals named
  // sysCall_* that are never called (typos, CoppeliaSim-only callbacks).
  void Start();
  // Control phase of one robot: sysCall_sensing of each of its scripts in
  // hierarchy order, then sysCall_actuation likewise. Safe to call
  // concurrently for different robots. Throws swarmsim::Error naming the
  // robot, script file and line on a Lua error.
  // A pass runs only the sensing or the actuation callbacks (threads are
  // resumed with the actuation callbacks; with a main script, in the first
  // such pass of a step only). Explicit scripts are skipped.
  void RunInstance(int instance, ScriptPass pass = ScriptPass::kAll);
  // Control phase of the scripts outside any model, on the calling thread.
  void RunSceneScripts(ScriptPass pass = ScriptPass::kAll);
  // The world's own main script (WorldSettings::main_script), if any: its
  // sysCall_step runs one step on the calling thread, calling the World's
  // handlers through sim.handleSensing(), sim.handleChildScripts(), ...
  bool has_main_script() const;
  void RunMainScript();
  // Arguments sim.handleChildScripts(pass, ...) passes to the child
  // callbacks it runs (empty outside such a call).
  void SetChildScriptArguments(std::vector<ParamValue> args);
  // sysCall_cleanup of every script whose sysCall_init returned; closes the
  // states. Throws the lowest robot's cleanup error (under disable_script, a
  // failing cleanup is logged and listed as disabled instead). Safe to call
  // twice.
  void Stop();

  // Bytes held by all Lua states, as Lua counts them (lua_gc LUA_GCCOUNT;
  // malloc's own overhead is not included).
  size_t MemoryBytes() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// The script calls running right now on any thread, innermost first per
// thread: "footbot#3: probe.lua, in sysCall_actuation of /footbot#3/body".
// For a watchdog that finds a run stuck in one call (Lua's hooks cannot stop
// a script inside one C function, such as a pattern match that backtracks
// for hours); safe to call from any thread while scripts run.
std::vector<std::string> ScriptCallsInProgress();

}  // namespace swarmsim
