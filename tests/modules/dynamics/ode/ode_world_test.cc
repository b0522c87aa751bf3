// The ODE world (ode_world.cc) through a World: joint modes and limits, a
// wheeled robot, the hybrid switch, scripts, teleports and bad shapes.

#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "framework/error.h"
#include "framework/registry.h"
#include "framework/scene.h"
#include "framework/world.h"
#include "modules/builtin.h"
#include "modules/dynamics/ode/ode_backend.h"
#include "tests/modules/dynamics/ode/ode_test_world.h"

namespace swarmsim::ode {
namespace {

using namespace test;  // ode_test_world.h

// The child's world pose equals the scene's forward kinematics of the joint.
void ExpectChildFollowsJoint(const Scene& scene, const Arm& arm, const Pose& X_JB0, double tol) {
  const Pose X_WB_fk = scene.world_pose(arm.joint) * scene.joint(arm.joint).Motion() * X_JB0;
  const Pose X_WB = scene.world_pose(arm.bar);
  EXPECT_NEAR((X_WB.p - X_WB_fk.p).Norm(), 0, tol);
  const double dot = X_WB.q.w * X_WB_fk.q.w + X_WB.q.x * X_WB_fk.q.x + X_WB.q.y * X_WB_fk.q.y +
                     X_WB.q.z * X_WB_fk.q.z;
  EXPECT_NEAR(std::abs(dot), 1, tol);
}

TEST(OdeBackend, VelocityMotorTurnsAtTargetSpeedWithV_RepSign) {
  Fixture f(0.01, 1, 0.0);
  JointData j = Joint(JointType::kRevolute, JointMode::kVelocity);
  j.target_velocity = 1.0;
  const Arm arm = AddArm(&f.scene(), j, {{0, 0, 1}, {}});
  f.world->Start();
  EXPECT_TRUE(f.scene().joint(arm.joint).simulated);
  for (int i = 0; i < 100; ++i) f.world->Step();
  EXPECT_NEAR(f.scene().joint(arm.joint).position, 1.0, 0.02);
  EXPECT_NEAR(f.scene().joint(arm.joint).velocity, 1.0, 1e-3);
  // Positive about +z: the bar's yaw is the joint position.
  EXPECT_NEAR(f.scene().world_pose(arm.bar).q.Yaw(), f.scene().joint(arm.joint).position, 1e-3);
  ExpectChildFollowsJoint(f.scene(), arm, {{0.25, 0, 0}, {}}, 1e-3);
}

TEST(OdeBackend, RevolutePositionIsUnwrappedPastPi) {
  Fixture f(0.01, 1, 0.0);
  JointData j = Joint(JointType::kRevolute, JointMode::kVelocity);
  j.target_velocity = 5.0;
  const Arm arm = AddArm(&f.scene(), j, {{0, 0, 1}, {}});
  for (int i = 0; i < 200; ++i) f.world->Step();  // 10 rad
  EXPECT_NEAR(f.scene().joint(arm.joint).position, 10.0, 0.1);
}

TEST(OdeBackend, PositionServoHoldsAPendulumAtItsTargetWithinMaxVelocity) {
  Fixture f(0.01, 5);
  JointData j = Joint(JointType::kRevolute, JointMode::kPosition);
  j.target_position = 0.5;
  j.settings.Edit().max_velocity = 1.0;
  // Axis horizontal (joint z along world y): gravity pulls the bar down.
  const Arm arm = AddArm(&f.scene(), j, {{0, 0, 1}, Quat::FromAxisAngle({1, 0, 0}, M_PI / 2)});
  for (int i = 0; i < 20; ++i) f.world->Step();  // 0.2 s at <= 1 rad/s
  EXPECT_LE(std::abs(f.scene().joint(arm.joint).position), 0.2 + 0.02);
  EXPECT_GT(f.scene().joint(arm.joint).position, 0.15);
  for (int i = 0; i < 180; ++i) f.world->Step();
  EXPECT_NEAR(f.scene().joint(arm.joint).position, 0.5, 2e-3);
  ExpectChildFollowsJoint(f.scene(), arm, {{0.25, 0, 0}, {}}, 2e-3);
}

TEST(OdeBackend, WeakServoCannotLiftTheLoad) {
  Fixture f(0.01, 5);
  JointData j = Joint(JointType::kRevolute, JointMode::kPosition);
  j.target_position = 0.5;
  j.settings.Edit().max_force = 0.1;  // N m, the bar needs m g l = 1.2 N m
  const Arm arm = AddArm(&f.scene(), j, {{0, 0, 1}, Quat::FromAxisAngle({1, 0, 0}, M_PI / 2)});
  for (int i = 0; i < 100; ++i) f.world->Step();
  EXPECT_LT(f.scene().joint(arm.joint).position, 0.0);  // sags the other way
}

TEST(OdeBackend, ForceModeGivesTheExpectedAngularAcceleration) {
  Fixture f(0.001, 1, 0.0);
  JointData j = Joint(JointType::kRevolute, JointMode::kForce);
  j.target_force = 0.1;  // N m
  const Arm arm = AddArm(&f.scene(), j, {{0, 0, 1}, {}});
  for (int i = 0; i < 500; ++i) f.world->Step();
  // Bar of 1 kg, 0.5 m long, centre 0.25 m from the axis: I = m (l^2 + w^2)/12 + m d^2.
  const double inertia = (0.25 + 0.0016) / 12 + 0.0625;
  const double t = 0.5;
  EXPECT_NEAR(f.scene().joint(arm.joint).position, 0.5 * 0.1 / inertia * t * t, 0.01);
}

TEST(OdeBackend, PassiveJointStopsAtItsLimits) {
  Fixture f(0.01, 5);
  JointData j = Joint(JointType::kRevolute, JointMode::kPassive);
  j.settings.Edit().min_position = -0.3;
  j.settings.Edit().max_position = 0.3;
  const Arm arm = AddArm(&f.scene(), j, {{0, 0, 1}, Quat::FromAxisAngle({1, 0, 0}, M_PI / 2)});
  for (int i = 0; i < 200; ++i) f.world->Step();
  EXPECT_NEAR(f.scene().joint(arm.joint).position, -0.3, 0.02);
}

// Limits farther than pi from where the joint starts (a Panda's joint6 up
// to 3.75 rad, a Jaco's joint2 from 0.82 to 5.46): ODE measures a hinge's
// angle in (-pi, pi] and ignores stops outside it, so the joint ran past
// them (a Jaco's joint2 reached 8.36 rad). Driven both ways, in velocity
// and position mode, it now stops at each.
TEST(OdeBackend, LimitsFartherThanPiFromTheStartStillStopTheJoint) {
  for (const JointMode mode : {JointMode::kVelocity, JointMode::kPosition}) {
    SCOPED_TRACE(mode == JointMode::kVelocity ? "velocity" : "position");
    Fixture f(0.01, 5, 0.0);
    JointData j = Joint(JointType::kRevolute, mode);
    j.settings.Edit().min_position = -3.9;
    j.settings.Edit().max_position = 4.0;
    j.settings.Edit().max_velocity = 2.0;
    const Arm arm = AddArm(&f.scene(), j, {{0, 0, 1}, {}});
    const auto drive = [&](double sign) {
      JointData& row = f.scene().mutable_joint(arm.joint);
      row.target_velocity = 2.0 * sign;
      row.target_position = 10.0 * sign;
    };
    drive(1);
    for (int i = 0; i < 400; ++i) f.world->Step();  // 8 rad at 2 rad/s
    EXPECT_NEAR(f.scene().joint(arm.joint).position, 4.0, 0.02);
    EXPECT_NEAR(f.scene().world_pose(arm.bar).q.Yaw(), 4.0 - 2 * M_PI, 0.02);
    drive(-1);
    for (int i = 0; i < 600; ++i) f.world->Step();  // 12 rad back
    EXPECT_NEAR(f.scene().joint(arm.joint).position, -3.9, 0.02);
    ExpectChildFollowsJoint(f.scene(), arm, {{0.25, 0, 0}, {}}, 2e-3);
  }
}

TEST(OdeBackend, PrismaticMotorSlidesAlongTheJointAxis) {
  Fixture f(0.01, 1, 0.0);
  JointData j = Joint(JointType::kPrismatic, JointMode::kVelocity);
  j.target_velocity = 0.1;
  // Joint z along world x.
  const Arm arm =
      AddArm(&f.scene(), j, {{0, 0, 1}, Quat::FromAxisAngle({0, 1, 0}, M_PI / 2)}, {0, 0, 0});
  const Vec3 start = f.scene().world_pose(arm.bar).p;
  for (int i = 0; i < 100; ++i) f.world->Step();
  EXPECT_NEAR(f.scene().joint(arm.joint).position, 0.1, 2e-3);
  const Vec3 moved = f.scene().world_pose(arm.bar).p - start;
  EXPECT_NEAR(moved.x, 0.1, 2e-3);
  EXPECT_NEAR(moved.y, 0, 1e-6);
  ExpectChildFollowsJoint(f.scene(), arm, {}, 1e-3);
}

TEST(OdeBackend, SphericalJointSwingsAndReportsItsRotation) {
  Fixture f(0.005, 2);
  const Arm arm = AddArm(&f.scene(), Joint(JointType::kSpherical, JointMode::kPassive),
                         {{0, 0, 1}, {}}, {0.25, 0, 0});
  for (int i = 0; i < 40; ++i) f.world->Step();
  // Falling from horizontal, it swung down.
  EXPECT_LT(f.scene().world_pose(arm.bar).p.z, 0.9);
  EXPECT_NEAR((f.scene().world_pose(arm.bar).p - Vec3{0, 0, 1}).Norm(), 0.25, 2e-3);
  ExpectChildFollowsJoint(f.scene(), arm, {{0.25, 0, 0}, {}}, 2e-3);
}

TEST(OdeBackend, FixedJointKeepsTwoFallingBodiesTogether) {
  Fixture f(0.005, 2);
  const ObjectId a = f.scene().AddShape("a", {}, {{0, 0, 1}, {}}, Box({0.2, 0.2, 0.2}, true));
  const ObjectId j = f.scene().AddJoint("weld", a, {{0.1, 0, 0}, {}},
                                        Joint(JointType::kFixed, JointMode::kPassive));
  const ObjectId b = f.scene().AddShape("b", j, {{0.1, 0, 0}, {}}, Box({0.2, 0.2, 0.2}, true));
  for (int i = 0; i < 40; ++i) f.world->Step();
  const Pose X_AB = f.scene().world_pose(a).Inverse() * f.scene().world_pose(b);
  EXPECT_NEAR((X_AB.p - Vec3{0.2, 0, 0}).Norm(), 0, 2e-3);
  EXPECT_LT(f.scene().world_pose(a).p.z, 0.9);
}

// A 3D differential-drive robot: a box chassis on two dynamic wheels and a
// frictionless ball caster that is part of the chassis.
struct Wheeled {
  ObjectId chassis, left, right;
};
Wheeled AddWheeledRobot(Scene* scene, const Vec3& at, double omega) {
  Wheeled r;
  const double R = 0.05;
  r.chassis =
      scene->AddShape("chassis", {}, {at + Vec3{0, 0, R}, {}}, Box({0.3, 0.2, 0.05}, true, 2));
  ShapeData caster = Sphere(0.025, false);
  caster.friction = 0;
  scene->AddShape("caster", r.chassis, {{-0.12, 0, -0.025}, {}}, caster);
  ShapeData wheel;
  wheel.kind = ShapeKind::kCylinder;
  wheel.size = {R, 0, 0.02};
  wheel.dynamic = true;
  wheel.mass = 0.2;
  wheel.friction = 1.0;
  for (int side : {1, -1}) {
    JointData m = Joint(JointType::kRevolute, JointMode::kVelocity);
    m.target_velocity = side * omega;  // mirror-mounted: the right wheel turns the other way
    m.settings.Edit().max_force = 5;
    // Joint z along +y (left) or -y (right): Rx(-90 deg) turns z onto +y.
    const Quat q = Quat::FromAxisAngle({1, 0, 0}, -side * M_PI / 2);
    const ObjectId motor =
        scene->AddJoint(side > 0 ? "left" : "right", r.chassis, {{0.05, side * 0.13, 0}, q}, m);
    scene->AddShape("wheel", motor, {}, wheel);
    (side > 0 ? r.left : r.right) = motor;
  }
  return r;
}

TEST(OdeBackend, WheeledRobotDrivesStraightAtOmegaTimesRadius) {
  Fixture f(0.01, 4);
  const double omega = 4;  // rad/s, 0.2 m/s with R = 5 cm
  const Wheeled r = AddWheeledRobot(&f.scene(), {0, 0, 0}, omega);
  f.world->Start();
  EXPECT_EQ(f.world->dynamics()->body_count(), 3);
  for (int i = 0; i < 50; ++i) f.world->Step();  // settle and accelerate
  const Pose start = f.scene().world_pose(r.chassis);
  for (int i = 0; i < 200; ++i) f.world->Step();  // 2 s
  const Pose end = f.scene().world_pose(r.chassis);
  EXPECT_NEAR(end.p.x - start.p.x, omega * 0.05 * 2, 0.02);
  EXPECT_NEAR(end.p.y, 0, 0.005);
  EXPECT_NEAR(end.q.Yaw(), 0, 0.01);
  EXPECT_NEAR(f.scene().joint(r.left).velocity, omega, 0.05);
}

TEST(OdeBackend, HybridSwitchMakesAKinematicBoxFallAndStopsItAgain) {
  Fixture f(0.01, 2);
  const ObjectId crate =
      f.scene().AddShape("crate", {}, {{0, 0, 1}, {}}, Box({0.1, 0.1, 0.1}, false));
  for (int i = 0; i < 20; ++i) f.world->Step();
  EXPECT_DOUBLE_EQ(f.scene().world_pose(crate).p.z, 1.0);  // static: held in the air
  f.scene().SetShapeDynamic(crate, true);
  for (int i = 0; i < 20; ++i) f.world->Step();  // 0.2 s: falls ~0.2 m
  const double z = f.scene().world_pose(crate).p.z;
  EXPECT_NEAR(z, 1 - 0.5 * 9.81 * 0.2 * 0.2, 0.02);
  f.scene().SetShapeDynamic(crate, false);
  for (int i = 0; i < 20; ++i) f.world->Step();
  EXPECT_DOUBLE_EQ(f.scene().world_pose(crate).p.z, z);  // frozen where it was
  f.scene().SetShapeDynamic(crate, true);
  for (int i = 0; i < 200; ++i) f.world->Step();
  EXPECT_NEAR(f.scene().world_pose(crate).p.z, 0.05, 2e-3);  // on the ground
}

TEST(OdeBackend, ScriptReleasesARobotsBoxWithSetObjectDynamic) {
  // A gripper-like robot holds a kinematic box; its script releases it at
  // t = 0.2 s, after which it falls to the ground.
  Fixture f(0.01, 2);
  const ObjectId base =
      f.scene().AddShape("base", {}, {{0, 0, 0.05}, {}}, Box({0.1, 0.1, 0.1}, false));
  const ObjectId crate =
      f.scene().AddShape("crate", {}, {{1, 0, 0.5}, {}}, Box({0.1, 0.1, 0.1}, false));
  f.scene().MakeModelInstance(base, "robot", "robot#0");
  const std::string code = R"(
    function sysCall_init() crate = sim.getObject('/crate') end
    function sysCall_actuation()
      if sim.getSimulationTime() >= 0.2 and not sim.isObjectDynamic(crate) then
        sim.setObjectDynamic(crate, true)
      end
    end)";
  f.scene().AttachScript(base,
                         std::make_shared<const ScriptSource>(ScriptSource{"release.lua", code}));
  for (int i = 0; i < 20; ++i) f.world->Step();
  EXPECT_DOUBLE_EQ(f.scene().world_pose(crate).p.z, 0.5);
  for (int i = 0; i < 100; ++i) f.world->Step();
  EXPECT_TRUE(f.scene().shape(crate).dynamic);
  EXPECT_NEAR(f.scene().world_pose(crate).p.z, 0.05, 2e-3);
}

TEST(OdeBackend, FollowsATeleportedBody) {
  Fixture f(0.01, 1);
  const ObjectId ball = f.scene().AddShape("ball", {}, {{0, 0, 0.1}, {}}, Sphere(0.1, true));
  for (int i = 0; i < 5; ++i) f.world->Step();
  f.scene().SetLocalPose(ball, {{3, 0, 0.1}, {}});
  f.world->Step();
  EXPECT_NEAR(f.scene().world_pose(ball).p.x, 3, 1e-6);
}

TEST(OdeBackend, BadDynamicShapeIsAClearError) {
  Fixture f;
  f.scene().AddShape("ghost", {}, {{0, 0, 1}, {}}, Sphere(0.1, true, 0.0));
  try {
    f.world->Start();
    FAIL() << "expected an error";
  } catch (const std::exception& e) {
    EXPECT_NE(std::string(e.what()).find("/ghost"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("mass"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace swarmsim::ode
