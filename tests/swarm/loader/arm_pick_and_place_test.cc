// worlds/arm_pick_and_place.yaml: the UR5 carries the box kinematically and
// releases it; the box falls onto the table at the place location. The run
// is independent of the thread count.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "framework/registry.h"
#include "framework/world.h"
#include "modules/builtin.h"
#include "swarm/loader/world_loader.h"

namespace swarmsim {
namespace {

std::unique_ptr<World> RunArm(int threads, int steps) {
  static ModuleRegistry* registry = [] {
    auto* r = new ModuleRegistry;
    RegisterBuiltinModules(r);
    return r;
  }();
  LoadOptions options;
  options.threads = threads;
  LoadedWorld loaded = LoadWorld(
      std::string(SWARMSIM_SOURCE_DIR) + "/worlds/arm_pick_and_place.yaml", options, *registry);
  loaded.world->set_log_sink([](std::string_view) {});
  for (int i = 0; i < steps; ++i) loaded.world->Step();
  return std::move(loaded.world);
}

TEST(ArmPickAndPlaceTest, BoxEndsOnTheTableAtThePlaceLocation) {
  auto world = RunArm(1, 500);  // 10 s
  const Scene& scene = world->scene();
  const ObjectId box = scene.FindObject("/box");
  ASSERT_FALSE(box.IsNull());
  EXPECT_TRUE(scene.shape(box).dynamic);  // released
  const Vec3 p = scene.world_pose(box).p;
  // Place location (0.45, -0.25), resting on the table top (z = 0.4, box 5 cm).
  EXPECT_NEAR(p.x, 0.45, 0.03);
  EXPECT_NEAR(p.y, -0.25, 0.03);
  EXPECT_NEAR(p.z, 0.425, 0.005);
  EXPECT_LT(scene.linear_velocity_at(box.index()).Norm(), 0.01);  // at rest
}

TEST(ArmPickAndPlaceTest, StateHashIsEqualAtOneAndTwoThreads) {
  EXPECT_EQ(RunArm(1, 300)->StateHash(), RunArm(2, 300)->StateHash());
}

}  // namespace
}  // namespace swarmsim
