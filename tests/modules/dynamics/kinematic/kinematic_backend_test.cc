// The kinematic backend (modules/dynamics/kinematic): joints move, nothing
// falls.

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

// A bar hanging from a scene-level joint (attached to the static world).
struct Arm {
  ObjectId joint, bar;
};
Arm AddArm(Scene* scene, JointData joint, const Pose& X_WJ, const Vec3& p_JB = {0.25, 0, 0}) {
  Arm a;
  a.joint = scene->AddJoint("joint", {}, X_WJ, joint);
  a.bar = scene->AddShape("bar", a.joint, {p_JB, {}}, Box({0.5, 0.04, 0.04}, true, 1.0));
  return a;
}

TEST(KinematicBackend, MovesJointsButNothingFalls) {
  Fixture f(0.1, 1, 9.81, "kinematic");
  JointData j = Joint(JointType::kRevolute, JointMode::kVelocity);
  j.target_velocity = 1;
  const Arm arm = AddArm(&f.scene(), j, {{0, 0, 1}, {}});
  for (int i = 0; i < 10; ++i) f.world->Step();
  EXPECT_NEAR(f.scene().joint(arm.joint).position, 1.0, 1e-12);
  EXPECT_NEAR(f.scene().world_pose(arm.bar).p.z, 1.0, 1e-12);
  EXPECT_NEAR(f.scene().world_pose(arm.bar).q.Yaw(), 1.0, 1e-12);
}

}  // namespace
}  // namespace swarmsim::ode
