// The scripts' side of modules/planning (lua_api_planning.cc): sim.planPath
// answered in the same step's actuate phase, sim.readPlan, sim.getPlanStates,
// sim.setPlanningTask, who may use which task, and the errors.
#include <gtest/gtest.h>

#include <string>

#include "modules/planning/rows.h"
#include "tests/modules/module_world.h"

namespace swarmsim::planning {
namespace {

using testing::ModuleWorld;

// A robot "bot" (a 0.2 m box body) at (-1, 0) with a task "task" in a
// 4 x 4 m box of bounds, a scene task "other", a post "post" at (1, 1);
// `code` runs on the robot.
struct PlanScripts {
  ModuleWorld w;
  ObjectId task;
  explicit PlanScripts(const std::string& code) {
    const ObjectId bot = w.Robot("bot", {{-1, 0, 0.1}, {}});
    w.Box("body", bot, {}, {0.2, 0.2, 0.2});
    w.Box("post", {}, {{1, 1, 0.25}, {}}, {0.2, 0.2, 0.5});
    PlanningTaskRow row;
    row.has_bounds = true;
    row.lo = {-2, -2, 0};
    row.hi = {2, 2, 0};
    task = w.Add(kTypeName, "task", bot, {}, &row);
    row.robot = "/post";
    w.Add(kTypeName, "other", {}, {}, &row);
    w.Script(bot, code);
  }
  std::string Log() const {
    std::string all;
    for (const std::string& line : w.log()) all += line + "\n";
    return all;
  }
};

TEST(LuaApiPlanningTest, APlanIsPendingThenSolvedWithItsStatesAndPath) {
  PlanScripts s(R"(
    local step = 0
    function sysCall_actuation()
      step = step + 1
      local task = sim.getObject('./task')
      if step == 1 then
        sim.planPath(task, {1, -1, 0})
        print('asked: ' .. (sim.readPlan(task)))
      elseif step == 2 then
        local status, reason, path, length = sim.readPlan(task)
        local states = sim.getPlanStates(task)
        print(string.format('%s %s path %s length>2 %s states>1 %s first %.3f %.3f last %.3f %.3f',
          status, reason, tostring(path ~= nil), tostring(length > 2), tostring(#states > 1),
          states[1][1], states[1][2], states[#states][1], states[#states][2]))
      end
    end
  )");
  ASSERT_EQ(s.w.Run(2), "");
  EXPECT_CONTAINS(s.Log(), "asked: pending");
  EXPECT_CONTAINS(s.Log(),
                  "solved solved path true length>2 true states>1 true first -1.000 0.000 last "
                  "1.000 -1.000");
}

TEST(LuaApiPlanningTest, SetPlanningTaskChangesTheSettings) {
  PlanScripts s(R"(
    function sysCall_init()
      sim.setPlanningTask(sim.getObject('./task'), {space = 'dubins', turning_radius = 0.3,
        resolution = 0.02, time_limit = 4, obstacles = 'everything_else',
        bounds = {-3, -3, 3, 3}})
    end
  )");
  ASSERT_EQ(s.w.Run(1), "");
  const PlanningTaskRow& t = s.w.RowOf<PlanningTaskRow>(kTypeName, s.task);
  EXPECT_EQ(t.space, Space::kDubins);
  EXPECT_DOUBLE_EQ(t.turning_radius, 0.3);
  EXPECT_DOUBLE_EQ(t.resolution, 0.02);
  EXPECT_DOUBLE_EQ(t.time_limit, 4);
  EXPECT_EQ(t.obstacles, "everything_else");
  EXPECT_EQ(t.lo, (Vec3{-3, -3, 0}));
}

std::string ErrorOfLine(const std::string& line) {
  PlanScripts s("function sysCall_init()\n" + line + "\nend\n");
  return s.w.Run(1);
}

TEST(LuaApiPlanningTest, MistakesAreErrorsNamingWhatIsWrong) {
  EXPECT_CONTAINS(ErrorOfLine("sim.planPath(sim.getObject('./task'), {1, 1})"),
                  "bad argument #2 (a goal {x, y, yaw} expected for a se2 task, got 2 numbers)");
  EXPECT_CONTAINS(ErrorOfLine("sim.planPath(sim.getObject('./task'), {1, 0/0, 0})"),
                  "the goal: element 2 is not a finite number");
  EXPECT_CONTAINS(ErrorOfLine("sim.planPath(sim.getObject('./task'), {1, 1, 0}, -1)"),
                  "the time limit must be a positive number of seconds");
  // A budget past an hour (72 million planner iterations) would be a plan
  // that never ends, as a world file's time_limit cannot ask for.
  EXPECT_CONTAINS(ErrorOfLine("sim.planPath(sim.getObject('./task'), {1, 1, 0}, 1e9)"),
                  "the time limit must be a positive number of seconds, at most 3600 (got");
  EXPECT_CONTAINS(ErrorOfLine("sim.setPlanningTask(sim.getObject('./task'), {time_limit = 3601})"),
                  "time_limit must be a positive number of seconds, at most 3600");
  EXPECT_CONTAINS(ErrorOfLine("sim.planPath(sim.getObject('./task'), {1, 1, 0}, 1/0)"),
                  "at most 3600 (got inf)");
  // Checks every nanometre would never end (QA: 800 MB in 15 s).
  EXPECT_CONTAINS(ErrorOfLine("sim.setPlanningTask(sim.getObject('./task'), {resolution = 1e-9})"),
                  "resolution must be a number of metres from 0.0001 (got 1e-09)");
  EXPECT_CONTAINS(ErrorOfLine("sim.planPath(sim.getObject('/other'), {1, 1, 0})"),
                  "planning task '/other' belongs to another robot");
  EXPECT_CONTAINS(ErrorOfLine("sim.readPlan(sim.getObject('./body'))"),
                  "object /bot/body is not a planning_task");
  EXPECT_CONTAINS(ErrorOfLine("sim.setPlanningTask(sim.getObject('./task'), {speed = 1})"),
                  "unknown setting 'speed' (space, turning_radius, resolution, time_limit, bounds, "
                  "obstacles)");
  EXPECT_CONTAINS(ErrorOfLine("sim.setPlanningTask(sim.getObject('./task'), {space = 'se4'})"),
                  "unknown state space 'se4' (se2, se3, dubins, reeds_shepp)");
  EXPECT_CONTAINS(ErrorOfLine("sim.setPlanningTask(sim.getObject('./task'), {space = 'se3'})"),
                  "the task's bounds are planar: give new bounds with a space of the other kind");
  EXPECT_CONTAINS(
      ErrorOfLine("sim.setPlanningTask(sim.getObject('./task'), {obstacles = '/nothing'})"),
      "obstacles '/nothing' is neither 'environment', 'everything_else' nor an object path");
  EXPECT_CONTAINS(
      ErrorOfLine("sim.setPlanningTask(sim.getObject('./task'), {bounds = {1, 1, 0, 0}})"),
      "bounds: each minimum must be below its maximum");
}

}  // namespace
}  // namespace swarmsim::planning
