// Paths in world files (modules/paths): their mistakes (file:line:col), a
// square's exact length and poses, a smooth path through its points and
// parametrised by arc length, followers moving along open and closed
// paths, the scripts' calls, copies and scaled copies, the example world
// and its hash at 1 and 2 threads, and the docs.
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <string>
#include <vector>

#include "framework/error.h"
#include "framework/world.h"
#include "modules/paths/rows.h"
#include "swarm/loader/world_loader.h"
#include "tests/framework/error_of.h"
#include "tests/swarm/loader/world_dir_test.h"

namespace swarmsim {
namespace {

using paths::PathRow;
using PathsTest = testing::WorldDirTest;

constexpr double kPi = 3.141592653589793;

TEST_F(PathsTest, BadPathsAreFileLineColumnErrors) {
  EXPECT_CONTAINS(ErrorOf("path", "  points: [[0, 0, 0]]\n"),
                  "thing.yaml:4:11: 'points' needs at least 2 [x, y, z] lists");
  EXPECT_CONTAINS(ErrorOf("path", "  closed: true\n"), "thing.yaml:");
  EXPECT_CONTAINS(ErrorOf("path", "  points: [[0, 0, 0], [1, 0, 0], [1, 0, 0]]\n"),
                  "thing.yaml:4:34: points[2] repeats points[1]: a path segment must have a "
                  "length");
  EXPECT_CONTAINS(ErrorOf("path", "  points: [[0, 0, 0], [1, .nan, 0]]\n"), "thing.yaml:4:");
  EXPECT_CONTAINS(ErrorOf("path", "  points: [[0, 0, 0], [1, .inf, 0]]\n"), "thing.yaml:4:");
  EXPECT_CONTAINS(ErrorOf("path", "  points: [[0, 0, 0], [1, 0]]\n"), "thing.yaml:4:23:");
  EXPECT_CONTAINS(ErrorOf("path", "  points: [[0, 0, 0], [1, 0, 0], [0, 0, 0]]\n  closed: true\n"),
                  "thing.yaml:4:34: the last point repeats the first");
  EXPECT_CONTAINS(ErrorOf("path", "  points: [[0, 0, 0], [1, 0, 0]]\n  interpolation: smoth\n"),
                  "did you mean 'smooth'?");
  EXPECT_CONTAINS(ErrorOf("path", "  points: [[0, 0, 0], [1, 0, 0]]\n  followers: [nope]\n"),
                  "thing.yaml:5:14: path /thing#0: follower 'nope' is not a child of the path");
  EXPECT_EQ(ErrorOf("path", "  points: [[0, 0, 0], [1, 0, 0], [0, 0, 0]]\n"), "(no error)");
}

// A model whose root dummy holds a path `track` (its keys given) with a
// follower `rider` 0.2 m above it.
std::string TrackModel(const std::string& path_keys, const std::string& script = "") {
  return "model: cart\n"
         "objects:\n"
         "  type: dummy\n" +
         (script.empty() ? "" : "  script: " + script + "\n") +
         "  children:\n"
         "    - name: track\n"
         "      type: path\n"
         "      followers: [rider]\n" +
         path_keys +
         "      children:\n"
         "        - {name: rider, type: dummy, position: [0, 0, 0.2]}\n";
}

constexpr const char* kSquare = "      points: [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]]\n";

// A closed unit square: length 4 exactly, corners and midpoints exactly
// where they are, x along each side; the scripts see it in the world frame.
TEST_F(PathsTest, ASquaresLengthAndPosesAreExact) {
  Write("cart.yaml", TrackModel(std::string(kSquare) + "      closed: true\n", "cart.lua"));
  Write("cart.lua",
        "function sysCall_sensing()\n"
        "  local h = sim.getObject('./track')\n"
        "  sim.recordMetric('length', sim.getPathLength(h))\n"
        "  local p = sim.getPathPose(h, 2.5)\n"
        "  sim.recordMetric('x', p[1]); sim.recordMetric('y', p[2]); sim.recordMetric('z', p[3])\n"
        "  sim.recordMetric('qz', p[6]); sim.recordMetric('qw', p[7])\n"
        "  sim.recordMetric('wrapped', sim.getPathPose(h, 4.5)[1])\n"
        "end\n");
  LoadedWorld w =
      Load("simulation: {physics: kinematic}\nmodels: [{model: cart.yaml, position: [2, 0, 1]}]\n");
  const PathRow& track = RowOf<PathRow>(*w.world, "/cart#0/track");
  EXPECT_EQ(track.curve->length(), 4.0);
  const Pose half = track.curve->PoseAt(2.0);  // the opposite corner
  EXPECT_EQ(half.p, Vec3(1, 1, 0));
  const Pose mid = track.curve->PoseAt(0.5);
  EXPECT_EQ(mid.p, Vec3(0.5, 0, 0));
  EXPECT_NEAR(mid.q.w, 1, 1e-15);
  const Pose up = track.curve->PoseAt(1.5);  // second side, heading +y
  EXPECT_EQ(up.p, Vec3(1, 0.5, 0));
  EXPECT_NEAR(up.q.Yaw(), kPi / 2, 1e-15);
  w.world->Step();
  std::map<std::string, double> m;
  for (const MetricSample& s : w.world->TakeMetrics()) m[s.name] = s.value;
  EXPECT_EQ(m["length"], 4.0);
  EXPECT_DOUBLE_EQ(m["x"], 2.5);  // (0.5, 1, 0) on the path, the model at (2, 0, 1)
  EXPECT_DOUBLE_EQ(m["y"], 1);
  EXPECT_DOUBLE_EQ(m["z"], 1);
  EXPECT_NEAR(std::atan2(m["qz"], m["qw"]) * 2, kPi, 1e-12);  // the third side heads -x
  EXPECT_DOUBLE_EQ(m["wrapped"], 2.5);                        // 4.5 wraps to 0.5
}

// A smooth path passes through every control point, at the arc lengths
// it reports for them, and is parametrised by length: points ds apart along
// it are ds apart in space (the curve barely bends over ds).
TEST_F(PathsTest, ASmoothPathPassesThroughItsPointsAtArcLengthSpeed) {
  for (const bool closed : {false, true}) {
    Write("cart.yaml",
          TrackModel("      points: [[0, 0, 0], [1, 0.2, 0], [1.5, 1, 0.3], [0.4, 1.6, 0], "
                     "[-0.5, 0.8, -0.2]]\n      interpolation: smooth\n      closed: " +
                     std::string(closed ? "true" : "false") + "\n"));
    LoadedWorld w = Load(
        "simulation: {physics: kinematic}\nmodels: [{model: cart.yaml, position: [0, 0, 0]}]\n");
    const paths::PathCurve& curve = *RowOf<PathRow>(*w.world, "/cart#0/track").curve;
    for (size_t i = 0; i < curve.points().size(); ++i) {
      const Vec3 p = curve.PoseAt(curve.LengthAtPoint(i)).p;
      EXPECT_NEAR((p - curve.points()[i]).Norm(), 0, 1e-12) << i;
    }
    // Longer than its chords, shorter than a detour.
    double chords = 0;
    const size_t n = curve.points().size();
    for (size_t i = 0; i + 1 < n + (closed ? 1 : 0); ++i)
      chords += (curve.points()[(i + 1) % n] - curve.points()[i]).Norm();
    EXPECT_GT(curve.length(), chords);
    EXPECT_LT(curve.length(), 1.3 * chords);
    const double ds = 1e-4;
    for (double s = 0; s + ds < curve.length(); s += curve.length() / 97) {
      const double step = (curve.PoseAt(s + ds).p - curve.PoseAt(s).p).Norm();
      EXPECT_NEAR(step, ds, 1e-9) << "s " << s;
      // x along the tangent.
      const Vec3 x = curve.PoseAt(s).q.Rotate({1, 0, 0});
      EXPECT_NEAR(x.Dot((curve.PoseAt(s + ds).p - curve.PoseAt(s).p) / step), 1, 1e-6);
    }
  }
}

// A follower moves at the path's velocity, keeps its offset, and stops at
// the end of an open path.
TEST_F(PathsTest, AFollowerMovesAtItsVelocityAndStopsAtTheEnd) {
  Write("cart.yaml", TrackModel("      points: [[0, 0, 0], [1, 0, 0], [1, 2, 0]]\n"
                                "      velocity: 0.5\n      start: 0.25\n"));
  LoadedWorld w = Load(
      "simulation: {physics: kinematic, time_step: 0.1}\n"
      "models: [{model: cart.yaml, position: [0, 0, 1]}]\n");
  World& world = *w.world;
  world.Start();
  const ObjectId rider = world.scene().FindObject("/cart#0/rider");
  const Vec3 start = world.scene().world_pose(rider).p;
  EXPECT_NEAR((start - Vec3(0.25, 0, 1.2)).Norm(), 0, 1e-12);  // placed at `start`
  for (int i = 0; i < 10; ++i) world.Step();
  EXPECT_NEAR(RowOf<PathRow>(world, "/cart#0/track").position, 0.75, 1e-12);
  EXPECT_NEAR((world.scene().world_pose(rider).p - Vec3(0.75, 0, 1.2)).Norm(), 0, 1e-12);
  for (int i = 0; i < 10; ++i) world.Step();  // past the corner, heading +y
  EXPECT_NEAR((world.scene().world_pose(rider).p - Vec3(1, 0.25, 1.2)).Norm(), 0, 1e-12);
  EXPECT_NEAR(world.scene().world_pose(rider).q.Yaw(), kPi / 2, 1e-12);
  for (int i = 0; i < 100; ++i) world.Step();
  EXPECT_EQ(RowOf<PathRow>(world, "/cart#0/track").position, 3.0);
  EXPECT_NEAR((world.scene().world_pose(rider).p - Vec3(1, 2, 1.2)).Norm(), 0, 1e-12);
}

// On a closed path a follower wraps around, forwards and backwards; a
// script sets the velocity (through the follower's handle) and the position.
TEST_F(PathsTest, AClosedPathWrapsAndScriptsSetTheirOwnPaths) {
  Write("cart.yaml",
        TrackModel(std::string(kSquare) + "      closed: true\n      velocity: 1\n", "cart.lua"));
  Write("cart.lua",
        "local n = 0\n"
        "function sysCall_actuation()\n"
        "  n = n + 1\n"
        "  local rider = sim.getObject('./track/rider')\n"
        "  sim.recordMetric('s', sim.getPathPosition(rider))\n"
        "  if n == 46 then sim.setPathVelocity(rider, -1) end\n"
        "  if n == 60 then sim.setPathPosition(sim.getObject('./track'), 1.5) end\n"
        "  if n == 61 and sim.getRobotIndex() == 1 then\n"
        "    sim.setPathVelocity(sim.getObject('/cart#0/track'), 0)\n"
        "  end\n"
        "end\n");
  LoadedWorld w = Load(
      "simulation: {physics: kinematic, time_step: 0.1}\n"
      "models: [{model: cart.yaml, position: [0, 0, 0]}, {model: cart.yaml, position: [5, 0, "
      "0]}]\n");
  World& world = *w.world;
  const ObjectId rider = world.scene().FindObject("/cart#0/rider");
  for (int i = 0; i < 45; ++i) world.Step();  // 4.5 m: once round, then half a side
  EXPECT_NEAR(RowOf<PathRow>(world, "/cart#0/track").position, 0.5, 1e-9);
  EXPECT_NEAR((world.scene().world_pose(rider).p - Vec3(0.5, 0, 0.2)).Norm(), 0, 1e-9);
  for (int i = 0; i < 10; ++i) world.Step();  // back 1 m: past the start to 3.5
  EXPECT_NEAR(RowOf<PathRow>(world, "/cart#0/track").position, 3.5, 1e-9);
  EXPECT_NEAR((world.scene().world_pose(rider).p - Vec3(0, 0.5, 0.2)).Norm(), 0, 1e-9);
  for (int i = 0; i < 5; ++i) world.Step();  // the last one sets 1.5, then goes back 0.1
  EXPECT_NEAR(RowOf<PathRow>(world, "/cart#0/track").position, 1.4, 1e-9);
  // Another robot's path is not a script's to set.
  try {
    world.Step();
    ADD_FAILURE() << "no error";
  } catch (const Error& e) {
    EXPECT_CONTAINS(e.what(), "path '/cart#0/track' belongs to another robot");
  }
}

// Copies (placed, scaled, and made at run time) each ride their own path;
// a scaled copy's path, speed and offset scale with it.
TEST_F(PathsTest, CopiesAndScaledCopiesRideTheirOwnPaths) {
  Write("cart.yaml",
        TrackModel("      points: [[0, 0, 0], [10, 0, 0]]\n      velocity: 0.5\n", "cart.lua"));
  Write("cart.lua",
        "local n = 0\n"
        "function sysCall_actuation()\n"
        "  n = n + 1\n"
        "  if n == 4 and sim.getRobotIndex() == 0 then\n"
        "    sim.copyModel(sim.getObject('.'), {0, 5, 0})\n"
        "  end\n"
        "end\n");
  LoadedWorld w = Load(
      "simulation: {physics: kinematic, time_step: 0.1}\n"
      "models:\n"
      "  - {model: cart.yaml, position: [0, 0, 0]}\n"
      "  - {model: cart.yaml, position: [0, 2, 0], scale: 2}\n");
  World& world = *w.world;
  for (int i = 0; i < 10; ++i) world.Step();
  const Scene& scene = world.scene();
  EXPECT_EQ(RowOf<PathRow>(world, "/cart#1/track").curve->length(), 20.0);
  EXPECT_NEAR((scene.world_pose(scene.FindObject("/cart#0/rider")).p - Vec3(0.5, 0, 0.2)).Norm(), 0,
              1e-12);
  EXPECT_NEAR((scene.world_pose(scene.FindObject("/cart#1/rider")).p - Vec3(1, 2, 0.4)).Norm(), 0,
              1e-12);
  // The copy was made after 4 steps (at 0.2 m) and has moved 6 more.
  ASSERT_FALSE(scene.FindObject("/cart#2/rider").IsNull());
  EXPECT_NEAR(RowOf<PathRow>(world, "/cart#2/track").position, 0.5, 1e-12);
  EXPECT_NEAR((scene.world_pose(scene.FindObject("/cart#2/rider")).p - Vec3(0.5, 5, 0.2)).Norm(), 0,
              1e-12);
}

// worlds/path_following.yaml: every torch stays on its seam (5 cm above
// it), the twice-as-fast cell laps twice as often, the half-size cell
// laps as often as the first; the same hash at 1 and 2 threads.
TEST_F(PathsTest, TheExampleWorldsTorchesRideTheirSeams) {
  uint64_t hashes[2] = {};
  for (const int threads : {1, 2}) {
    LoadOptions options;
    options.threads = threads;
    LoadedWorld w = LoadWorld(std::string(SWARMSIM_SOURCE_DIR) + "/worlds/path_following.yaml",
                              options, registry_);
    w.world->set_log_sink([](std::string_view) {});
    for (int i = 0; i < 1000; ++i) w.world->Step();
    hashes[threads - 1] = w.world->StateHash();
    double max_error = 0;
    std::map<int, double> laps;
    for (const MetricSample& m : w.world->TakeMetrics()) {
      if (m.name == "torch_error") max_error = std::max(max_error, m.value);
      if (m.name == "laps") laps[m.instance] = m.value;
    }
    EXPECT_LT(max_error, 1e-9);
    ASSERT_EQ(laps.size(), 3u);
    EXPECT_GT(laps[0], 1);  // 50 s at 0.05 m/s round a seam of about 2.1 m
    EXPECT_NEAR(laps[1], 2 * laps[0], 0.01);
    EXPECT_NEAR(laps[2], laps[0], 1e-9);
  }
  EXPECT_EQ(hashes[0], hashes[1]);
}

TEST_F(PathsTest, EveryKeyIsDocumented) { ExpectDocumented({"path"}); }

}  // namespace
}  // namespace swarmsim
