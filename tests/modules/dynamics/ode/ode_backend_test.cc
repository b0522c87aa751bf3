// The ODE backend as registered (modules/dynamics/ode/ode_backend.cc): its
// names, its bare loop; the rest of its behaviour is in the tests of
// ode_world, ode_contacts, ode_threading and ode_process.

#include "modules/dynamics/ode/ode_backend.h"

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
#include "tests/modules/dynamics/ode/ode_test_world.h"

namespace swarmsim::ode {
namespace {

using namespace test;  // ode_test_world.h

TEST(OdeBackend, RegistersAsOdeAndKinematic) {
  ModuleRegistry registry;
  RegisterBuiltinModules(&registry);
  EXPECT_TRUE(registry.HasDynamics("ode"));
  EXPECT_TRUE(registry.HasDynamics("kinematic"));
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

TEST(OdeBackend, BareLoopTimesStepping) {
  Scene scene;
  AddWheeledRobot(&scene, {}, 2);
  scene.UpdateWorldPoses();
  EXPECT_GT(TimeBareLoop(scene, 0.01, 2, 10), 0.0);
}

}  // namespace
}  // namespace swarmsim::ode
