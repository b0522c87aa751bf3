// The module contract: what a calculation module declares and what World
// runs (ARGoS's registered engines and sensors; MuJoCo's engine plugins).
//
// A module registers once, by name, in the ModuleRegistry with a
// ModuleDescriptor: its `swarmsim modules` line (kind, name, version, one
// line), the phases it hooks and its order within them, and how one world's
// instance is made, and its Lua area. World makes the every-world modules
// when it starts, the others when something asks for them (World::module:
// the loader for a model's IK groups; a module's world-file section,
// framework/world_section.h, for `paint:` or `metrics:`), and runs every
// instance's hooks phase by phase:
//
//   Phase::kSense    after the scene's state is final, before the scripts
//                    (proximity 100; then plugin sensors, after_sense callbacks)
//   Phase::kActuate  after deferred writes, before joints move (IK groups 100)
//   Phase::kPhysics  after the dynamics step (AfterPhysics; then after_physics
//                    callbacks)
//   Phase::kRecord   after the step (swarm metrics 100, paint 200, then
//                    record-phase plugin callbacks)
//
// (Phase::kControl is the scripts' own: no module hooks it.)
//
// Within a phase, lower `order` first, then creation order: never the
// thread count. A module's state that changes the future goes into the
// state hash (HashState), modules in creation order after the dynamics.
// A module follows the objects it refers to through copies and removals
// (SceneListener; paper §2.3).
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "framework/phase.h"
#include "framework/scene.h"

struct lua_State;

namespace swarmsim {

class StateHasher;
class StateReader;
class StateWriter;
class World;
struct MetricSample;

// A file a module wrote into the run's output folder, for summary.json's
// "outputs" list.
struct OutputFile {
  std::string kind;         // "graph", "snapshot", "video", "image", ...
  std::string path;         // relative to the output folder
  std::string description;  // one line (a graph's name, a camera's)
};

// One world's instance of a module. Hooks it does not declare are not called.
class Module : public SceneListener {
 public:
  ~Module() override = default;
  // The world has started: the scene is placed and the dynamics built, the
  // scripts' sysCall_init has not run yet.
  virtual void Start(World* /*world*/) {}
  // Robots may be handled concurrently through world->scheduler(); results
  // must not depend on the thread count.
  virtual void Sense(World* /*world*/) {}
  virtual void Actuate(World* /*world*/) {}
  virtual void AfterPhysics(World* /*world*/) {}
  // Appends this step's rows of metrics.csv.
  virtual void Record(const World& /*world*/, std::vector<MetricSample>* /*out*/) {}
  // Writes the module's files (paint.png) into the run's output folder at
  // the end of a run. Throws swarmsim::Error if it cannot.
  virtual void WriteOutputs(const std::filesystem::path& /*dir*/) const {}
  // The files WriteOutputs (or the run so far) wrote, for summary.json.
  virtual void ListOutputs(std::vector<OutputFile>* /*out*/) const {}
  // Folds state that is not in the scene and changes the future into the hash.
  virtual void HashState(StateHasher* /*hasher*/) const {}
  // Snapshots (framework/world_state.h): writes the module's own state that
  // changes the future or its outputs (what HashState adds, a metric's
  // running values, a layer's pixels) and returns true; LoadState reads it
  // back into the same module of a world loaded from the same file (after
  // the scene, the rows and the seed are restored: a module that keeps the
  // seed reads world->settings().seed again). A module with nothing to save
  // between steps returns true writing nothing. The default, false, makes
  // World::SaveState refuse the world, naming the module: a module is not
  // saved by accident.
  virtual bool SaveState(const World& /*world*/, StateWriter* /*out*/) const { return false; }
  virtual void LoadState(StateReader* /*in*/, World* /*world*/) {}
  // Once the loader has built every object: throws swarmsim::Error (naming
  // the file:line:column the module kept) for a reference that matches
  // nothing, such as an IK group's obstacle path (World::CheckModuleReferences).
  virtual void CheckReferences(const Scene& /*scene*/) {}
  void OnSubtreeDuplicated(const Scene&, std::span<const uint32_t>,
                           std::span<const uint32_t>) override {}
  void OnSubtreeRemoved(const Scene&, std::span<const uint32_t>) override {}
};

struct ModuleInfo {
  std::string kind;  // "dynamics", "proximity", "calculation", "metric", ...
  std::string name;  // e.g. "box2d"
  std::string version;
  std::string description;  // one line
};

struct ModuleDescriptor {
  ModuleInfo info;
  uint32_t phases = 0;       // PhaseBit(Phase::kSense) | ... (not kControl)
  int order = 0;             // within each phase, lower first
  bool every_world = false;  // made by World::Start for every world; else on request
  // One world's instance. `config` is what the requester passes
  // (World::AddModule: a `paint:` section's settings, a metric's `every`),
  // or null (World::module).
  std::function<std::unique_ptr<Module>(World* world, const void* config)> make;
  // The module's Lua API area (framework/lua_api.h): adds its sim.*
  // functions and constants to the table on top of L's stack, as an object
  // type's register_lua does (sim.getIkGroup, ...). Null: none.
  void (*register_lua)(lua_State* L) = nullptr;
};

}  // namespace swarmsim
