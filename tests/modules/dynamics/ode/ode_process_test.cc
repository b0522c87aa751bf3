// ODE for the whole process (ode_process.cc): its error handlers turn an
// internal assertion of ODE into an error instead of an abort.

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

// An internal assertion of ODE (here: a body teleported to a zero
// quaternion, which ODE cannot normalize) ends the step with an error
// instead of aborting the process.
TEST(OdeBackend, InternalAssertionIsAnErrorNotAnAbort) {
  Fixture f;
  const ObjectId ball = f.scene().AddShape("ball", {}, {{0, 0, 1}, {}}, Sphere(0.1, true));
  f.scene().AddShape("floor", {}, {{0, 0, -0.5}, {}}, Box({4, 4, 1}, false));
  f.world->Step();
  f.scene().SetWorldPose(ball, {{0, 0, 1}, {0, 0, 0, 0}});
  try {
    f.world->Step();
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("ode: internal error"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace swarmsim::ode
