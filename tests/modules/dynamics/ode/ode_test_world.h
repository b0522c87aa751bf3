// What the ODE backend's tests build on: a World with the built-in modules
// and the ODE backend (or another), shapes, joints and a hanging arm.
#pragma once

#include <memory>
#include <string>
#include <string_view>
#include <utility>

#include "framework/registry.h"
#include "framework/scene.h"
#include "framework/world.h"
#include "modules/builtin.h"

namespace swarmsim::ode::test {

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

inline ShapeData Sphere(double r, bool dynamic, double mass = 1) {
  ShapeData s;
  s.kind = ShapeKind::kSphere;
  s.size = {r, 0, 0};
  s.dynamic = dynamic;
  s.mass = mass;
  return s;
}

inline ShapeData Box(const Vec3& size, bool dynamic, double mass = 1) {
  ShapeData s;
  s.kind = ShapeKind::kBox;
  s.size = size;
  s.dynamic = dynamic;
  s.mass = mass;
  return s;
}

inline JointData Joint(JointType type, JointMode mode) {
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
inline Arm AddArm(Scene* scene, JointData joint, const Pose& X_WJ,
                  const Vec3& p_JB = {0.25, 0, 0}) {
  Arm a;
  a.joint = scene->AddJoint("joint", {}, X_WJ, joint);
  a.bar = scene->AddShape("bar", a.joint, {p_JB, {}}, Box({0.5, 0.04, 0.04}, true, 1.0));
  return a;
}

}  // namespace swarmsim::ode::test
