// The two narrow interfaces between World and its script host, so that
// neither includes the other's header:
//   PhaseHandlers  what a world's own main script runs through
//                  sim.handleSensing(), sim.handleChildScripts(), ...;
//                  World implements it, the Lua host calls it.
//   ScriptHost     what World runs of its scripts; the Lua host
//                  (script_host.cc) implements it, made by MakeScriptHost.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>

namespace swarmsim {

class World;

// Which child-script callbacks a pass of the control phase runs.
enum class ScriptPass : uint8_t { kSensing, kActuation, kAll };

// The phases of the default step, for a world's own main script
// (sim.handleSensing(), ...). Robots fan out in parallel inside each.
class PhaseHandlers {
 public:
  virtual void HandleSensing() = 0;
  virtual void HandleChildScripts(ScriptPass pass) = 0;
  virtual void HandleActuation() = 0;
  virtual void HandleDynamics() = 0;

 protected:
  ~PhaseHandlers() = default;
};

// The scripts of a world: one Lua state per robot, one for the scripts
// outside any model, one for the world's own main script (script_host.h).
class ScriptHost {
 public:
  virtual ~ScriptHost() = default;

  // Creates the Lua states, loads every enabled script and runs its body,
  // then every sysCall_init, each robot's scripts in hierarchy order; then
  // the scene's scripts likewise. Robots start in parallel (each touches
  // only its own state); their prints and errors come out in robot order.
  // Throws swarmsim::Error on a script error (the lowest robot's), or under
  // on_script_error: disable_script disables the failing script (an error
  // in its main chunk or sysCall_init, a sysCall_* callback that is not a
  // function). Logs one warning per script file and name for globals named
  // sysCall_* that are never called (typos, CoppeliaSim-only callbacks).
  virtual void Start() = 0;
  // Control phase of one robot: sysCall_sensing of each of its scripts in
  // hierarchy order, then sysCall_actuation likewise. Safe to call
  // concurrently for different robots. Throws swarmsim::Error naming the
  // robot, script file and line on a Lua error.
  // A pass runs only the sensing or the actuation callbacks (threads are
  // resumed with the actuation callbacks; with a main script, in the first
  // such pass of a step only). Explicit scripts are skipped.
  virtual void RunInstance(int instance, ScriptPass pass) = 0;
  // Robots made after Start (copies, World::ApplyModelEdits), indices
  // `first` .. robot_count - 1: like Start for them (their states, their
  // scripts' bodies and sysCall_init, in parallel; the lowest robot's error
  // is thrown). The world has grown its runtimes and mail for them (which
  // may have moved the others': the host points its states at them again).
  virtual void StartInstances(int first) = 0;
  // A robot about to be removed: sysCall_cleanup of its scripts (as Stop
  // does), then its state closes. On the calling thread, between phases, so
  // no script of it is running. Throws its cleanup error.
  virtual void StopInstance(int instance) = 0;
  // Control phase of the scripts outside any model, on the calling thread.
  virtual void RunSceneScripts(ScriptPass pass) = 0;
  // The world's own main script (WorldSettings::main_script), if any: its
  // sysCall_step runs one step on the calling thread, calling the world's
  // PhaseHandlers through sim.handleSensing(), sim.handleChildScripts(), ...
  virtual bool has_main_script() const = 0;
  virtual void RunMainScript() = 0;
  // sysCall_cleanup of every script whose sysCall_init returned; closes the
  // states. Throws the lowest robot's cleanup error (under disable_script, a
  // failing cleanup is logged and listed as disabled instead). Safe to call
  // twice.
  virtual void Stop() = 0;

  // Bytes held by all Lua states, as Lua counts them (lua_gc LUA_GCCOUNT;
  // malloc's own overhead is not included).
  virtual size_t MemoryBytes() const = 0;
};

// The Lua host of `world` (script_host.cc); it calls the world back through
// PhaseHandlers.
std::unique_ptr<ScriptHost> MakeScriptHost(World* world);

}  // namespace swarmsim
