// Range-and-bearing boards in world and model files: every key reaches the
// settings (shared by the copies of one model entry), scaled copies scale
// the range, mistakes are errors naming file:line:column (exit code 2 from
// the program), and worlds/README.md documents every key.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "framework/error.h"
#include "framework/world.h"
#include "modules/range_and_bearing/range_and_bearing.h"
#include "swarm/loader/world_loader.h"
#include "tests/framework/error_of.h"
#include "tests/swarm/loader/world_dir_test.h"
#include "tests/swarm/run_program.h"

namespace swarmsim::range_and_bearing {
namespace {

using RangeAndBearingLoaderTest = testing::WorldDirTest;

TEST_F(RangeAndBearingLoaderTest, BadValuesAreFileLineColumnErrors) {
  const char* t = kTypeName;
  EXPECT_CONTAINS(ErrorOf(t, "  range: -1\n"),
                  "thing.yaml:4:10: 'range' must be a positive number");
  EXPECT_CONTAINS(ErrorOf(t, "  range: 0\n"), "thing.yaml:4:10:");
  EXPECT_CONTAINS(ErrorOf(t, "  loss_probability: 1.5\n"), "thing.yaml:4:21:");
  EXPECT_CONTAINS(ErrorOf(t, "  loss_probability: -0.1\n"), "thing.yaml:4:21:");
  EXPECT_CONTAINS(ErrorOf(t, "  loss_at_range: 2\n"), "thing.yaml:4:18:");
  EXPECT_CONTAINS(ErrorOf(t, "  failure_probability: 1.01\n"), "thing.yaml:4:24:");
  EXPECT_CONTAINS(ErrorOf(t, "  payload_size: 0\n"), "thing.yaml:4:17:");
  EXPECT_CONTAINS(ErrorOf(t, "  payload_size: 100000\n"), "thing.yaml:4:17:");
  EXPECT_CONTAINS(ErrorOf(t, "  payload_size: 2.5\n"), "thing.yaml:4:17:");
  EXPECT_CONTAINS(ErrorOf(t, "  capacity: 0\n"), "thing.yaml:4:13:");
  EXPECT_CONTAINS(ErrorOf(t, "  capacity: -3\n"), "thing.yaml:4:13:");
  EXPECT_CONTAINS(ErrorOf(t, "  capacity_order: nearst\n"), "did you mean 'nearest'?");
  EXPECT_CONTAINS(ErrorOf(t, "  range_noise: -0.1\n"), "thing.yaml:4:16:");
  EXPECT_CONTAINS(ErrorOf(t, "  bearing_noise_deg: 200\n"), "thing.yaml:4:22:");
  EXPECT_CONTAINS(ErrorOf(t, "  robot_occlusion: perhaps\n"), "thing.yaml:4:20:");
  EXPECT_CONTAINS(ErrorOf(t, "  payload: 4\n"), "thing.yaml:4:3: unknown key 'payload'");
  EXPECT_EQ(ErrorOf(t, "  range: 0.8\n  payload_size: 4\n  capacity: 1\n  loss_probability: 1\n"),
            "(no error)");
}

TEST_F(RangeAndBearingLoaderTest, TheProgramExitsWithTwoAndNamesTheKey) {
  Write("thing.yaml", "model: thing\nobjects:\n  type: range_and_bearing\n  loss_probability: 2\n");
  Write("world.yaml",
        "simulation: {physics: kinematic}\nmodels: [{model: thing.yaml, position: [0, 0]}]\n");
  const auto r = testing::RunProgram("run " + (dir_ / "world.yaml").string() + " --steps 1");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_CONTAINS(r.output, "thing.yaml:4:21:");
}

TEST_F(RangeAndBearingLoaderTest, KeysReachTheSharedSettingsAndScaledCopiesScaleTheRange) {
  Write("bot.yaml", R"(model: bot
objects:
  name: body
  type: dummy
  children:
    - {name: rab, type: range_and_bearing, range: 0.8, payload_size: 4, loss_probability: 0.1,
       loss_at_range: 0.5, range_noise: 0.01, range_noise_uniform: 0.02, bearing_noise_deg: 2,
       bearing_noise_uniform_deg: 3, failure_probability: 0.05, capacity: 3,
       capacity_order: random, occlusion: false, robot_occlusion: true}
)");
  LoadedWorld w = Load(R"(simulation: {physics: kinematic}
models:
  - {model: bot.yaml, count: 2, distribute: {region: {min: [-3, -3], max: [3, 3]}}}
  - {model: bot.yaml, position: [5, 5], scale: 2}
)");
  Scene& scene = w.world->scene();
  ObjectType type;
  ASSERT_TRUE(scene.FindType(kTypeName, &type));
  const auto& rows = scene.rows<RangeAndBearingRow>(type);
  ASSERT_EQ(rows.size(), 3u);
  const RangeAndBearingSettings& s = *rows.rows[0].settings;
  EXPECT_DOUBLE_EQ(s.range, 0.8);
  EXPECT_EQ(s.payload_size, 4u);
  EXPECT_DOUBLE_EQ(s.loss_probability, 0.1);
  EXPECT_DOUBLE_EQ(s.loss_at_range, 0.5);
  EXPECT_DOUBLE_EQ(s.range_noise.gaussian, 0.01);
  EXPECT_DOUBLE_EQ(s.range_noise.uniform, 0.02);
  EXPECT_DOUBLE_EQ(s.range_noise.failure, 0.05);
  EXPECT_NEAR(s.bearing_noise.gaussian, 2 * M_PI / 180, 1e-15);
  EXPECT_NEAR(s.bearing_noise.uniform, 3 * M_PI / 180, 1e-15);
  EXPECT_EQ(s.capacity, 3u);
  EXPECT_EQ(s.capacity_order, CapacityOrder::kRandom);
  EXPECT_FALSE(s.occlusion);
  EXPECT_TRUE(s.robot_occlusion);
  // p = min(1, 0.1 + 0.5 (d / 0.8)^2).
  EXPECT_DOUBLE_EQ(s.LossAt(0.4), 0.1 + 0.5 * 0.25);
  EXPECT_TRUE(rows.rows[1].settings.SameAs(rows.rows[0].settings));
  EXPECT_FALSE(rows.rows[2].settings.SameAs(rows.rows[0].settings));
  EXPECT_DOUBLE_EQ(rows.rows[2].settings->range, 1.6);
  EXPECT_DOUBLE_EQ(rows.rows[2].settings->range_noise.gaussian, 0.02);
  EXPECT_EQ(rows.rows[2].settings->payload_size, 4u);
}

TEST_F(RangeAndBearingLoaderTest, EveryKeyIsDocumented) { ExpectDocumented({kTypeName}); }

}  // namespace
}  // namespace swarmsim::range_and_bearing
