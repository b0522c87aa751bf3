// worlds/hexapod.yaml (the V-REP paper's §4 scene): the hexapod walks, its
// IK groups are copied with each robot, and the run is independent of the
// thread count.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "framework/registry.h"
#include "framework/world.h"
#include "modules/builtin.h"
#include "modules/kinematics/ik_groups.h"
#include "swarm/loader/world_loader.h"
#include "tests/swarm/run_program.h"

namespace swarmsim {
namespace {

LoadedWorld Load(const std::string& name, int threads,
                 std::vector<std::pair<std::string, std::string>> overrides = {}) {
  static ModuleRegistry* registry = [] {
    auto* r = new ModuleRegistry;
    RegisterBuiltinModules(r);
    return r;
  }();
  LoadOptions options;
  options.threads = threads;
  options.overrides = std::move(overrides);
  LoadedWorld loaded =
      LoadWorld(std::string(SWARMSIM_SOURCE_DIR) + "/worlds/" + name, options, *registry);
  loaded.world->set_log_sink([](std::string_view) {});
  return loaded;
}

TEST(HexapodTest, WalksAtLeastOneBodyLengthIn20Seconds) {
  LoadedWorld loaded = Load("hexapod.yaml", 1);
  World& world = *loaded.world;
  world.Start();
  const Scene& scene = world.scene();
  const ObjectId body = scene.instance(0).root;
  const Vec3 start = scene.world_pose(body).p;
  const double body_length = 2 * scene.shape(body).size.x;  // body diameter, 0.24 m
  for (int i = 0; i < 1000; ++i) world.Step();              // 20 s
  const Vec3 end = scene.world_pose(body).p;
  const double advance = end.x - start.x;
  RecordProperty("advance_m", std::to_string(advance));
  EXPECT_GT(advance, body_length) << "from x " << start.x << " to " << end.x;
  // Still upright and standing.
  EXPECT_GT(scene.world_pose(body).q.Rotate({0, 0, 1}).z, 0.9);
  EXPECT_GT(end.z, 0.03);
}

TEST(HexapodTest, TwentyCopiesEachHaveSixIkGroups) {
  LoadedWorld loaded = Load("hexapod.yaml", 2, {{"robots", "20"}});
  World& world = *loaded.world;
  ASSERT_EQ(world.robot_count(), 20);
  auto* ik = kinematics::FindIkGroups(world);
  ASSERT_NE(ik, nullptr);
  EXPECT_EQ(ik->live_group_count(), 120);
  for (int r = 0; r < 20; ++r)
    for (int leg = 0; leg < 6; ++leg)
      EXPECT_NE(ik->FindGroup("leg" + std::to_string(leg), r), 0) << r << " " << leg;
}

TEST(HexapodTest, StateHashIsEqualAtOneAndTwoThreads) {
  uint64_t hash[2];
  for (int threads : {1, 2}) {
    LoadedWorld loaded = Load("hexapod.yaml", threads, {{"robots", "4"}});
    for (int i = 0; i < 150; ++i) loaded.world->Step();
    hash[threads - 1] = loaded.world->StateHash();
  }
  EXPECT_EQ(hash[0], hash[1]);
}

}  // namespace
}  // namespace swarmsim

namespace swarmsim {
namespace {

// The README's scaling command: the paint layer's resolution follows the
// arena (1 cm up to 40 m, then at most 4000 x 4000 pixels), so 10,000
// hexapods load instead of asking for a 10,200 x 10,200 image.
TEST(HexapodTest, TenThousandCopiesLoadWithAPaintLayerThatFits) {
  const auto r = testing::RunProgram("describe " + std::string(SWARMSIM_SOURCE_DIR) +
                                     "/worlds/hexapod.yaml --set robots=10000");
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("paint_resolution = 0.0255\n"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("10000 copies"), std::string::npos) << r.output;
  // One hexapod keeps its 1 cm.
  LoadedWorld one = Load("hexapod.yaml", 1);
  EXPECT_EQ(std::get<double>(one.world->parameters().at("paint_resolution")), 0.01);
}

}  // namespace
}  // namespace swarmsim
