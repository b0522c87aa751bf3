// Native controllers (framework/plugin_api.h, ABI 6): C functions from a
// plugin that a models entry attaches with `native_controller: NAME`, run
// once per robot per step in the control phase, robots in parallel, like a
// robot's scripts.
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "framework/plugin_api.h"

namespace swarmsim {

class World;

// A controller registered by a plugin (add_controller).
struct PluginControllerType {
  std::string name;  // as models entries write it: native_controller: NAME
  std::string description;
  std::string plugin;  // the plugin's path, for messages
  SwarmsimControllerInit init = nullptr;
  SwarmsimControllerStep step = nullptr;
  SwarmsimControllerCleanup cleanup = nullptr;
  void* user_data = nullptr;
};

// The native controllers of one world's robots. Per robot: its type, its
// state (init's), whether it runs, and its place in this step's inbox.
class PluginControllers {
 public:
  explicit PluginControllers(World* world) : world_(world) {}

  // Robot `robot` runs `type` (before the world starts, or a copy's
  // source's). in_place_of_scripts: its Lua scripts were dropped for it; its
  // start then takes the two numbers from the robot's random stream that
  // the Lua state would have taken (script_host.cc seeds math.random with
  // them), so that its random_uniform draws are the ones sim.random would
  // have given and a controller ported from Lua gives the same results.
  void Assign(int robot, const PluginControllerType* type, bool in_place_of_scripts);
  // Room for `robots` robots (World::ReserveRobots): assigned one by one,
  // they then leave no slack.
  void Reserve(size_t robots) { robots_.reserve(robots); }
  // The controller of `robot`, or null.
  const PluginControllerType* type_of(int robot) const {
    return robot >= 0 && robot < static_cast<int>(robots_.size()) ? robots_[robot].type : nullptr;
  }
  bool in_place_of_scripts(int robot) const {
    return type_of(robot) != nullptr && robots_[robot].in_place_of_scripts;
  }
  // Runs init for the robots first .. robot_count - 1 that have a controller,
  // in parallel; a failure goes to the robot's RobotRuntime::error (or, under
  // disable_script, disables it), for the world to flush in robot order.
  void Init(int first);
  // One step of `robot`'s controller, on its worker (nothing if it has none).
  void Step(int robot) {
    if (robot < static_cast<int>(robots_.size()) && robots_[robot].running) CallStep(robot);
  }
  // cleanup of one robot (a removal), or of every robot in index order (Stop).
  void Cleanup(int robot);
  void CleanupAll();
  // The next message delivered to `robot`'s controller this step (world API).
  int Receive(int robot, SwarmsimMessage* out);

 private:
  struct Robot {
    const PluginControllerType* type = nullptr;
    void* state = nullptr;
    bool running = false;  // initialised, not failed, not cleaned up
    bool in_place_of_scripts = false;
    uint64_t round = 0;  // Messaging::round() `next` refers to
    uint32_t next = 0;   // next inbox entry to look at
  };
  void CallStep(int robot);
  // The robot's failure (what: "init", "step"): the run stops with it, or
  // under disable_script the robot's controller stops.
  void Fail(int robot, const char* what, const char* message);
  SwarmsimCallContext Context(int robot) const;

  World* world_;
  std::vector<Robot> robots_;  // by robot index
};

}  // namespace swarmsim
