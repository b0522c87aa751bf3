// Snapshots of loaded worlds on every dynamics backend a user can pick
// (framework/world_state.h): restore + k steps gives the state hash of the
// uninterrupted run at several points, in a crowded arena where bodies
// touch (Box2D's and ODE's contact caches); a restore with another seed
// equals a fresh load with that seed (World.reset); what cannot be saved
// (Lua scripts) is refused by name.
#include <gtest/gtest.h>

#include <map>
#include <string>
#include <vector>

#include "framework/error.h"
#include "framework/registry.h"
#include "framework/world.h"
#include "modules/builtin.h"
#include "swarm/loader/world_loader.h"

namespace swarmsim {
namespace {

const ModuleRegistry& Registry() {
  static const ModuleRegistry registry = [] {
    ModuleRegistry r;
    RegisterBuiltinModules(&r);
    return r;
  }();
  return registry;
}

LoadedWorld Load(const std::string& physics, uint64_t seed, int threads = 2) {
  LoadOptions options;
  options.overrides = {{"physics", physics}, {"robots", "30"}};
  options.seed = seed;
  options.threads = threads;
  options.python_controllers = true;  // the entry's python_controller drops the Lua scripts
  return LoadWorld(std::string(SWARMSIM_SOURCE_DIR) + "/tests/data/worlds/snapshot.yaml", options,
                   Registry());
}

// What a Python controller does between steps: each robot's wheels, from
// its index and the step, so that robots turn into one another.
void Drive(World* world) {
  Scene& scene = world->scene();
  const int64_t phase = world->step_count() / 7;
  for (size_t r = 0; r < scene.joints().size(); ++r) {
    const uint32_t slot = scene.joint_owners()[r];
    const int robot = scene.instance_of_at(slot);
    const bool left = scene.name_at(slot) == "leftMotor";
    const int64_t mode = (robot + phase) % 3;
    scene.joints()[r].target_velocity = mode == 0 ? 4.0
                                        : (mode == 1) == left
                                            ? 4.0
                                            : -1.0;  // rad/s: straight, or turning
  }
}

void StepDriven(World* world, int64_t until) {
  while (world->step_count() < until) {
    Drive(world);
    world->Step();
  }
}

class SnapshotTest : public ::testing::TestWithParam<std::string> {};

TEST_P(SnapshotTest, RestorePlusStepsEqualsTheUninterruptedRun) {
  // A snapshot at step 0, 6 or 19 of a run; its hashes at 19, 30 and 40.
  // (Each run takes one snapshot: with planar, box2d and ode a snapshot
  // rebuilds the engine, which is part of the run it is taken in.)
  for (const int64_t at : {0, 6, 19}) {
    LoadedWorld original = Load(GetParam(), 3);
    StepDriven(original.world.get(), at);
    const std::string bytes = original.world->SaveState();
    const uint64_t at_hash = original.world->StateHash();
    std::map<int64_t, uint64_t> hashes;
    for (const int64_t later : {19, 30, 40}) {
      if (later <= at) continue;
      StepDriven(original.world.get(), later);
      hashes[later] = original.world->StateHash();
    }
    EXPECT_NE(hashes[30], hashes[40]);  // the robots move: the run is not trivial
    LoadedWorld restored = Load(GetParam(), 3, at == 6 ? 1 : 2);  // any thread count
    restored.world->RestoreState(bytes);
    EXPECT_EQ(restored.world->step_count(), at);
    EXPECT_EQ(restored.world->StateHash(), at_hash) << GetParam() << " restored at " << at;
    for (const auto& [later, hash] : hashes) {
      StepDriven(restored.world.get(), later);
      EXPECT_EQ(restored.world->StateHash(), hash)
          << GetParam() << ": restored at step " << at << ", compared at " << later;
    }
    // The original goes back to it as well.
    original.world->RestoreState(bytes);
    StepDriven(original.world.get(), 40);
    EXPECT_EQ(original.world->StateHash(), hashes[40]) << GetParam() << " back to " << at;
  }
}

// Kinematic worlds keep nothing in the engine: taking a snapshot changes
// nothing of the run.
TEST(SnapshotKinematicTest, TakingASnapshotDoesNotChangeTheRun) {
  LoadedWorld plain = Load("kinematic", 5), saved = Load("kinematic", 5);
  plain.world->Start();
  StepDriven(plain.world.get(), 20);
  StepDriven(saved.world.get(), 10);
  saved.world->SaveState();
  StepDriven(saved.world.get(), 20);
  EXPECT_EQ(plain.world->StateHash(), saved.world->StateHash());
}

// World.reset(seed): the snapshot of a world before its first step, with
// another seed and the robots placed as a load with that seed places them,
// is that load.
TEST_P(SnapshotTest, ReseededRestoreEqualsAFreshLoadWithThatSeed) {
  LoadedWorld first = Load(GetParam(), 1);
  const std::string initial = first.world->SaveState();
  StepDriven(first.world.get(), 5);
  const auto roots = first.placement(9);
  ASSERT_EQ(roots.size(), 30u);
  const World::Reseed reseed{9, roots};
  first.world->RestoreState(initial, &reseed);
  EXPECT_EQ(first.world->step_count(), 0);
  EXPECT_EQ(first.world->settings().seed, 9u);
  StepDriven(first.world.get(), 12);

  LoadedWorld fresh = Load(GetParam(), 9);
  fresh.world->Start();
  StepDriven(fresh.world.get(), 12);
  EXPECT_EQ(first.world->StateHash(), fresh.world->StateHash()) << GetParam();
  // And back to the world's own seed: the world as it was loaded.
  first.world->RestoreState(initial);
  LoadedWorld again = Load(GetParam(), 1);
  again.world->Start();
  StepDriven(first.world.get(), 4);
  StepDriven(again.world.get(), 4);
  EXPECT_EQ(first.world->StateHash(), again.world->StateHash()) << GetParam();
}

INSTANTIATE_TEST_SUITE_P(Backends, SnapshotTest,
                         ::testing::Values("kinematic", "planar", "box2d", "ode"));

TEST(SnapshotRefusalTest, LuaScriptsAreRefusedByName) {
  LoadOptions options;
  options.overrides = {{"robots", "4"}};
  LoadedWorld loaded =
      LoadWorld(std::string(SWARMSIM_SOURCE_DIR) + "/worlds/diffusion.yaml", options, Registry());
  loaded.world->set_log_sink([](std::string_view) {});
  try {
    loaded.world->SaveState();
    FAIL() << "saved a world whose robots run Lua scripts";
  } catch (const Error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("robot 'footbot#0' runs Lua script"), std::string::npos) << what;
    EXPECT_NE(what.find("diffusion.lua"), std::string::npos) << what;
  }
}

}  // namespace
}  // namespace swarmsim
