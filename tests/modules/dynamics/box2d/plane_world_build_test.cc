// The scene projected to the plane (plane_world_build.cc), driven directly
// (no World): one body per dynamic shape, walls and tilted obstacles as
// ground fixtures that stop robots at any speed.

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "framework/dynamics_backend.h"
#include "framework/scene.h"
#include "framework/state_hash.h"
#include "modules/dynamics/box2d/box2d_backend.h"
#include "tests/modules/dynamics/box2d/box2d_scene.h"

namespace swarmsim::box2d {
namespace {

using namespace box2d::scene_kit;  // NOLINT: the scene helpers

std::unique_ptr<DynamicsBackend> Build(const Scene& scene, const Options& options = {}) {
  auto backend = MakeBackend(options);
  backend->Build(scene, {});
  return backend;
}

TEST(Box2dBackend, MakesOneBodyPerDynamicShape) {
  Scene scene;
  AddFloor(&scene);
  AddRobot(&scene, "a", 0, 0, 0);
  AddRobot(&scene, "b", 1, 0, 0);
  AddWall(&scene, 3, 0, 0.1, 2);
  auto backend = Build(scene);
  EXPECT_EQ(backend->body_count(), 2);  // not the wheels, the wall or the floor
}

// Drives a robot at +x into a wall whose face is at x = 1; returns the
// largest centre x seen and leaves the robot at rest against it.
struct WallRun {
  double max_x = -1e9;
  double final_x = 0;
  double final_vx = 0;
};
WallRun DriveIntoWall(double v, double seconds, const RobotSpec& spec = {},
                      const Options& options = {}) {
  Scene scene;
  AddFloor(&scene);
  AddWall(&scene, 1.05, 0, 0.1, 2);  // face at x = 1.0
  Robot robot = AddRobot(&scene, "r", 0, 0, 0, spec);
  auto backend = Build(scene, options);
  SetWheelSpeeds(&scene, robot, v, v);
  WallRun out;
  Simulate(backend.get(), &scene, seconds,
           [&] { out.max_x = std::max(out.max_x, Position(scene, robot.body).x); });
  out.final_x = Position(scene, robot.body).x;
  out.final_vx = scene.linear_velocity_at(scene.SlotOf(robot.body)).x;
  return out;
}

TEST(Box2dBackend, StopsAtWall) {
  const double contact = 1.0 - 0.085;
  const WallRun run = DriveIntoWall(0.05, 30.0);  // reaches the wall after ~18 s
  EXPECT_NEAR(run.final_x, contact, 3e-3);
  EXPECT_LT(run.max_x, contact + 3e-3);
  EXPECT_NEAR(run.final_vx, 0, 1e-3);  // pushing, but not gaining energy
}

// Tilted obstacles become the hull of their projected corners. One nearly
// edge-on (a 10 m x 0.2 m x 0.1 mm sheet at 89.99 degrees) projects to a
// strip thinner than Box2D's weld distance: it is skipped, where Box2D's
// polygon code used to assert (abort); a tilted box with a real footprint
// still stops a robot.
TEST(Box2dBackend, TiltedObstaclesUseTheirProjectedHull) {
  Scene scene;
  const Robot robot = AddRobot(&scene, "r", 0, 0, 0);
  ShapeData sheet;
  sheet.kind = ShapeKind::kBox;
  sheet.size = {10, 0.2, 0.0001};
  scene.AddShape("sheet", {}, {{0, 2, 0.07}, Quat::FromAxisAngle({1, 0, 0}, 89.99 * M_PI / 180)},
                 sheet);
  ShapeData block;
  block.kind = ShapeKind::kBox;
  block.size = {0.2, 2, 0.2};
  scene.AddShape("block", {}, {{1, 0, 0.1}, Quat::FromAxisAngle({0, 1, 0}, 0.3)}, block);
  auto backend = Build(scene);
  SetWheelSpeeds(&scene, robot, 0.1, 0.1);
  Simulate(backend.get(), &scene, 15);
  // The block's hull reaches x = 1 - (0.1 cos 0.3 + 0.1 sin 0.3) ~ 0.875 m.
  EXPECT_LT(Position(scene, robot.body).x, 0.9 - 0.085);
  EXPECT_GT(Position(scene, robot.body).x, 0.7);
}

TEST(Box2dBackend, StopsAtWallWithoutTunnellingWhenFast) {
  const double contact = 1.0 - 0.085;
  const WallRun run = DriveIntoWall(0.5, 5.0);
  EXPECT_NEAR(run.final_x, contact, 3e-3);
  EXPECT_LT(run.max_x, contact + 3e-3);
  EXPECT_NEAR(run.final_vx, 0, 1e-3);
}

TEST(Box2dBackend, SmallRobotRestsAgainstWallAndDrivesTrue) {
  RobotSpec small;
  small.radius = 0.03;
  small.height = 0.04;
  small.mass = 0.1;
  small.half_axle = 0.025;
  small.wheel_radius = 0.01;
  const WallRun run = DriveIntoWall(0.05, 25.0, small);
  EXPECT_NEAR(run.final_x, 1.0 - small.radius, 2e-3);
  EXPECT_LT(run.max_x, 1.0 - small.radius + 2e-3);

  Scene scene;
  Robot robot = AddRobot(&scene, "r", 0, 0, 0, small);
  auto backend = Build(scene);
  SetWheelSpeeds(&scene, robot, 0.05, 0.05);
  Simulate(backend.get(), &scene, 10.0);
  EXPECT_NEAR(Position(scene, robot.body).x, 0.5, 0.01);
  EXPECT_NEAR(Position(scene, robot.body).y, 0, 1e-3);
  EXPECT_NEAR(Yaw(scene, robot.body), 0, 1e-3);
}

}  // namespace
}  // namespace swarmsim::box2d
