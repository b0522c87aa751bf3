// Conveyors in world files (modules/paths/conveyor.cc and the dynamics
// backends' moving surfaces): a crate on a straight or a curved belt rides
// it at the belt's speed in ODE and in Box2D, a crate off the belt stays
// put; scripts stop and reverse a belt; scaled copies carry at their scaled
// speed; mistakes are file:line:col (or script line) errors; the example
// world delivers its crates with the same hash at 1 and 2 threads.
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <string>

#include "framework/error.h"
#include "framework/world.h"
#include "modules/paths/rows.h"
#include "swarm/loader/world_loader.h"
#include "tests/framework/error_of.h"
#include "tests/swarm/loader/world_dir_test.h"

namespace swarmsim {
namespace {

using paths::ConveyorRow;
using ConveyorsTest = testing::WorldDirTest;

// A model `line` whose root dummy holds a conveyor `belt` (its keys given),
// its top 0.4 m above the model's origin, and maybe a script.
std::string LineModel(const std::string& belt_keys, const std::string& script = "") {
  return "model: line\n"
         "objects:\n"
         "  type: dummy\n" +
         (script.empty() ? "" : "  script: " + script + "\n") +
         "  children:\n"
         "    - name: belt\n"
         "      type: conveyor\n"
         "      position: [0, 0, 0.4]\n" +
         belt_keys;
}

// A world of `physics` with the line at `line_position`, a 6 cm crate lying
// on the belt at (x, y) and another on the floor at (0, -1).
std::string CrateWorld(const std::string& physics, double x, double y,
                       const std::string& line_position = "[0, 0, 0]") {
  return "simulation: {physics: " + physics + ", time_step: 0.02, physics_substeps: 5}\n" +
         "obstacles:\n"
         "  - {name: crate, shape: box, size: [0.06, 0.06, 0.06], position: [" +
         std::to_string(x) + ", " + std::to_string(y) +
         ", 0.43], dynamic: true, mass: 0.2, friction: 0.8}\n"
         "  - {name: off, shape: box, size: [0.06, 0.06, 0.06], position: [0, -1, 0.03], "
         "dynamic: true, mass: 0.2, friction: 0.8}\n"
         "models: [{model: line.yaml, position: " +
         line_position + "}]\n";
}

Vec3 PositionOf(World& world, const std::string& path) {
  return world.scene().world_pose(world.scene().FindObject(path)).p;
}

// A crate on a straight belt moves at the belt's speed along it, in ODE
// and Box2D; the crate on the floor does not move.
TEST_F(ConveyorsTest, AStraightBeltCarriesACrateAtItsSpeed) {
  Write("line.yaml", LineModel("      points: [[-1, 0, 0], [3, 0, 0]]\n      speed: 0.25\n"));
  for (const std::string physics : {"ode", "box2d"}) {
    LoadedWorld w = Load(CrateWorld(physics, 0, 0.5, "[-0.5, 0.5, 0]"));
    World& world = *w.world;
    const Vec3 start = PositionOf(world, "/crate");
    for (int i = 0; i < 25; ++i) world.Step();  // 0.5 s: picks up the belt's speed
    const Vec3 mid = PositionOf(world, "/crate");
    for (int i = 0; i < 100; ++i) world.Step();  // 2 s more
    const Vec3 end = PositionOf(world, "/crate");
    EXPECT_NEAR(end.x - mid.x, 0.5, 0.01) << physics;  // 0.25 m/s x 2 s
    EXPECT_NEAR(end.y, start.y, 0.005) << physics;
    EXPECT_NEAR(end.z, start.z, 0.005) << physics;  // still lying on the belt
    EXPECT_NEAR((PositionOf(world, "/off") - Vec3(0, -1, 0.03)).Norm(), 0, 1e-3) << physics;
  }
}

// A quarter turn (a smooth curve): the crate follows the bend, staying over
// the belt's centre line, at the belt's speed along it.
TEST_F(ConveyorsTest, ACurvedBeltCarriesACrateRoundTheBend) {
  Write("line.yaml",
        LineModel("      points: [[0, 0, 0], [1, 0, 0], [1.7071, 0.2929, 0], [2, 1, 0], "
                  "[2, 2, 0]]\n      interpolation: smooth\n      width: 0.3\n      speed: 0.3\n"));
  for (const std::string physics : {"ode", "box2d"}) {
    LoadedWorld w = Load(CrateWorld(physics, 0.2, 0, "[0, 0, 0]"));
    World& world = *w.world;
    const ConveyorRow& belt = RowOf<ConveyorRow>(world, "/line#0/belt");
    // 10 s at 0.3 m/s: from s = 0.2 to about 3.2 of the 3.57 m belt, past the bend.
    for (int i = 0; i < 500; ++i) world.Step();
    const Vec3 end = PositionOf(world, "/crate");
    // The nearest point of the curve and how far along it lies.
    double best = 1e9, s_best = 0;
    for (double s = 0; s <= belt.curve->length(); s += 0.001) {
      const Vec3 p = belt.curve->PoseAt(s).p + Vec3(0, 0, 0.43);
      if ((p - end).Norm() < best) best = (p - end).Norm(), s_best = s;
    }
    EXPECT_LT(best, 0.05) << physics;  // on the centre line, give or take 5 cm
    EXPECT_NEAR(s_best, 0.2 + 0.3 * 10, 0.15) << physics;
    EXPECT_GT(end.y, 1.5) << physics;  // on the last straight, heading +y
  }
}

// A script stops its belt (speed 0) and reverses it; the crate stops and
// comes back. The belt is in a model: a kinematic body in ODE.
TEST_F(ConveyorsTest, ScriptsStopAndReverseTheirBelt) {
  Write("line.yaml",
        LineModel("      points: [[-1, 0, 0], [3, 0, 0]]\n      speed: 0.2\n", "line.lua"));
  Write("line.lua",
        "local n = 0\n"
        "function sysCall_actuation()\n"
        "  n = n + 1\n"
        "  local belt = sim.getObject('./belt')\n"
        "  sim.recordMetric('speed', sim.getConveyorSpeed(belt))\n"
        "  if n == 100 then sim.setConveyorSpeed(belt, 0) end\n"
        "  if n == 150 then sim.setConveyorSpeed(sim.getObject('./belt/belt0'), -0.4) end\n"
        "end\n");
  for (const std::string physics : {"ode", "box2d"}) {
    LoadedWorld w = Load(CrateWorld(physics, 0, 0.5, "[-0.5, 0.5, 0]"));
    World& world = *w.world;
    for (int i = 0; i < 100; ++i) world.Step();
    const double x_moving = PositionOf(world, "/crate").x;
    EXPECT_NEAR(x_moving, 0.4, 0.03) << physics;  // 2 s at 0.2 m/s, less the start
    for (int i = 0; i < 10; ++i) world.Step();    // stopping
    const double x_stopped = PositionOf(world, "/crate").x;
    for (int i = 0; i < 39; ++i) world.Step();  // to step 149: still stopped
    EXPECT_NEAR(PositionOf(world, "/crate").x, x_stopped, 1e-4) << physics;
    for (int i = 0; i < 11; ++i) world.Step();  // reversing from step 150
    const double x_back = PositionOf(world, "/crate").x;
    for (int i = 0; i < 50; ++i) world.Step();
    EXPECT_NEAR(PositionOf(world, "/crate").x - x_back, -0.4, 0.01) << physics;  // 1 s
    std::map<int, double> speed;
    int step = 0;
    for (const MetricSample& m : world.TakeMetrics())
      if (m.name == "speed") speed[++step] = m.value;
    EXPECT_EQ(speed[100], 0.2);  // set in step 100, applied in its actuate phase
    EXPECT_EQ(speed[101], 0.0);
    EXPECT_EQ(speed[151], -0.4);
  }
}

// A copy scaled by 2 has a belt twice as wide and twice as fast.
TEST_F(ConveyorsTest, AScaledCopysBeltIsWiderAndFaster) {
  Write("line.yaml", LineModel("      points: [[-0.5, 0, 0], [1.5, 0, 0]]\n      speed: 0.1\n"));
  LoadedWorld w = Load(
      "simulation: {physics: ode, time_step: 0.02, physics_substeps: 5}\n"
      "obstacles:\n"
      "  - {name: crate, shape: box, size: [0.06, 0.06, 0.06], position: [0, 0.5, 0.83], "
      "dynamic: true, mass: 0.2, friction: 0.8}\n"
      "models: [{model: line.yaml, position: [-0.5, 0.5, 0], scale: 2}]\n");
  World& world = *w.world;
  for (int i = 0; i < 25; ++i) world.Step();
  const ConveyorRow& belt = RowOf<ConveyorRow>(world, "/line#0/belt");
  EXPECT_EQ(belt.speed, 0.2);
  EXPECT_EQ(belt.width, 0.6);
  const Scene& scene = world.scene();
  EXPECT_EQ(scene.shape(scene.FindObject("/line#0/belt/belt0")).size.y, 0.6);
  const double x = PositionOf(world, "/crate").x;
  for (int i = 0; i < 100; ++i) world.Step();
  EXPECT_NEAR(PositionOf(world, "/crate").x - x, 0.4, 0.01);  // 2 s at 0.2 m/s
}

TEST_F(ConveyorsTest, BadConveyorsAreFileLineColumnErrors) {
  EXPECT_CONTAINS(ErrorOf("conveyor", "  points: [[0, 0, 0]]\n"),
                  "thing.yaml:4:11: 'points' needs at least 2 [x, y, z] lists");
  EXPECT_CONTAINS(ErrorOf("conveyor", "  points: [[0, 0, 0], [1, .nan, 0]]\n"), "thing.yaml:4:");
  EXPECT_CONTAINS(ErrorOf("conveyor", "  points: [[0, 0, 0], [1, 0, 0]]\n  width: -0.2\n"),
                  "thing.yaml:5:10:");
  EXPECT_CONTAINS(ErrorOf("conveyor", "  points: [[0, 0, 0], [1, 0, 0]]\n  speed: .inf\n"),
                  "thing.yaml:5:10:");
  EXPECT_CONTAINS(ErrorOf("conveyor", "  points: [[0, 0, 0], [1, 0, 0]]\n  thickness: 0\n"),
                  "thing.yaml:5:14:");
  EXPECT_CONTAINS(ErrorOf("conveyor", "  points: [[0, 0, 0], [1, 0, 0]]\n  sped: 1\n"),
                  "did you mean 'speed'?");
  EXPECT_EQ(ErrorOf("conveyor", "  points: [[0, 0, 0], [1, 0, 0]]\n  speed: -1\n"), "(no error)");
}

// A script's bad speed, or another robot's belt: an error naming the
// script's line.
TEST_F(ConveyorsTest, BadScriptCallsNameTheScriptLine) {
  Write("line.yaml", LineModel("      points: [[-1, 0, 0], [3, 0, 0]]\n", "line.lua"));
  for (const std::string call :
       {"sim.setConveyorSpeed(sim.getObject('./belt'), 0/0)",
        "sim.setConveyorSpeed(sim.getObject('./belt'), math.huge)",
        "if sim.getRobotIndex() == 1 then sim.setConveyorSpeed(sim.getObject('/line#0/belt'), 1) "
        "end",
        "sim.getConveyorSpeed(sim.getObject('.'))"}) {
    Write("line.lua", "function sysCall_actuation()\n  " + call + "\nend\n");
    LoadedWorld w = Load(
        "simulation: {physics: ode}\n"
        "models: [{model: line.yaml, position: [0, 0, 0]}, {model: line.yaml, position: [0, 2, "
        "0]}]\n");
    try {
      w.world->Step();
      ADD_FAILURE() << "no error: " << call;
    } catch (const Error& e) {
      EXPECT_CONTAINS(e.what(), "line.lua:2");
      const std::string what = e.what();
      EXPECT_TRUE(what.find("not a finite number") != std::string::npos ||
                  what.find("belongs to another robot") != std::string::npos ||
                  what.find("neither a conveyor nor a conveyor's child") != std::string::npos)
          << what;
    }
  }
}

// worlds/conveyor.yaml: all six crates dropped, picked and put down on the
// side table; the same hash at 1 and 2 threads.
TEST_F(ConveyorsTest, TheExampleWorldDeliversItsCrates) {
  uint64_t hashes[2] = {};
  for (const int threads : {1, 2}) {
    LoadOptions options;
    options.threads = threads;
    LoadedWorld w =
        LoadWorld(std::string(SWARMSIM_SOURCE_DIR) + "/worlds/conveyor.yaml", options, registry_);
    w.world->set_log_sink([](std::string_view) {});
    for (int i = 0; i < 2500; ++i) w.world->Step();
    hashes[threads - 1] = w.world->StateHash();
    std::map<std::string, double> last;
    for (const MetricSample& m : w.world->TakeMetrics()) last[m.name] = m.value;
    EXPECT_EQ(last["boxes_spawned"], 6);
    EXPECT_EQ(last["boxes_picked"], 6);
    EXPECT_EQ(last["boxes_delivered"], 6);
    // Each crate lies on the side table (its top at 0.4 m, y from -0.5 to -0.2).
    const Scene& scene = w.world->scene();
    for (int k = 2; k <= 7; ++k) {
      const Vec3 p = scene.world_pose(scene.FindObject("/crate#" + std::to_string(k))).p;
      EXPECT_NEAR(p.z, 0.43, 0.005) << k;
      EXPECT_LT(p.y, -0.2) << k;
      EXPECT_GT(p.y, -0.5) << k;
    }
  }
  EXPECT_EQ(hashes[0], hashes[1]);
}

TEST_F(ConveyorsTest, EveryKeyIsDocumented) { ExpectDocumented({"conveyor"}); }

}  // namespace
}  // namespace swarmsim
