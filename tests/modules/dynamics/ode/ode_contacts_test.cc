// Contacts in ODE (ode_contacts.cc): a sphere landing on the ground, bouncing
// with its restitution, and carried by a kinematic platform.

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
  j.settings.Edit().type = type;
  j.settings.Edit().mode = mode;
  j.settings.Edit().max_force = 100;
  return j;
}

TEST(OdeBackend, DroppedSphereLandsAtFreeFallTime) {
  const double h = 1.0, r = 0.1, g = 9.81, dt = 0.005;
  Fixture f(dt, 1, g);
  const ObjectId ball = f.scene().AddShape("ball", {}, {{0, 0, r + h}, {}}, Sphere(r, true));
  f.world->Start();
  EXPECT_EQ(f.world->dynamics()->body_count(), 1);
  double landed = -1;
  for (int i = 0; i < 400 && landed < 0; ++i) {
    f.world->Step();
    if (f.scene().world_pose(ball).p.z <= r + 1e-9) landed = f.world->time();
  }
  EXPECT_NEAR(landed, std::sqrt(2 * h / g), dt);
  // And it rests on the ground instead of falling through.
  for (int i = 0; i < 200; ++i) f.world->Step();
  EXPECT_NEAR(f.scene().world_pose(ball).p.z, r, 2e-3);
}

TEST(OdeBackend, RestitutionBouncesToTheExpectedHeight) {
  const double h = 1.0, r = 0.05;
  Fixture f(0.002, 1);
  ShapeData shape = Sphere(r, true);
  shape.restitution = 0.8;
  const ObjectId ball = f.scene().AddShape("ball", {}, {{0, 0, r + h}, {}}, shape);
  double peak = 0;
  bool bounced = false;
  for (int i = 0; i < 1000; ++i) {
    f.world->Step();
    const double z = f.scene().world_pose(ball).p.z - r;
    if (!bounced && f.scene().linear_velocity_at(ball.index()).z > 0) bounced = true;
    if (bounced) peak = std::max(peak, z);
  }
  EXPECT_NEAR(peak, 0.64 * h, 0.06);  // e^2 h
}

TEST(OdeBackend, KinematicPlatformLiftsADynamicBall) {
  Fixture f(0.01, 2);
  JointData lift = Joint(JointType::kPrismatic, JointMode::kVelocity);
  lift.target_velocity = 0.2;
  const ObjectId j = f.scene().AddJoint("lift", {}, {{0, 0, 0.1}, {}}, lift);
  f.scene().AddShape("platform", j, {}, Box({1, 1, 0.05}, false));
  const ObjectId ball = f.scene().AddShape("ball", {}, {{0, 0, 0.2}, {}}, Sphere(0.075, true));
  f.world->Start();
  EXPECT_FALSE(f.scene().joint(j).simulated);     // no dynamic child: kinematic
  for (int i = 0; i < 100; ++i) f.world->Step();  // platform top rises 0.2 m to 0.325
  EXPECT_NEAR(f.scene().joint(j).position, 0.2, 1e-9);
  EXPECT_NEAR(f.scene().world_pose(ball).p.z, 0.325 + 0.2 + 0.075 - 0.2, 0.01);
}

}  // namespace
}  // namespace swarmsim::ode
