// The Lua scripting host.
//
// One lua_State per model instance (robot); each script attached to an
// object of the robot is a separate environment in it. Scripts outside any
// model share one scene state that runs on the calling thread. Lua types
// stay inside the host's .cc files.
#pragma once

#include <cstddef>
#include <memory>

namespace swarmsim {

class World;

class ScriptHost {
 public:
  explicit ScriptHost(World* world);
  ~ScriptHost();
  ScriptHost(const ScriptHost&) = delete;
  ScriptHost& operator=(const ScriptHost&) = delete;

  // Creates the Lua states, loads every attached script and runs their
  // sysCall_init, robots in index order, scripts in hierarchy order.
  // Throws swarmsim::Error on a script error.
  void Start();
  // Control phase of one robot: sysCall_sensing of each of its scripts in
  // hierarchy order, then sysCall_actuation likewise. Safe to call
  // concurrently for different robots. Throws swarmsim::Error naming the
  // robot, script file and line on a Lua error.
  void RunInstance(int instance);
  // Control phase of the scripts outside any model, on the calling thread.
  void RunSceneScripts();
  // sysCall_cleanup of every script; closes the states. Safe to call twice.
  void Stop();

  // Bytes held by all Lua states (for the memory figures).
  size_t MemoryBytes() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace swarmsim
