// Planning tasks in world files (modules/planning): plans checked for
// collisions with the test's own geometry (rectangles, no FCL), a failed
// plan's status and reason as a result the run goes on after, bad keys
// (file:line:column) and a time limit of 0 from a script (script and line),
// the example world's hash at 1, 2 and 4 threads and with another seed, and
// the docs.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "framework/error.h"
#include "framework/world.h"
#include "modules/paths/rows.h"
#include "modules/planning/rows.h"
#include "swarm/loader/world_loader.h"
#include "tests/framework/error_of.h"
#include "tests/swarm/loader/world_dir_test.h"

namespace swarmsim {
namespace {

using planning::PlanningTaskRow;
using planning::PlanStatus;
using PlanningTest = testing::WorldDirTest;

// An axis-aligned box in the plane.
struct Box {
  double x0, y0, x1, y1;
};

// The 6 x 6 m arena of Yard() (walls 0.1 m thick) and its obstacles.
std::vector<Box> YardBoxes() {
  return {{-3.1, -3.1, 3.1, -3.0}, {-3.1, 3.0, 3.1, 3.1}, {-3.1, -3.1, -3.0, 3.1},
          {3.0, -3.1, 3.1, 3.1},   {-0.2, -3, 0.2, 1.5},  {1.2, -1.5, 1.8, 3}};
}

std::string Yard(const std::string& extra_obstacles = "") {
  return "simulation: {physics: kinematic, time_step: 0.1, seed: 3}\n"
         "arena: {size: 6, wall_thickness: 0.1, wall_height: 0.3}\n"
         "obstacles:\n"
         "  - {shape: box, size: [0.4, 4.5, 0.3], position: [0, -0.75, 0.15]}\n"
         "  - {shape: box, size: [0.6, 4.5, 0.3], position: [1.5, 0.75, 0.15]}\n" +
         extra_obstacles + "models: [{model: rover.yaml, position: [-2.2, -2], heading_deg: 90}]\n";
}

// A 0.4 x 0.2 m rover with a planning task (its keys given) whose script
// plans to `goal` once.
std::string Rover(const std::string& task_keys) {
  return "model: rover\n"
         "objects:\n"
         "  name: body\n"
         "  type: shape\n"
         "  shape: box\n"
         "  size: [0.4, 0.2, 0.1]\n"
         "  script: rover.lua\n"
         "  children:\n"
         "    - name: planner\n"
         "      type: planning_task\n" +
         task_keys;
}

std::string PlanOnce(const std::string& goal) {
  return "function sysCall_init()\n"
         "  sim.planPath(sim.getObject('./planner'), " +
         goal +
         ")\n"
         "end\n";
}

// Does the rover's rectangle at (x, y, yaw) overlap the box? (Separating
// axes: the box's two and the rectangle's two.)
bool Overlaps(const Box& b, double x, double y, double yaw, double hx, double hy) {
  const double c = std::cos(yaw), s = std::sin(yaw);
  // The rectangle's extent along x and y, and the box's along the rectangle's axes.
  const double ex = std::abs(c) * hx + std::abs(s) * hy, ey = std::abs(s) * hx + std::abs(c) * hy;
  const double bx = (b.x0 + b.x1) / 2, by = (b.y0 + b.y1) / 2;
  const double bhx = (b.x1 - b.x0) / 2, bhy = (b.y1 - b.y0) / 2;
  if (std::abs(x - bx) > ex + bhx || std::abs(y - by) > ey + bhy) return false;
  const double dx = bx - x, dy = by - y;
  const double along_u = std::abs(dx * c + dy * s), along_v = std::abs(-dx * s + dy * c);
  if (along_u > hx + std::abs(c) * bhx + std::abs(s) * bhy) return false;
  if (along_v > hy + std::abs(s) * bhx + std::abs(c) * bhy) return false;
  return true;
}

void ExpectClear(const std::vector<Pose>& states) {
  ASSERT_GE(states.size(), 2u);
  for (size_t i = 0; i + 1 < states.size(); ++i) {
    // Between two states (at most `resolution` apart) too.
    for (int k = 0; k < 4; ++k) {
      const double t = k / 4.0;
      const Vec3 p = states[i].p + (states[i + 1].p - states[i].p) * t;
      const double yaw = states[i].q.Yaw() +
                         std::remainder(states[i + 1].q.Yaw() - states[i].q.Yaw(), 2 * M_PI) * t;
      for (const Box& b : YardBoxes())
        ASSERT_FALSE(Overlaps(b, p.x, p.y, yaw, 0.2 - 1e-3, 0.1 - 1e-3))
            << "state " << i << " (" << p.x << ", " << p.y << ", " << yaw << ") hits a box";
    }
  }
}

TEST_F(PlanningTest, PlansGoRoundTheObstaclesAndBecomeThePathsCurve) {
  for (const std::string space : {"se2", "dubins", "reeds_shepp"}) {
    Write("rover.yaml",
          Rover("      space: " + space + "\n      turning_radius: 0.3\n      resolution: 0.02\n"));
    Write("rover.lua", PlanOnce("{2.4, 2.2, math.pi / 2}") +
                           "function sysCall_actuation()\n"
                           "  local status, reason, path, length = "
                           "sim.readPlan(sim.getObject('./planner'))\n"
                           "  if status == 'solved' then\n"
                           "    local p = sim.getPathPose(path, length)\n"
                           "    sim.recordMetric('end_x', p[1])\n"
                           "    sim.recordMetric('states', #sim.getPlanStates(sim.getObject("
                           "'./planner')))\n"
                           "  end\n"
                           "end\n");
    LoadedWorld w = Load(Yard());
    World& world = *w.world;
    world.Step();
    world.Step();
    const PlanningTaskRow& task = RowOf<PlanningTaskRow>(world, "/rover#0/planner");
    ASSERT_EQ(task.status, PlanStatus::kSolved) << space << ": " << task.reason;
    EXPECT_EQ(task.reason, "solved");
    ExpectClear(task.dense);
    // It starts at the rover and ends at the goal, weaving between the walls.
    EXPECT_NEAR((task.dense.front().p - Vec3(-2.2, -2, 0.05)).Norm(), 0, 1e-6) << space;
    EXPECT_NEAR((task.dense.back().p - Vec3(2.4, 2.2, 0.05)).Norm(), 0, 1e-6) << space;
    double top = -9, bottom = 9;
    for (const Pose& X : task.dense) {
      if (std::abs(X.p.x) < 0.3) top = std::max(top, X.p.y);
      if (std::abs(X.p.x - 1.5) < 0.4) bottom = std::min(bottom, X.p.y);
    }
    EXPECT_GT(top, 1.5) << space << ": passes the first wall above its end";
    EXPECT_LT(bottom, -1.5) << space << ": passes the second wall below its end";
    // The path object the script reads is the plan.
    ASSERT_TRUE(world.scene().IsValid(task.path));
    const auto& path = *static_cast<paths::PathRow*>(world.scene().row_data(task.path));
    EXPECT_NEAR(path.curve->points().back().x, 2.4, 1e-6);
    double end_x = 0, states = 0;
    for (const MetricSample& m : world.TakeMetrics()) {
      if (m.name == "end_x") end_x = m.value;
      if (m.name == "states") states = m.value;
    }
    EXPECT_NEAR(end_x, 2.4, 1e-6);
    EXPECT_EQ(states, static_cast<double>(task.dense.size()));
  }
}

TEST_F(PlanningTest, ImpossibleGoalsAreResultsAndTheRunGoesOn) {
  Write("rover.yaml", Rover("      time_limit: 0.1\n"));
  const struct {
    const char* goal;
    const char* reason;
  } cases[] = {
      {"{0, 0, 0}", "invalid goal: in collision"},
      {"{5, 0, 0}", "invalid goal: outside bounds"},
      {"{2.4, -2.4, 0}", "goal enclosed/unreachable"},
  };
  // A pen of boxes round (2.4, -2.4).
  const std::string pen =
      "  - {shape: box, size: [1.2, 0.1, 0.3], position: [2.4, -1.8, 0.15]}\n"
      "  - {shape: box, size: [0.1, 1.2, 0.3], position: [1.85, -2.4, 0.15]}\n";
  for (const auto& c : cases) {
    Write("rover.lua", PlanOnce(c.goal));
    LoadedWorld w = Load(Yard(pen));
    World& world = *w.world;
    world.Step();
    const PlanningTaskRow& task = RowOf<PlanningTaskRow>(world, "/rover#0/planner");
    EXPECT_EQ(task.status, PlanStatus::kFailed) << c.goal;
    EXPECT_EQ(task.reason, c.reason) << c.goal;
    EXPECT_NO_THROW(for (int i = 0; i < 3; ++i) world.Step());
  }
}

TEST_F(PlanningTest, BadKeysAreFileLineColumnErrors) {
  EXPECT_CONTAINS(ErrorOf("planning_task", "  space: se4\n"), "thing.yaml:4:10:");
  EXPECT_CONTAINS(ErrorOf("planning_task", "  space: dubbins\n"), "did you mean 'dubins'?");
  EXPECT_CONTAINS(ErrorOf("planning_task", "  time_limit: 0\n"), "thing.yaml:4:15:");
  EXPECT_CONTAINS(ErrorOf("planning_task", "  time_limit: -1\n"), "thing.yaml:4:15:");
  EXPECT_CONTAINS(ErrorOf("planning_task", "  bounds: [0, 0, 1]\n"), "thing.yaml:4:11:");
  EXPECT_CONTAINS(ErrorOf("planning_task", "  bounds: [0, 0, -1, 1]\n"),
                  "each minimum must be below its maximum");
  EXPECT_CONTAINS(ErrorOf("planning_task", "  robot: ./nowhere\n"),
                  "thing.yaml:4:10: planning task /thing#0: './nowhere' matches no object");
  EXPECT_CONTAINS(ErrorOf("planning_task", "  turning_radius: 0\n"), "thing.yaml:4:19:");
  EXPECT_EQ(ErrorOf("planning_task", "  space: reeds_shepp\n  bounds: [-1, -1, 1, 1]\n"),
            "(no error)");
}

TEST_F(PlanningTest, ATimeLimitOfZeroOrAnUnknownSpaceFromAScriptIsAnErrorAtItsLine) {
  Write("rover.yaml", Rover("      space: se2\n"));
  const std::string calls[] = {
      "sim.planPath(sim.getObject('./planner'), {1, 1, 0}, 0)",
      "sim.setPlanningTask(sim.getObject('./planner'), {space = 'se4'})",
      "sim.setPlanningTask(sim.getObject('./planner'), {time_limit = -2})",
      "sim.planPath(sim.getObject('./planner'), {1, 1})",
  };
  const std::string messages[] = {
      "the time limit must be a positive number of seconds",
      "unknown state space 'se4' (se2, se3, dubins, reeds_shepp)",
      "time_limit must be a positive number of seconds",
      "a goal {x, y, yaw} expected for a se2 task, got 2 numbers",
  };
  for (int i = 0; i < 4; ++i) {
    Write("rover.lua", "function sysCall_init()\n  " + calls[i] + "\nend\n");
    try {
      LoadedWorld w = Load(Yard());
      w.world->Step();
      ADD_FAILURE() << "no error for " << calls[i];
    } catch (const Error& e) {
      EXPECT_CONTAINS(e.what(), "rover.lua:2:");
      EXPECT_CONTAINS(e.what(), messages[i]);
    }
  }
}

// worlds/planning.yaml: 20 Dubins cars plan and drive; the same hash at 1, 2
// and 4 threads, another with another seed; cars arrive within 30 s.
TEST_F(PlanningTest, TheExampleWorldIsTheSameAtAnyThreadCount) {
  uint64_t hashes[3] = {};
  int slot = 0;
  for (const int threads : {1, 2, 4}) {
    LoadOptions options;
    options.threads = threads;
    LoadedWorld w =
        LoadWorld(std::string(SWARMSIM_SOURCE_DIR) + "/worlds/planning.yaml", options, registry_);
    w.world->set_log_sink([](std::string_view) {});
    for (int i = 0; i < 300; ++i) w.world->Step();
    hashes[slot++] = w.world->StateHash();
    if (threads == 1) {
      double arrived = 0;
      for (const MetricSample& m : w.world->TakeMetrics())
        if (m.name == "arrived" && m.step == 299) arrived += m.value;
      EXPECT_GE(arrived, 5);
    }
  }
  EXPECT_EQ(hashes[0], hashes[1]);
  EXPECT_EQ(hashes[0], hashes[2]);
  LoadOptions options;
  options.threads = 2;
  options.seed = 4;
  LoadedWorld w =
      LoadWorld(std::string(SWARMSIM_SOURCE_DIR) + "/worlds/planning.yaml", options, registry_);
  w.world->set_log_sink([](std::string_view) {});
  for (int i = 0; i < 3; ++i) w.world->Step();
  const PlanningTaskRow& other = RowOf<PlanningTaskRow>(*w.world, "/planning_car#0/planner");
  LoadOptions same;
  same.threads = 1;
  LoadedWorld v =
      LoadWorld(std::string(SWARMSIM_SOURCE_DIR) + "/worlds/planning.yaml", same, registry_);
  v.world->set_log_sink([](std::string_view) {});
  for (int i = 0; i < 3; ++i) v.world->Step();
  const PlanningTaskRow& first = RowOf<PlanningTaskRow>(*v.world, "/planning_car#0/planner");
  EXPECT_NE(first.waypoints, other.waypoints);
}

TEST_F(PlanningTest, EveryKeyIsDocumented) { ExpectDocumented({"planning_task"}); }

}  // namespace
}  // namespace swarmsim
