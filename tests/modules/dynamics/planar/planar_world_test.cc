// The planar world's kinematic step and overlap resolution (planar_world.cc),
// driven directly (no World): what a user of a swarm that only drives and
// bumps would notice — rolling, walls, thin walls at speed, robots meeting,
// pushing.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "framework/dynamics_backend.h"
#include "framework/scene.h"
#include "framework/scheduler.h"
#include "framework/state_hash.h"
#include "modules/dynamics/planar/planar_backend.h"
#include "tests/framework/error_of.h"
#include "tests/modules/dynamics/plane_robot.h"

namespace swarmsim::planar {
namespace {

using plane_test::AddFloor;
using plane_test::AddRobot;
using plane_test::AddWall;
using plane_test::Robot;
using plane_test::SetWheelSpeeds;

constexpr double kDt = 0.01;       // s, one physics substep
constexpr int kSubsteps = 10;      // substeps per control step (0.1 s)
constexpr double kRadius = 0.085;  // m, plane_test::RobotSpec's body
constexpr double kTolerance = Options{}.tolerance;

std::unique_ptr<DynamicsBackend> Build(const Scene& scene, TaskScheduler* scheduler = nullptr) {
  auto backend = MakeBackend();
  DynamicsSettings settings;
  settings.scheduler = scheduler;
  backend->Build(scene, settings);
  return backend;
}

void Simulate(DynamicsBackend* backend, Scene* scene, double seconds) {
  const int steps = static_cast<int>(std::lround(seconds / (kDt * kSubsteps)));
  for (int i = 0; i < steps; ++i) {
    backend->Step(scene, kDt, kSubsteps);
    scene->UpdateWorldPoses();
  }
}

Vec3 Position(const Scene& scene, ObjectId id) { return scene.world_pose(id).p; }

TEST(PlanarBackend, RollsExactlyAtTheWheelSpeeds) {
  Scene scene;
  AddFloor(&scene);  // not an obstacle
  const double yaw0 = 0.3, v = 0.05;
  Robot straight = AddRobot(&scene, "straight", 0, 0, yaw0);
  Robot spinner = AddRobot(&scene, "spinner", 3, 3, 0);
  auto backend = Build(scene);
  SetWheelSpeeds(&scene, straight, v, v);
  SetWheelSpeeds(&scene, spinner, -v, v);  // counter-clockwise in place
  Simulate(backend.get(), &scene, 10.0);
  const Vec3 p = Position(scene, straight.body);
  EXPECT_NEAR(p.x, v * 10 * std::cos(yaw0), 1e-9);
  EXPECT_NEAR(p.y, v * 10 * std::sin(yaw0), 1e-9);
  EXPECT_DOUBLE_EQ(p.z, 0.05);  // height kept
  const Vec3 v_W = scene.linear_velocity_at(scene.SlotOf(straight.body));
  EXPECT_NEAR(v_W.x, v * std::cos(yaw0), 1e-9);  // what moved / dt
  // 2 v / axle = 1/0.14 rad/s for 10 s, centre fixed.
  const double turned = 2 * v / (2 * 0.07) * 10;
  EXPECT_NEAR(std::remainder(scene.world_pose(spinner.body).q.Yaw() - turned, 2 * M_PI), 0, 1e-9);
  EXPECT_NEAR(Position(scene, spinner.body).x, 3, 1e-9);
  EXPECT_NEAR(scene.angular_velocity_at(scene.SlotOf(spinner.body)).z, 2 * v / 0.14, 1e-9);
}

TEST(PlanarBackend, RobotDrivingIntoAWallStopsAtIt) {
  for (double yaw : {0.0, 0.5}) {  // head on and at an angle (it slides along)
    Scene scene;
    AddWall(&scene, 1.05, 0, 0.1, 4);  // face at x = 1
    Robot robot = AddRobot(&scene, "r", 0, 0, yaw);
    auto backend = Build(scene);
    SetWheelSpeeds(&scene, robot, 0.3, 0.3);
    Simulate(backend.get(), &scene, 6.0);
    const Vec3 p = Position(scene, robot.body);
    EXPECT_LE(p.x + kRadius, 1 + kTolerance) << yaw;  // penetration <= tolerance
    EXPECT_GE(p.x + kRadius, 1 - 1e-3) << yaw;        // and it is at the wall
    if (yaw > 0) {
      EXPECT_GT(p.y, 0.5);  // sliding along
    }
  }
}

TEST(PlanarBackend, TwoRobotsHeadOnDoNotOverlap) {
  Scene scene;
  Robot a = AddRobot(&scene, "a", -0.5, 0.01, 0);
  Robot b = AddRobot(&scene, "b", 0.5, -0.01, M_PI);
  auto backend = Build(scene);
  SetWheelSpeeds(&scene, a, 0.2, 0.2);
  SetWheelSpeeds(&scene, b, 0.2, 0.2);
  for (int step = 0; step < 50; ++step) {
    Simulate(backend.get(), &scene, 0.1);
    const Vec3 d = Position(scene, a.body) - Position(scene, b.body);
    ASSERT_GE(std::hypot(d.x, d.y), 2 * kRadius - kTolerance) << "step " << step;
  }
  // They met (and, off-centre, slid past each other or stayed in contact).
  EXPECT_GT(Position(scene, a.body).x, -0.2);
}

TEST(PlanarBackend, RobotCannotPassAThinWallAtAnySpeed) {
  // A 1 cm wall; the foot-bot's top speed is about 0.3 m/s: try far beyond.
  for (double v : {0.3, 3.0, 30.0}) {
    Scene scene;
    AddWall(&scene, 1, 0, 0.01, 10);
    Robot robot = AddRobot(&scene, "r", 0, 0, 0);
    auto backend = Build(scene);
    SetWheelSpeeds(&scene, robot, v, v);
    Simulate(backend.get(), &scene, 2.0);
    EXPECT_LE(Position(scene, robot.body).x + kRadius, 0.995 + kTolerance) << v << " m/s";
  }
}

// Faster than the internal steps can follow (1,000 steps of a quarter of
// the 8.5 cm radius in 0.1 s: about 212 m/s), a robot would cross the wall
// unseen: the step fails naming it instead (it went through silently).
TEST(PlanarBackend, ARobotTooFastToFollowIsAnErrorNamingIt) {
  Scene scene;
  AddWall(&scene, 1, 0, 0.01, 10);
  Robot robot = AddRobot(&scene, "r", 0, 0, 0);
  auto backend = Build(scene);
  SetWheelSpeeds(&scene, robot, 200, 200);  // within: stopped by the wall
  Simulate(backend.get(), &scene, 0.1);
  EXPECT_LE(Position(scene, robot.body).x + kRadius, 0.995 + kTolerance);
  SetWheelSpeeds(&scene, robot, -300, -300);
  const std::string error = testing::ErrorOf([&] { Simulate(backend.get(), &scene, 0.1); });
  EXPECT_CONTAINS(error, "planar: body '/r' moves at 300 m/s");
  EXPECT_CONTAINS(error, "so it would cross walls unseen; lower its speed or the time_step");
}

TEST(PlanarBackend, RobotPushesABoxWithoutWheels) {
  Scene scene;
  ShapeData crate;
  crate.kind = ShapeKind::kBox;
  crate.size = {0.1, 0.2, 0.1};
  crate.dynamic = true;
  crate.mass = 0.3;
  const ObjectId box = scene.AddShape("crate", {}, {{0.3, 0.02, 0.05}, {}}, crate);
  Robot robot = AddRobot(&scene, "r", 0, 0, 0);
  auto backend = Build(scene);
  Simulate(backend.get(), &scene, 1.0);  // no wheels, not touched: stays put
  EXPECT_EQ(Position(scene, box).x, 0.3);
  SetWheelSpeeds(&scene, robot, 0.1, 0.1);
  Simulate(backend.get(), &scene, 5.0);
  // The robot reached the box (0.165 m ahead) after 1.65 s, then pushed it
  // for 3.35 s at m_robot / (m_robot + m_box) of its wheel speed.
  const double robot_x = Position(scene, robot.body).x;
  EXPECT_NEAR(robot_x, 0.165 + 0.335 * 1.6 / 1.9, 0.01);
  EXPECT_NEAR(Position(scene, box).x - 0.05, robot_x + kRadius, 1e-3);  // in contact
  EXPECT_NEAR(Position(scene, box).y, 0.02, 1e-9);                      // no sideways push
}

}  // namespace
}  // namespace swarmsim::planar
