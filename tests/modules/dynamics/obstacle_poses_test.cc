// Static shapes that move (modules/dynamics/obstacle_poses.h): a wall of no
// robot moved by a script (Scene::SetWorldPose, as sim.setObjectPose does)
// or a path stops robots where it is now, not where the world file put it,
// in every engine: box2d and planar build their world again, ODE turns its
// geom into a kinematic body.
#include "modules/dynamics/obstacle_poses.h"

#include <gtest/gtest.h>

#include <string>
#include <string_view>
#include <vector>

#include "framework/registry.h"
#include "framework/world.h"
#include "modules/builtin.h"
#include "modules/force_sensor/force_sensor.h"
#include "tests/modules/dynamics/plane_robot.h"
#include "tests/modules/module_world.h"

namespace swarmsim {
namespace {

using testing::ModuleWorld;

TEST(ObstaclePosesTest, TellsAMoveOfAnyShapeItHolds) {
  Scene scene;
  const ObjectId a = plane_test::AddWall(&scene, 1, 0, 0.1, 1);
  const ObjectId b = plane_test::AddWall(&scene, 2, 0, 0.1, 1);
  dynamics::ObstaclePoses poses;
  EXPECT_FALSE(poses.Moved(scene));
  poses.Add(a.index(), scene.world_pose(a));
  poses.Add(b.index(), scene.world_pose(b));
  EXPECT_FALSE(poses.Moved(scene));
  scene.SetWorldPose(b, {{2, 1e-9, 0.1}, {}});
  EXPECT_TRUE(poses.Moved(scene));
  poses.Clear();
  EXPECT_FALSE(poses.Moved(scene));
}

// A robot drives at 0.1 m/s towards a wall (face at x = 0.45) and stops
// there; the wall is moved to x = 1.2 (face at 1.15): the robot drives on
// through where it was and stops at its new place.
class PlanarEnginesTest : public ::testing::TestWithParam<std::string> {};

TEST_P(PlanarEnginesTest, ARobotMeetsAMovedWallWhereItIsNow) {
  ModuleWorld w(GetParam(), 1, 0.1);
  plane_test::AddFloor(&w.scene());
  const plane_test::Robot robot = plane_test::AddRobot(&w.scene(), "bot", 0, 0, 0);
  plane_test::SetWheelSpeeds(&w.scene(), robot, 0.1, 0.1);
  const ObjectId wall = plane_test::AddWall(&w.scene(), 0.5, 0, 0.1, 1);
  const double radius = robot.spec.radius;
  ASSERT_EQ(w.Run(60), "");  // 6 s: 0.6 m, were there no wall
  EXPECT_NEAR(w.scene().world_pose(robot.body).p.x, 0.45 - radius, 5e-3);
  w.scene().SetWorldPose(wall, {{1.2, 0, 0.1}, {}});
  ASSERT_EQ(w.Run(120), "");  // 12 s more: 1.2 m more, were there no wall
  EXPECT_NEAR(w.scene().world_pose(robot.body).p.x, 1.15 - radius, 5e-3)
      << "stopped at the wall's new place, having passed its old one";
}

// box2d cut into regions (two strips here, one robot in each): a wall
// across both, moved, is taken out of each region and put in again where it
// is now, in every region it reaches.
TEST(Box2dObstacleTest, AMovedWallStopsTheRobotsOfEveryRegion) {
  ModuleRegistry registry;
  RegisterBuiltinModules(&registry);
  WorldSettings settings;
  settings.physics = "box2d";
  settings.time_step = 0.1;
  settings.physics_partitions = 2;
  settings.threads = 2;
  World world(settings, registry);
  world.set_log_sink([](std::string_view) {});
  Scene& scene = world.scene();
  plane_test::AddFloor(&scene);
  std::vector<plane_test::Robot> robots;
  for (double y : {-4.0, 4.0}) {
    robots.push_back(plane_test::AddRobot(&scene, "bot", 0, y, 0));
    plane_test::SetWheelSpeeds(&scene, robots.back(), 0.1, 0.1);
  }
  const ObjectId wall = plane_test::AddWall(&scene, 0.5, 0, 0.1, 12);
  world.Start();
  for (int i = 0; i < 60; ++i) world.Step();
  const double radius = robots[0].spec.radius;
  for (const plane_test::Robot& robot : robots)
    EXPECT_NEAR(scene.world_pose(robot.body).p.x, 0.45 - radius, 5e-3);
  scene.SetWorldPose(wall, {{1.2, 0, 0.1}, {}});
  for (int i = 0; i < 120; ++i) world.Step();
  for (const plane_test::Robot& robot : robots)
    EXPECT_NEAR(scene.world_pose(robot.body).p.x, 1.15 - radius, 5e-3);
}

INSTANTIATE_TEST_SUITE_P(Engines, PlanarEnginesTest, ::testing::Values("box2d", "planar"),
                         [](const auto& info) { return info.param; });

// ODE: a ball dropped on a table (its top at z = 0.5) rests on it; the
// table moved away, the ball falls to the ground plane.
TEST(OdeObstacleTest, ABallFallsWhenItsTableIsMovedAway) {
  ModuleWorld w("ode", 1, 0.05);
  ShapeData ball;
  ball.kind = ShapeKind::kSphere;
  ball.size = {0.1, 0, 0};
  ball.dynamic = true;
  ball.mass = 1;
  const ObjectId b = w.scene().AddShape("ball", {}, {{0, 0, 0.8}, {}}, ball);
  const ObjectId table = w.Box("table", {}, {{0, 0, 0.25}, {}}, {1, 1, 0.5});
  ASSERT_EQ(w.Run(40), "");  // 2 s
  EXPECT_NEAR(w.scene().world_pose(b).p.z, 0.6, 0.01);
  w.scene().SetWorldPose(table, {{5, 0, 0.25}, {}});
  ASSERT_EQ(w.Run(40), "");
  EXPECT_NEAR(w.scene().world_pose(b).p.z, 0.1, 0.01) << "on the ground, not on the table";
}

ShapeData Dynamic(ShapeKind kind, const Vec3& size, double mass) {
  ShapeData s;
  s.kind = kind;
  s.size = size;
  s.dynamic = true;
  s.mass = mass;
  return s;
}

// ODE: a static shape that jumps (2 m in one step: a path's follower put
// at the path's start, a door toggled) is put there, not swept through what
// lies between: a crate on the way is not thrown.
TEST(OdeObstacleTest, AJumpDoesNotRamWhatLiesOnTheWay) {
  ModuleWorld w("ode", 1, 0.1);
  const ObjectId crate = w.scene().AddShape("crate", {}, {{-1, 0, 0.1}, {}},
                                            Dynamic(ShapeKind::kBox, {0.2, 0.2, 0.2}, 1));
  const ObjectId puck = w.Box("puck", {}, {{0, 0, 0.1}, {}}, {0.4, 0.4, 0.2});
  ASSERT_EQ(w.Run(5), "");
  w.scene().SetWorldPose(puck, {{-2, 0, 0.1}, {}});
  ASSERT_EQ(w.Run(10), "");
  EXPECT_NEAR(w.scene().world_pose(crate).p.x, -1, 1e-3) << "left where it was";
  EXPECT_NEAR(w.scene().world_pose(crate).p.z, 0.1, 1e-2);
}

// ODE: a static table moved 4 mm a step carries a dynamic crate that hangs
// from it in the scene tree 1:1 (the scene moves the crate with it; the
// table's motion adds no friction drag on top), as box2d and planar do; and
// a force sensor under a static beam that moves carries its load along.
TEST(OdeObstacleTest, WhatHangsFromAMovedStaticShapeMovesWithIt) {
  ModuleWorld w("ode", 1, 0.05);
  const ObjectId table = w.Box("table", {}, {{0, 0, 0.25}, {}}, {1, 1, 0.5});
  const ObjectId crate = w.scene().AddShape("crate", table, {{0, 0, 0.35}, {}},
                                            Dynamic(ShapeKind::kBox, {0.2, 0.2, 0.2}, 2));
  const ObjectId beam = w.Box("beam", {}, {{3, 0, 2}, {}}, {0.2, 0.2, 0.05});
  ObjectType sensor_type;
  ASSERT_TRUE(force_sensor::FindType(w.scene(), &sensor_type));
  ForceSensorData settings;
  const ObjectId hook =
      w.scene().AddObject(sensor_type, "hook", beam, {{0, 0, -0.05}, {}}, &settings);
  const ObjectId load = w.scene().AddShape("load", hook, {{0, 0, -0.25}, {}},
                                           Dynamic(ShapeKind::kSphere, {0.05, 0, 0}, 2));
  ASSERT_EQ(w.Run(20), "");
  for (int step = 1; step <= 40; ++step) {
    w.scene().SetWorldPose(table, {{0.004 * step, 0, 0.25}, {}});
    w.scene().SetWorldPose(beam, {{3 + 0.004 * step, 0, 2}, {}});
    w.scene().UpdateWorldPoses();
    ASSERT_EQ(w.Run(1), "");
  }
  ASSERT_EQ(w.Run(20), "");
  EXPECT_NEAR(w.scene().world_pose(crate).p.x, 0.16, 5e-3) << "not twice as far";
  EXPECT_NEAR(w.scene().world_pose(load).p.x, 3.16, 5e-3) << "the load follows its hook";
  EXPECT_NEAR(force_sensor::Row(w.scene(), hook).force.z, 2 * 9.81, 0.2);
}

}  // namespace
}  // namespace swarmsim
