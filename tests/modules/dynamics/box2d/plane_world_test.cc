// The Box2D plane world's step (plane_world.cc), driven directly (no World):
// what a user of a wheeled swarm would notice — distances, turn rates,
// pushing, traction limits, sliding, write-back of carried objects and
// teleports.

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
#include "modules/proximity/proximity_sensor.h"
#include "tests/modules/dynamics/box2d/box2d_scene.h"

namespace swarmsim::box2d {
namespace {

using namespace box2d::scene_kit;  // NOLINT: the scene helpers

std::unique_ptr<DynamicsBackend> Build(const Scene& scene, const Options& options = {}) {
  auto backend = MakeBackend(options);
  backend->Build(scene, {});
  return backend;
}

TEST(Box2dBackend, DrivesStraightAtCommandedSpeed) {
  Scene scene;
  AddFloor(&scene);
  const double yaw0 = 0.3;
  Robot robot = AddRobot(&scene, "r", 0.2, -0.1, yaw0);
  auto backend = Build(scene);
  const double v = 0.05;
  SetWheelSpeeds(&scene, robot, v, v);
  const Vec3 p0 = Position(scene, robot.body);
  Simulate(backend.get(), &scene, 10.0);
  const Vec3 d = Position(scene, robot.body) - p0;
  const Vec3 heading{std::cos(yaw0), std::sin(yaw0), 0};
  const double along = d.Dot(heading);
  const double sideways = d.x * heading.y - d.y * heading.x;
  EXPECT_NEAR(along, v * 10.0, 0.02 * v * 10.0);
  EXPECT_NEAR(sideways, 0, 1e-3);
  EXPECT_NEAR(AngleDiff(Yaw(scene, robot.body), yaw0), 0, 1e-3);
  // Height and tilt are kept; velocities are written back.
  EXPECT_DOUBLE_EQ(Position(scene, robot.body).z, 0.05);
  EXPECT_NEAR(scene.linear_velocity_at(scene.SlotOf(robot.body)).Dot(heading), v, 1e-3);
}

TEST(Box2dBackend, KeepsHeightRollAndPitchOfBodies) {
  // A pushable box tilted a little, knocked into a spin by a robot.
  Scene scene;
  Robot robot = AddRobot(&scene, "r", 0, 0, 0);
  ShapeData crate;
  crate.kind = ShapeKind::kBox;
  crate.size = {0.1, 0.2, 0.1};
  crate.dynamic = true;
  crate.mass = 0.3;
  const ObjectId box = scene.AddShape(
      "crate", {}, {{0.3, 0.12, 0.07}, Quat::FromRollPitchYaw(0.1, -0.05, 0.4)}, crate);
  auto backend = Build(scene);
  SetWheelSpeeds(&scene, robot, 0.2, 0.2);
  Simulate(backend.get(), &scene, 2.0);
  const Pose X = scene.world_pose(box);
  const Vec3 rpy = X.q.RollPitchYaw();
  EXPECT_GT(X.p.x, 0.31);                            // pushed
  EXPECT_GT(std::abs(AngleDiff(rpy.z, 0.4)), 0.05);  // and turned
  EXPECT_DOUBLE_EQ(X.p.z, 0.07);
  EXPECT_NEAR(rpy.x, 0.1, 1e-9);
  EXPECT_NEAR(rpy.y, -0.05, 1e-9);
}

TEST(Box2dBackend, PositiveVelocityOnPlusYAxisDrivesForward) {
  // Only the left wheel (axis +y) turns, positively: the robot moves forward
  // (+x) while turning right (clockwise) about the stopped right wheel.
  Scene scene;
  Robot robot = AddRobot(&scene, "r", 0, 0, 0);
  auto backend = Build(scene);
  scene.mutable_joint(robot.left).target_velocity = 1.0;
  Simulate(backend.get(), &scene, 0.5);
  EXPECT_GT(Position(scene, robot.body).x, 0.005);
  EXPECT_LT(Yaw(scene, robot.body), -0.05);
}

TEST(Box2dBackend, SpinsInPlaceAtTwoVOverSeparation) {
  Scene scene;
  Robot robot = AddRobot(&scene, "r", 0.5, 0.5, 0);
  auto backend = Build(scene);
  const double v = 0.05;
  SetWheelSpeeds(&scene, robot, -v, v);  // left back, right forward: counter-clockwise
  Simulate(backend.get(), &scene, 0.5);  // spin up
  // Unwrapped yaw over 4 s.
  double yaw = Yaw(scene, robot.body), turned = 0;
  Simulate(backend.get(), &scene, 4.0, [&] {
    const double now = Yaw(scene, robot.body);
    turned += AngleDiff(now, yaw);
    yaw = now;
  });
  const double omega = 2 * v / (2 * robot.spec.half_axle);
  EXPECT_NEAR(turned / 4.0, omega, 0.02 * omega);
  const Vec3 p = Position(scene, robot.body);
  EXPECT_NEAR(p.x, 0.5, 1e-3);
  EXPECT_NEAR(p.y, 0.5, 1e-3);
}

ObjectId AddPassiveCylinder(Scene* scene, double x, double y, double mass, double friction) {
  ShapeData puck;
  puck.kind = ShapeKind::kCylinder;
  puck.size = {0.085, 0, 0.1};
  puck.dynamic = true;
  puck.mass = mass;
  puck.friction = friction;
  return scene->AddShape("puck", {}, {{x, y, 0.05}, {}}, puck);
}

TEST(Box2dBackend, RobotPushesALightPassiveObject) {
  Scene scene;
  AddFloor(&scene);
  Robot robot = AddRobot(&scene, "r", 0, 0, 0);
  ObjectId puck = AddPassiveCylinder(&scene, 0.4, 0, 0.5, 0.5);
  auto backend = Build(scene);
  Simulate(backend.get(), &scene, 1.0);
  EXPECT_NEAR(Position(scene, puck).x, 0.4, 1e-6);  // friction holds it at rest
  SetWheelSpeeds(&scene, robot, 0.05, 0.05);
  Simulate(backend.get(), &scene, 20.0);
  // Contact after ~4.6 s, then ~15 s of pushing at nearly full speed.
  // At the commanded speed, not one step's contact impulse behind it.
  EXPECT_NEAR(Position(scene, robot.body).x, 0.05 * 20.0, 0.02);
  EXPECT_GT(Position(scene, puck).x, 0.4 + 0.7);
  EXPECT_LT(Position(scene, robot.body).x, Position(scene, puck).x - 0.17 + 3e-3);
}

TEST(Box2dBackend, TractionIsLimitedByFriction) {
  // A 10 kg block (ground friction 0.7 * 98 N) out-weighs a 1.6 kg robot's
  // traction (0.7 * 16 N): the robot stalls, the block stays.
  Scene scene;
  AddFloor(&scene);
  Robot robot = AddRobot(&scene, "r", 0, 0, 0);
  ObjectId block = AddPassiveCylinder(&scene, 0.3, 0, 10.0, 0.7);
  auto backend = Build(scene);
  SetWheelSpeeds(&scene, robot, 0.2, 0.2);
  Simulate(backend.get(), &scene, 5.0);
  EXPECT_NEAR(Position(scene, block).x, 0.3, 1e-3);
  EXPECT_NEAR(Position(scene, robot.body).x, 0.3 - 0.17, 3e-3);

  // Two equal robots head-on: neither wins.
  Scene duel;
  Robot a = AddRobot(&duel, "a", 0, 0, 0);
  Robot b = AddRobot(&duel, "b", 0.5, 0, M_PI);
  auto backend2 = Build(duel);
  SetWheelSpeeds(&duel, a, 0.1, 0.1);
  SetWheelSpeeds(&duel, b, 0.1, 0.1);
  Simulate(backend2.get(), &duel, 6.0);
  EXPECT_NEAR(Position(duel, a.body).x, 0.25 - 0.085, 3e-3);
  EXPECT_NEAR(Position(duel, b.body).x, 0.25 + 0.085, 3e-3);
}

TEST(Box2dBackend, AbsurdWheelTargetsSaturateLikeLargeOnes) {
  // The traction impulse is clipped to the friction limit; with a target of
  // 1e200 m/s its square overflowed and the clip scaled it to zero: the
  // robot stood still without a word. It must drive as with any target far
  // above what the motor can reach.
  auto run = [](double speed) {
    Scene scene;
    AddFloor(&scene);
    Robot robot = AddRobot(&scene, "r", 0, 0, 0);
    auto backend = Build(scene);
    SetWheelSpeeds(&scene, robot, speed, speed);
    Simulate(backend.get(), &scene, 1.0);
    return Position(scene, robot.body).x;
  };
  const double large = run(1e3);
  EXPECT_GT(large, 0.1);
  EXPECT_EQ(run(1e200), large);
}

// Drives a robot at 0.1 m/s from (0.9 - offset, 0) with heading `yaw` into a
// wall whose face is at x = 1 (yaw 0 faces the wall). Returns the final
// position and the largest x seen.
struct SlideRun {
  Vec3 p;
  double max_x = -1;
};
SlideRun SlideAlongWall(double yaw, double wall_friction, double seconds) {
  Scene scene;
  AddFloor(&scene);
  ObjectId wall = AddWall(&scene, 1.05, 0, 0.1, 6);
  scene.mutable_shape(wall).friction = wall_friction;
  Robot robot = AddRobot(&scene, "r", 0.8, 0, yaw);
  auto backend = Build(scene);
  SetWheelSpeeds(&scene, robot, 0.1, 0.1);
  SlideRun out;
  Simulate(backend.get(), &scene, seconds,
           [&] { out.max_x = std::max(out.max_x, Position(scene, robot.body).x); });
  out.p = Position(scene, robot.body);
  return out;
}

TEST(Box2dBackend, SlidesAlongWallWhenDrivenDiagonally) {
  // A shallow approach (10 degrees to the wall) on a wall of ordinary
  // friction: the robot keeps sliding along it at about v sin(yaw).
  const double shallow = 80 * M_PI / 180;
  SlideRun run = SlideAlongWall(shallow, 0.7, 10.0);
  EXPECT_LT(run.max_x, 1.0 - 0.085 + 3e-3);
  EXPECT_NEAR(run.p.x, 1.0 - 0.085, 3e-3);
  EXPECT_NEAR(run.p.y, 0.1 * 10.0 * std::sin(shallow), 0.1);
  // At 45 degrees on a smooth wall it slides too (with ordinary wall
  // friction, the friction torque turns it to face the wall, where it stops).
  run = SlideAlongWall(M_PI / 4, 0.0, 10.0);
  EXPECT_LT(run.max_x, 1.0 - 0.085 + 3e-3);
  EXPECT_NEAR(run.p.x, 1.0 - 0.085, 3e-3);
  EXPECT_GT(run.p.y, 0.6);  // free driving: 0.71; sticking: ~0.12
}

// Robots far apart never touch, so each must move exactly as it would alone:
// the traction solve batches bodies (passes interleaved across them) and that
// must not mix one body's numbers into another's. The commands cover a free
// straight run, turning, spinning, an idle robot (that falls asleep), wheels
// slipping at their Coulomb limit and a motor at its force limit.
TEST(Box2dBackend, EachRobotMovesExactlyAsIfAlone) {
  struct Setup {
    double v_left, v_right;
    double wheel_friction = 0.7;
    double max_force = 10;
  };
  const std::vector<Setup> setups = {{0.05, 0.05},     {0.08, 0.02},     {-0.05, 0.05},
                                     {0, 0},           {0.6, 0.6, 0.02}, {0.3, 0.3, 0.7, 0.02},
                                     {0.1, 0.09, 0.05}};
  auto add = [](Scene* scene, size_t i, const Setup& setup) {
    std::string name = "r";  // (not "r" + ...: GCC 12 -Wrestrict false positive)
    name += std::to_string(i);
    Robot robot = AddRobot(scene, name, 10.0 * static_cast<double>(i), 0, 0.4 * i);
    for (ObjectId motor : {robot.left, robot.right}) {
      scene->mutable_joint(motor).settings.Edit().max_force = setup.max_force;
      scene->mutable_shape(scene->children(motor).front()).friction = setup.wheel_friction;
    }
    SetWheelSpeeds(scene, robot, setup.v_left, setup.v_right);
    return robot;
  };
  Scene together;
  std::vector<Robot> robots;
  for (size_t i = 0; i < setups.size(); ++i) robots.push_back(add(&together, i, setups[i]));
  auto backend = Build(together);
  Simulate(backend.get(), &together, 3.0);
  for (size_t i = 0; i < setups.size(); ++i) {
    Scene alone;
    Robot robot = add(&alone, i, setups[i]);
    auto alone_backend = Build(alone);
    Simulate(alone_backend.get(), &alone, 3.0);
    const Pose a = together.world_pose(robots[i].body), b = alone.world_pose(robot.body);
    EXPECT_EQ(std::memcmp(&a, &b, sizeof(Pose)), 0) << "robot " << i;
    const Vec3 va = together.linear_velocity_at(robots[i].body.index()),
               vb = alone.linear_velocity_at(robot.body.index());
    EXPECT_EQ(std::memcmp(&va, &vb, sizeof(Vec3)), 0) << "robot " << i;
  }
  // The slipping robot did slip (so the Coulomb clamp ran): well short of
  // 0.6 m/s x 3 s.
  EXPECT_LT(Position(together, robots[4].body).x - 40.0, 1.0);
}

// After each control step every object a robot carries (its proximity ring,
// its wheels) sits where composing its frames from the body's new pose puts
// it, bit for bit, and the body's local pose is the pose the backend wrote.
TEST(Box2dBackend, CarriedObjectsFollowTheBodyExactly) {
  Scene scene;
  AddFloor(&scene);
  Robot robot = AddRobot(&scene, "r", 0.2, -0.3, 0.5);
  std::vector<ObjectId> ring;
  for (int i = 0; i < 24; ++i) {
    const double a = i * M_PI / 12;
    const Quat q_BS = Quat::FromYaw(a) * Quat::FromAxisAngle({0, 1, 0}, M_PI / 2);
    ring.push_back(proximity::AddSensor(&scene, "prox", robot.body,
                                        {{0.085 * std::cos(a), 0.085 * std::sin(a), -0.013}, q_BS},
                                        {}));
  }
  auto backend = Build(scene);
  SetWheelSpeeds(&scene, robot, 0.08, 0.03);  // a curve
  auto same = [](const Pose& a, const Pose& b) { return std::memcmp(&a, &b, sizeof(Pose)) == 0; };
  const Pose X_WB0 = scene.world_pose(robot.body);
  int steps = 0;
  Simulate(backend.get(), &scene, 2.0, [&] {
    ++steps;
    // Joints advance as World::Actuate would; the next update moves the wheels.
    for (ObjectId motor : {robot.left, robot.right}) {
      JointData& j = scene.mutable_joint(motor);
      j.position += j.target_velocity * kDt * kSubsteps;
    }
    const Pose& X_WB = scene.world_pose(robot.body);
    EXPECT_TRUE(same(scene.local_pose(robot.body), X_WB));
    for (ObjectId sensor : ring)
      EXPECT_TRUE(same(scene.world_pose(sensor), X_WB * scene.local_pose(sensor)));
  });
  scene.UpdateWorldPoses();
  for (ObjectId motor : {robot.left, robot.right}) {
    const ObjectId wheel = scene.children(motor).front();
    const Pose X_WJ = scene.world_pose(robot.body) * scene.local_pose(motor);
    EXPECT_TRUE(same(scene.world_pose(motor), X_WJ));
    EXPECT_TRUE(same(scene.world_pose(wheel),
                     X_WJ * scene.joint(motor).Motion() * scene.local_pose(wheel)));
  }
  EXPECT_EQ(steps, 20);
  // It moved and turned (so the check above saw real motion).
  EXPECT_GT(std::hypot(Position(scene, robot.body).x - X_WB0.p.x,
                       Position(scene, robot.body).y - X_WB0.p.y),
            0.05);
  EXPECT_GT(std::abs(AngleDiff(Yaw(scene, robot.body), X_WB0.q.Yaw())), 0.3);
}

TEST(Box2dBackend, FollowsATeleportedBody) {
  Scene scene;
  Robot robot = AddRobot(&scene, "r", 0, 0, 0);
  auto backend = Build(scene);
  Simulate(backend.get(), &scene, 0.2);
  scene.SetWorldPose(robot.body, {{2, 3, 0.05}, Quat::FromYaw(1.0)});
  SetWheelSpeeds(&scene, robot, 0.05, 0.05);
  Simulate(backend.get(), &scene, 1.0);
  const Vec3 p = Position(scene, robot.body);
  EXPECT_NEAR(p.x, 2 + 0.05 * std::cos(1.0), 2e-3);
  EXPECT_NEAR(p.y, 3 + 0.05 * std::sin(1.0), 2e-3);
}

// A body teleported to a pose is written back exactly as a body built at
// that pose: nothing about its old rotation (which write-back keeps to skip
// the trigonometry while a body does not turn) survives the teleport. Tilted
// bodies, so that the kept roll and pitch matter too.
TEST(Box2dBackend, TeleportedBodyIsWrittenAsIfBuiltThere) {
  const Quat tilt = Quat::FromAxisAngle({1, 0.5, 0}, 0.05);
  for (const double yaw : {0.0, 0.7, M_PI, -2.0}) {
    Scene moved;
    Robot robot = AddRobot(&moved, "r", 0.3, 0.2, yaw);
    const Pose X_WB0 = moved.world_pose(robot.body);
    moved.SetWorldPose(robot.body, {X_WB0.p, X_WB0.q * tilt});
    auto backend = Build(moved);
    Simulate(backend.get(), &moved, 0.5);  // idle: not turning
    const Pose X_WB1 = moved.world_pose(robot.body);
    const Pose target{{X_WB1.p.x + 1, X_WB1.p.y - 0.5, X_WB1.p.z}, X_WB1.q};
    moved.SetWorldPose(robot.body, target);
    Simulate(backend.get(), &moved, 0.1);

    Scene fresh;
    Robot same = AddRobot(&fresh, "r", 0, 0, 0);
    fresh.SetWorldPose(same.body, target);
    auto fresh_backend = Build(fresh);
    Simulate(fresh_backend.get(), &fresh, 0.1);
    const Pose a = moved.world_pose(robot.body), b = fresh.world_pose(same.body);
    EXPECT_EQ(std::memcmp(&a, &b, sizeof(Pose)), 0) << "yaw " << yaw;
  }
}

}  // namespace
}  // namespace swarmsim::box2d
