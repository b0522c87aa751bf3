// The planning module (modules/planning/module.cc) through a World: each
// task's result path made at the start, a requested plan run in the
// actuate phase and written into that path, a goal in an obstacle failing
// with its reason, and requests that cannot be made naming the task.
#include "modules/planning/module.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "modules/paths/curve.h"
#include "modules/paths/rows.h"
#include "modules/planning/rows.h"
#include "tests/framework/error_of.h"
#include "tests/modules/module_world.h"

namespace swarmsim::planning {
namespace {

using testing::ErrorOf;
using testing::ModuleWorld;

// A robot "bot" (a 0.2 m box body) at (-1, 0) in a 4 x 4 m arena with a
// wall "wall" across x = 0 from y = -2 to 1 (a gap above it); the task
// "task" of the robot plans in se2 within the arena.
struct Arena {
  ModuleWorld w;
  ObjectId bot, task;
  Arena() {
    bot = w.Robot("bot", {{-1, 0, 0.1}, {}});
    w.Box("body", bot, {}, {0.2, 0.2, 0.2});
    w.Box("wall", {}, {{0, -0.5, 0.25}, {}}, {0.1, 3, 0.5});
    PlanningTaskRow row;
    row.robot = ":";
    row.obstacles = "everything_else";
    row.has_bounds = true;
    row.lo = {-2, -2, 0};
    row.hi = {2, 2, 1};
    task = w.Add(kTypeName, "task", bot, {}, &row);
  }
  PlanningTaskRow& row() { return w.RowOf<PlanningTaskRow>(kTypeName, task); }
  void Request(double x, double y, double yaw, uint64_t seed = 7) {
    PlanningTaskRow& t = row();
    t.requested = true;
    t.goal = {{x, y, 0.1}, Quat::FromYaw(yaw)};
    t.request_time_limit = 1;
    t.seed = seed;
  }
};

TEST(PlanningModuleTest, EachTaskGetsItsPathAtTheStart) {
  Arena a;
  ASSERT_EQ(a.w.Run(0), "");
  const ObjectId path = a.row().path;
  ASSERT_TRUE(a.w.scene().IsValid(path));
  EXPECT_EQ(a.w.scene().PathOf(path), "/task_path");
  EXPECT_EQ(a.row().status, PlanStatus::kNone);
}

TEST(PlanningModuleTest, ARequestedPlanGoesAroundTheWallIntoThePath) {
  Arena a;
  ASSERT_EQ(a.w.Run(0), "");
  a.Request(1, 0, 0);
  ASSERT_EQ(a.w.Run(1), "");
  const PlanningTaskRow& t = a.row();
  ASSERT_EQ(t.status, PlanStatus::kSolved) << t.reason;
  EXPECT_EQ(t.reason, "solved");
  EXPECT_FALSE(t.requested);
  EXPECT_GT(t.iterations, 0);
  ASSERT_GE(t.dense.size(), 2u);
  EXPECT_NEAR((t.dense.front().p - Vec3{-1, 0, 0.1}).Norm(), 0, 1e-6);
  EXPECT_NEAR(t.dense.back().p.x, 1, 1e-6);
  EXPECT_NEAR(t.dense.back().p.y, 0, 1e-6);
  // Around the wall: through the gap above y = 1.
  double highest = -INFINITY;
  for (const Pose& X : t.dense) highest = std::max(highest, X.p.y);
  EXPECT_GT(highest, 1.0);
  // The path object follows the plan from its start.
  const auto& path = a.w.RowOf<paths::PathRow>(paths::kTypeName, t.path);
  EXPECT_EQ(path.position, 0);
  EXPECT_NEAR((path.curve->points().front() - t.dense.front().p).Norm(), 0, 1e-9);
  EXPECT_NEAR((path.curve->points().back() - t.dense.back().p).Norm(), 0, 1e-9);
}

TEST(PlanningModuleTest, AGoalInsideTheWallFailsWithItsReason) {
  Arena a;
  ASSERT_EQ(a.w.Run(0), "");
  a.Request(0, -0.5, 0);
  ASSERT_EQ(a.w.Run(1), "");
  EXPECT_EQ(a.row().status, PlanStatus::kFailed);
  EXPECT_EQ(a.row().reason, "invalid goal: in collision");
}

TEST(PlanningModuleTest, TheSameRequestGivesTheSamePlan) {
  std::vector<Pose> plans[2];
  for (int i = 0; i < 2; ++i) {
    Arena a;
    ASSERT_EQ(a.w.Run(0), "");
    a.Request(1, 0, 0);
    ASSERT_EQ(a.w.Run(1), "");
    plans[i] = a.row().dense;
  }
  ASSERT_EQ(plans[0].size(), plans[1].size());
  for (size_t k = 0; k < plans[0].size(); ++k) EXPECT_EQ(plans[0][k], plans[1][k]);
}

TEST(PlanningModuleTest, RequestsThatCannotBeMadeNameTheTask) {
  Arena a;
  PlanningTaskRow t = a.row();
  t.where = "world.yaml:4:5";
  t.robot = "./nobody";
  const uint32_t owner = a.w.scene().SlotOf(a.task);
  EXPECT_EQ(ErrorOf([&] { PlanningModule::MakeRequest(a.w.scene(), owner, t); }),
            "world.yaml:4:5: planning task /bot/task: robot './nobody' matches no object");
  // No bounds, and nothing static but the wall: its centre alone is no box.
  t.robot = ":";
  t.has_bounds = false;
  EXPECT_CONTAINS(ErrorOf([&] { PlanningModule::MakeRequest(a.w.scene(), owner, t); }),
                  "no bounds given and no static shapes (an arena) to take them from");
  // With posts at the corners, the box of their centres.
  a.w.Box("post1", {}, {{-3, -2, 0.5}, {}}, {0.1, 0.1, 1});
  a.w.Box("post2", {}, {{3, 2, 0.5}, {}}, {0.1, 0.1, 1});
  const PlanRequest r = PlanningModule::MakeRequest(a.w.scene(), owner, t);
  EXPECT_EQ(r.lo.x, -3);
  EXPECT_EQ(r.hi.y, 2);
  EXPECT_EQ(r.lo.z, 0);
  EXPECT_EQ(r.hi.z, 2);
  EXPECT_NEAR((r.start.p - Vec3{-1, 0, 0.1}).Norm(), 0, 1e-12);
}

}  // namespace
}  // namespace swarmsim::planning
