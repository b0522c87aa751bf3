// Paths' per-point orientations and pauses (modules/paths): followers turn
// from one point's orientation to the next (slerp) instead of following the
// tangent, and stop at a point for its pause, going either way; mistakes
// are file:line:col errors. Paths made by scripts (sim.createPath) exist
// from the next step, the same for any thread count.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "framework/error.h"
#include "framework/world.h"
#include "modules/paths/rows.h"
#include "swarm/loader/world_loader.h"
#include "tests/framework/error_of.h"
#include "tests/swarm/loader/world_dir_test.h"

namespace swarmsim {
namespace {

using paths::PathRow;
using PathPausesTest = testing::WorldDirTest;

constexpr double kPi = 3.141592653589793;

// A model whose root dummy holds a path `track` with a follower `rider`.
std::string TrackModel(const std::string& path_keys) {
  return "model: cart\n"
         "objects:\n"
         "  type: dummy\n"
         "  children:\n"
         "    - name: track\n"
         "      type: path\n"
         "      followers: [rider]\n" +
         path_keys +
         "      children:\n"
         "        - {name: rider, type: dummy}\n";
}

// Along a straight path heading +x, headings of 0, 90 and 90 degrees at its
// points: the rider turns half way by the middle of the first segment, then
// keeps 90 degrees; full orientations (a roll) are slerped too.
TEST_F(PathPausesTest, FollowersTurnBetweenThePointsOrientations) {
  Write("cart.yaml", TrackModel("      points: [[0, 0, 0], [1, 0, 0], [2, 0, 0]]\n"
                                "      yaw_deg: [0, 90, 90]\n      velocity: 1\n"));
  LoadedWorld w = Load(
      "simulation: {physics: kinematic, time_step: 0.1}\n"
      "models: [{model: cart.yaml, position: [0, 0, 0]}]\n");
  World& world = *w.world;
  const ObjectId rider = world.scene().FindObject("/cart#0/rider");
  for (int i = 0; i < 5; ++i) world.Step();
  EXPECT_NEAR(world.scene().world_pose(rider).q.Yaw(), kPi / 4, 1e-9);
  EXPECT_NEAR(world.scene().world_pose(rider).p.x, 0.5, 1e-9);
  for (int i = 0; i < 10; ++i) world.Step();
  EXPECT_NEAR(world.scene().world_pose(rider).q.Yaw(), kPi / 2, 1e-9);
  EXPECT_NEAR(world.scene().world_pose(rider).p.x, 1.5, 1e-9);

  Write("cart.yaml", TrackModel("      points: [[0, 0, 0], [1, 0, 0]]\n"
                                "      orientations_deg: [[0, 0, 0], [90, 0, 0]]\n"
                                "      start: 0.25\n"));
  LoadedWorld w2 = Load(
      "simulation: {physics: kinematic, time_step: 0.1}\n"
      "models: [{model: cart.yaml, position: [0, 0, 0]}]\n");
  w2.world->Step();
  const Vec3 rpy =
      w2.world->scene().world_pose(w2.world->scene().FindObject("/cart#0/rider")).q.RollPitchYaw();
  EXPECT_NEAR(rpy.x, kPi / 8, 1e-9);  // a quarter of the way from 0 to 90 degrees of roll
  EXPECT_NEAR(rpy.z, 0, 1e-9);
}

// velocity 1 m/s, steps of 1/8 s (exact in binary), a 0.5 s pause at the
// middle point: the rider reaches it at 1 s, stays there four steps, then
// goes on; backwards it stops there again.
TEST_F(PathPausesTest, FollowersPauseAtAPointEitherWay) {
  Write("cart.yaml", TrackModel("      points: [[0, 0, 0], [1, 0, 0], [2, 0, 0]]\n"
                                "      pauses: [0, 0.5, 0]\n      velocity: 1\n"));
  LoadedWorld w = Load(
      "simulation: {physics: kinematic, time_step: 0.125}\n"
      "models: [{model: cart.yaml, position: [0, 0, 0]}]\n");
  World& world = *w.world;
  const ObjectId rider = world.scene().FindObject("/cart#0/rider");
  auto x = [&] { return world.scene().world_pose(rider).p.x; };
  for (int i = 0; i < 8; ++i) world.Step();
  EXPECT_EQ(x(), 1);
  for (int i = 0; i < 4; ++i) {
    world.Step();
    EXPECT_EQ(x(), 1) << "paused step " << i;
  }
  world.Step();
  EXPECT_EQ(x(), 1.125);
  for (int i = 0; i < 7; ++i) world.Step();  // at the end: 2
  EXPECT_EQ(x(), 2);
  RowOf<PathRow>(world, "/cart#0/track").velocity = -1;
  for (int i = 0; i < 8; ++i) world.Step();  // back at the middle point
  EXPECT_EQ(x(), 1);
  for (int i = 0; i < 4; ++i) world.Step();
  EXPECT_EQ(x(), 1);
  world.Step();
  EXPECT_EQ(x(), 0.875);
}

TEST_F(PathPausesTest, BadOrientationsAndPausesAreFileLineColumnErrors) {
  EXPECT_CONTAINS(ErrorOf("path", "  points: [[0, 0, 0], [1, 0, 0]]\n  yaw_deg: [0]\n"),
                  "thing.yaml:5:12:");
  EXPECT_CONTAINS(ErrorOf("path", "  points: [[0, 0, 0], [1, 0, 0]]\n  pauses: [0, -1]\n"),
                  "thing.yaml:5:");
  EXPECT_CONTAINS(
      ErrorOf("path", "  points: [[0, 0, 0], [1, 0, 0]]\n  orientations_deg: [[0, 0, 0]]\n"),
      "thing.yaml:5:");
  EXPECT_CONTAINS(
      ErrorOf("path",
              "  points: [[0, 0, 0], [1, 0, 0]]\n  orientations_deg: [[0, 0, 0], [0, 0, "
              "0], [0, 0, 0]]\n"),
      "needs one [roll, pitch, yaw] per point (2), got 3");
  EXPECT_CONTAINS(ErrorOf("path",
                          "  points: [[0, 0, 0], [1, 0, 0]]\n  yaw_deg: [0, 1]\n"
                          "  orientations_deg: [[0, 0, 0], [0, 0, 0]]\n"),
                  "give 'yaw_deg' or 'orientations_deg', not both");
  EXPECT_EQ(ErrorOf("path",
                    "  points: [[0, 0, 0], [1, 0, 0]]\n  yaw_deg: [0, 1]\n"
                    "  pauses: [1, 0]\n"),
            "(no error)");
}

// Each robot makes a path under itself in its first step; from the next
// one, sim.getObject finds it, its length and poses are the points', and
// the hash is the same at 1 and 2 threads.
TEST_F(PathPausesTest, ScriptsCreatePathsDeterministically) {
  Write("bot.yaml", "model: bot\nobjects: {type: dummy, script: bot.lua}\n");
  Write("bot.lua",
        "local n = 0\n"
        "function sysCall_actuation()\n"
        "  n = n + 1\n"
        "  if n == 1 then\n"
        "    sim.createPath({{0, 0, 0}, {1, 0, 0}, {1, 2, 0}}, {name = 'made', velocity = 0.5})\n"
        "  else\n"
        "    local h = sim.getObject('./made')\n"
        "    sim.recordMetric('length', sim.getPathLength(h))\n"
        "    sim.recordMetric('y', sim.getPathPose(h, 2)[2])\n"
        "  end\n"
        "end\n");
  uint64_t hashes[2] = {};
  for (const int threads : {1, 2}) {
    LoadedWorld w = Load(
        "simulation: {physics: kinematic, time_step: 0.1}\n"
        "models: [{model: bot.yaml, count: 6, distribute: {region: {min: [-3, -3], max: [3, "
        "3]}}}]\n",
        threads);
    for (int i = 0; i < 5; ++i) w.world->Step();
    hashes[threads - 1] = w.world->StateHash();
    int lengths = 0;
    for (const MetricSample& m : w.world->TakeMetrics()) {
      if (m.name == "length") {
        EXPECT_EQ(m.value, 3.0);
        ++lengths;
      }
    }
    EXPECT_EQ(lengths, 6 * 4);
    const Scene& scene = w.world->scene();
    const ObjectId made = scene.FindObject("/bot#3/made");
    ASSERT_FALSE(made.IsNull());
    // Made after step 1's control phase, it moves from that step's actuate
    // phase on: 5 steps at 0.5 m/s.
    EXPECT_NEAR(RowOf<PathRow>(*w.world, "/bot#3/made").position, 0.25, 1e-12);
  }
  EXPECT_EQ(hashes[0], hashes[1]);
}

TEST_F(PathPausesTest, BadCreatePathCallsNameTheScriptLine) {
  Write("bot.yaml", "model: bot\nobjects: {type: dummy, script: bot.lua}\n");
  for (const std::string call :
       {"sim.createPath({{0, 0, 0}})", "sim.createPath({{0, 0, 0}, {0/0, 0, 0}})",
        "sim.createPath({{0, 0, 0}, {0, 0, 0}})",
        "sim.createPath({{0, 0, 0}, {1, 0, 0}}, {interpolation = 'smoth'})",
        "sim.createPath({{0, 0, 0}, {1, 0, 0}}, {parent = sim.getObject('/bot#1')})"}) {
    Write("bot.lua", "function sysCall_actuation()\n  " + call + "\nend\n");
    LoadedWorld w = Load(
        "simulation: {physics: kinematic}\n"
        "models: [{model: bot.yaml, position: [0, 0]}, {model: bot.yaml, position: [2, 0]}]\n");
    try {
      w.world->Step();
      ADD_FAILURE() << "no error: " << call;
    } catch (const Error& e) {
      EXPECT_CONTAINS(e.what(), "bot.lua:2");
    }
  }
}

}  // namespace
}  // namespace swarmsim
