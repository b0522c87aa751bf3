// ODE's solver on threads (ode_threading.cc): exploding islands on solver
// threads are an error, and results are bit-identical at any thread count.

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

// Absurd torques blow eight arms (eight islands, solved on both threads) up:
// whatever ODE does with the infinities, on whichever thread, the step ends
// with an error naming physics or ODE, never an abort.
TEST(OdeBackend, ExplodingIslandsOnSolverThreadsAreAnErrorNotAnAbort) {
  Fixture f(0.01, 2, 9.81, "ode", 2);
  JointData j = Joint(JointType::kRevolute, JointMode::kForce);
  j.target_force = 1e300;  // N m
  for (int i = 0; i < 8; ++i) AddArm(&f.scene(), j, {{2.0 * i, 0, 1}, {}});
  std::string message;
  for (int i = 0; i < 100 && message.empty(); ++i) {
    try {
      f.world->Step();
    } catch (const Error& e) {
      message = e.what();
    }
  }
  ASSERT_FALSE(message.empty()) << "the arms never broke the physics";
  EXPECT_TRUE(message.find("non-finite") != std::string::npos ||
              message.find("ode:") != std::string::npos)
      << message;
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

uint64_t RunWheeledSwarm(int threads) {
  Fixture f(0.01, 4, 9.81, "ode", threads);
  for (int i = 0; i < 8; ++i) {
    const Wheeled r = AddWheeledRobot(&f.scene(), {0.0, 0.5 * i, 0}, 2.0 + 0.5 * i);
    f.scene().MakeModelInstance(r.chassis, "wheeled", "wheeled#" + std::to_string(i));
    f.scene().AddShape("ball", {}, {{0.4, 0.5 * i, 0.3}, {}}, Sphere(0.05, true, 0.3));
  }
  for (int i = 0; i < 100; ++i) f.world->Step();
  return f.world->StateHash();
}

TEST(OdeBackend, StateHashIsEqualAtOneAndTwoThreads) {
  const uint64_t one = RunWheeledSwarm(1);
  EXPECT_EQ(RunWheeledSwarm(1), one);
  EXPECT_EQ(RunWheeledSwarm(2), one);
}

// Four towers of eight boxes with spheres dropped on them: each tower is one
// island of eight bodies and a few dozen contacts, solved by the threaded
// solver's multi-threaded path; loose spheres are islands of their own.
struct Towers {
  std::vector<Pose> poses;  // every box and sphere, after the run
  uint64_t hash = 0;
};
Towers RunTowers(int threads) {
  Fixture f(0.01, 2, 9.81, "ode", threads);
  std::vector<ObjectId> bodies;
  for (int t = 0; t < 4; ++t)
    for (int level = 0; level < 8; ++level)
      bodies.push_back(f.scene().AddShape("box", {}, {{1.0 * t, 0, 0.05 + 0.1 * level}, {}},
                                          Box({0.1, 0.1, 0.1}, true, 0.5)));
  for (int s = 0; s < 12; ++s)
    bodies.push_back(f.scene().AddShape(
        "ball", {}, {{0.02 + 0.25 * s, 0.03 * (s % 3), 1.2 + 0.05 * s}, {}}, Sphere(0.04, true)));
  for (int i = 0; i < 300; ++i) f.world->Step();  // 3 s: the spheres land and the towers settle
  Towers out;
  for (ObjectId id : bodies) out.poses.push_back(f.scene().world_pose(id));
  out.hash = f.world->StateHash();
  return out;
}

TEST(OdeBackend, TowersOfBoxesStandAndAreBitIdenticalAtOneToFourThreads) {
  const Towers one = RunTowers(1);
  for (int t = 0; t < 4; ++t) {  // each tower still stands, its top box where it began
    const Pose& top = one.poses[static_cast<size_t>(t * 8 + 7)];
    EXPECT_NEAR(top.p.x, 1.0 * t, 0.02) << "tower " << t;
    EXPECT_NEAR(top.p.z, 0.75, 0.01) << "tower " << t;
  }
  for (int threads : {2, 3, 4}) {
    const Towers other = RunTowers(threads);
    EXPECT_EQ(other.hash, one.hash) << threads << " threads";
    for (size_t i = 0; i < one.poses.size(); ++i) {
      ASSERT_EQ(other.poses[i].p.x, one.poses[i].p.x) << "body " << i << ", " << threads;
      ASSERT_EQ(other.poses[i].p.z, one.poses[i].p.z) << "body " << i << ", " << threads;
      ASSERT_EQ(other.poses[i].q.w, one.poses[i].q.w) << "body " << i << ", " << threads;
    }
  }
}

}  // namespace
}  // namespace swarmsim::ode
