// Same world + seed + steps => bit-identical state whatever the thread count.
#include <gtest/gtest.h>

#include "framework/registry.h"
#include "framework/world.h"
#include "modules/builtin.h"
#include "swarm/loader/world_loader.h"

namespace swarmsim {
namespace {

uint64_t RunWorld(const std::string& file, int robots, int threads, uint64_t seed, int steps) {
  ModuleRegistry registry;
  RegisterBuiltinModules(&registry);
  LoadOptions options;
  options.overrides = {{"robots", std::to_string(robots)}};
  options.seed = seed;
  options.threads = threads;
  LoadedWorld loaded = LoadWorld(std::string(SWARMSIM_SOURCE_DIR) + "/" + file, options, registry);
  loaded.world->set_log_sink([](std::string_view) {});
  loaded.world->Start();
  for (int i = 0; i < steps; ++i) loaded.world->Step();
  return loaded.world->StateHash();
}

uint64_t RunDiffusion(int robots, int threads, uint64_t seed, int steps) {
  return RunWorld("worlds/diffusion.yaml", robots, threads, seed, steps);
}

TEST(DeterminismTest, DiffusionHashIsIndependentOfThreadCount) {
  const uint64_t one = RunDiffusion(300, 1, 7, 300);
  EXPECT_EQ(RunDiffusion(300, 2, 7, 300), one);
  EXPECT_EQ(RunDiffusion(300, 4, 7, 300), one);
  // Another seed, another history.
  EXPECT_NE(RunDiffusion(300, 2, 8, 300), one);
}

// The benchmark's threaded controller (sysCall_thread, one sim.step() a
// step) does what scripts/diffusion.lua does in sysCall_actuation: the same
// history, at any thread count. The broadcasting one differs (messages are
// part of the state), the same at 1 and 2 threads. Each bench world swaps
// the foot-bot's script through its `controller` parameter.
TEST(DeterminismTest, ThreadedControllerMatchesTheNonThreadedOne) {
  for (const char* name : {"threaded", "broadcast"}) {
    ModuleRegistry registry;
    RegisterBuiltinModules(&registry);
    LoadOptions options;
    options.overrides = {{"robots", "3"}};
    const std::string file = std::string("bench/worlds/diffusion_") + name;
    LoadedWorld loaded =
        LoadWorld(std::string(SWARMSIM_SOURCE_DIR) + "/" + file + ".yaml", options, registry);
    const Scene& scene = loaded.world->scene();
    const ScriptAttachment* script = scene.script(scene.instance(2).root);
    ASSERT_NE(script, nullptr);
    EXPECT_TRUE(script->source->path.ends_with(file + ".lua")) << script->source->path;
  }
  const uint64_t plain = RunDiffusion(200, 1, 3, 150);
  EXPECT_EQ(RunWorld("bench/worlds/diffusion_threaded.yaml", 200, 1, 3, 150), plain);
  EXPECT_EQ(RunWorld("bench/worlds/diffusion_threaded.yaml", 200, 2, 3, 150), plain);
  const uint64_t broadcast = RunWorld("bench/worlds/diffusion_broadcast.yaml", 200, 1, 3, 150);
  EXPECT_NE(broadcast, plain);
  EXPECT_EQ(RunWorld("bench/worlds/diffusion_broadcast.yaml", 200, 2, 3, 150), broadcast);
}

TEST(DeterminismTest, RobotsActuallyMoveSoTheHashMeansSomething) {
  // Guards the test above: if nothing moved, every hash would trivially match.
  ModuleRegistry registry;
  RegisterBuiltinModules(&registry);
  LoadOptions options;
  options.overrides = {{"robots", "50"}};
  options.threads = 2;
  LoadedWorld loaded =
      LoadWorld(std::string(SWARMSIM_SOURCE_DIR) + "/worlds/diffusion.yaml", options, registry);
  World& world = *loaded.world;
  world.set_log_sink([](std::string_view) {});
  world.Start();
  std::vector<Vec3> start;
  for (const ModelInstance& inst : world.scene().instances())
    start.push_back(world.scene().world_pose(inst.root).p);
  for (int i = 0; i < 100; ++i) world.Step();  // 10 s at 5 cm/s: up to 0.5 m
  int moved = 0;
  for (size_t r = 0; r < start.size(); ++r) {
    const Vec3 d = world.scene().world_pose(world.scene().instance(int(r)).root).p - start[r];
    if (d.Norm() > 0.1) ++moved;
  }
  EXPECT_GT(moved, 40);
}

}  // namespace
}  // namespace swarmsim
