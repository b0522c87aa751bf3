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

namespace swarmsim::ode {
namespace {

struct Fixture {
  ModuleRegistry registry;
  std::unique_ptr<World> world;
  explicit Fixture(double time_step = 0.01, int substeps = 1, double gravity = 9.81,
                   std::string physics = "ode", int threads = 1) {
    RegisterBuiltinModules(&registry);
    WorldSettings s;
    s.physics = std::move(physics);
    s.time_step = time_step;
    s.physics_substeps = substeps;
    s.gravity = gravity;
    s.threads = threads;
    world = std::make_unique<World>(s, registry);
    world->set_log_sink([](std::string_view) {});
  }
  Scene& scene() { return world->scene(); }
};

ShapeData Sphere(double r, bool dynamic, double mass = 1) {
  ShapeData s;
  s.kind = ShapeKind::kSphere;
  s.size = {r, 0, 0};
  s.dynamic = dynamic;
  s.mass = mass;
  return s;
}

ShapeData Box(const Vec3& size, bool dynamic, double mass = 1) {
  ShapeData s;
  s.kind = ShapeKind::kBox;
  s.size = size;
  s.dynamic = dynamic;
  s.mass = mass;
  return s;
}

JointData Joint(JointType type, JointMode mode) {
  JointData j;
  j.type = type;
  j.mode = mode;
  j.max_force = 100;
  return j;
}

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
    m.max_force = 5;
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
