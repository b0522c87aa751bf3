// Moving surfaces in the Box2D plane (plane_belts.cc), driven directly (no
// World): a crate lying on a belt is carried at the belt's surface speed
// along the belt's heading, stops on the ground once its centre leaves the
// belt, and a crate beside the belt or above its top stays where it is.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>

#include "framework/dynamics_backend.h"
#include "framework/scene.h"
#include "modules/dynamics/box2d/box2d_backend.h"
#include "tests/modules/dynamics/box2d/box2d_scene.h"

namespace swarmsim::box2d {
namespace {

using namespace box2d::scene_kit;  // NOLINT: the scene helpers

// A belt 1 m long (along its x) and 0.4 m wide, its top 0.1 m up, centred
// at (x, y) heading `yaw`, its surface sliding at `speed` along its x.
ObjectId AddBelt(Scene* scene, double x, double y, double yaw, double speed) {
  ShapeData belt;
  belt.kind = ShapeKind::kBox;
  belt.size = {1, 0.4, 0.05};
  const ObjectId id = scene->AddShape("belt", {}, {{x, y, 0.075}, Quat::FromYaw(yaw)}, belt);
  scene->SetSurfaceVelocity(id, {speed, 0, 0}, {});
  return id;
}

// A 0.1 m crate of 1 kg whose bottom is at `bottom`.
ObjectId AddCrate(Scene* scene, double x, double y, double bottom) {
  ShapeData crate;
  crate.kind = ShapeKind::kBox;
  crate.size = {0.1, 0.1, 0.1};
  crate.dynamic = true;
  crate.mass = 1;
  return scene->AddShape("crate", {}, {{x, y, bottom + 0.05}, {}}, crate);
}

std::unique_ptr<DynamicsBackend> Build(const Scene& scene) {
  auto backend = MakeBackend();
  backend->Build(scene, {});
  return backend;
}

TEST(PlaneBeltsTest, ACrateOnABeltRidesAtItsSpeed) {
  Scene scene;
  AddBelt(&scene, 0, 0, 0, 0.2);
  const ObjectId crate = AddCrate(&scene, -0.3, 0, 0.1);
  scene.UpdateWorldPoses();
  auto backend = Build(scene);
  Simulate(backend.get(), &scene, 2.0);
  // 0.4 m in 2 s, less the few millimetres of getting up to speed.
  EXPECT_NEAR(Position(scene, crate).x, -0.3 + 0.4, 0.01);
  EXPECT_NEAR(Position(scene, crate).y, 0, 1e-6);
  EXPECT_NEAR(scene.linear_velocity_at(scene.SlotOf(crate)).x, 0.2, 1e-3);
}

TEST(PlaneBeltsTest, ABeltCarriesAlongItsHeading) {
  Scene scene;
  AddBelt(&scene, 2, 0, M_PI / 2, 0.25);  // its x along the world's +y
  const ObjectId crate = AddCrate(&scene, 2, -0.3, 0.1);
  scene.UpdateWorldPoses();
  auto backend = Build(scene);
  Simulate(backend.get(), &scene, 2.0);
  EXPECT_NEAR(Position(scene, crate).x, 2, 1e-6);
  EXPECT_NEAR(Position(scene, crate).y, -0.3 + 0.5, 0.01);
}

// Past the belt's end its centre is over the ground, whose friction stops it.
TEST(PlaneBeltsTest, ACrateStopsOnceItLeavesTheBelt) {
  Scene scene;
  AddBelt(&scene, 0, 0, 0, 0.2);
  const ObjectId crate = AddCrate(&scene, 0.3, 0, 0.1);
  scene.UpdateWorldPoses();
  auto backend = Build(scene);
  Simulate(backend.get(), &scene, 3.0);
  const double x = Position(scene, crate).x;
  EXPECT_GE(x, 0.5);
  EXPECT_LT(x, 0.53);
  EXPECT_NEAR(scene.linear_velocity_at(scene.SlotOf(crate)).x, 0, 1e-6);
}

// (Each alone: the belt is an obstacle only to bodies whose heights it
// reaches into, plane_world_build.cc.)
TEST(PlaneBeltsTest, CratesBesideOrAboveTheBeltStayPut) {
  for (const bool above : {false, true}) {
    Scene scene;
    AddBelt(&scene, 0, 0, 0, 0.2);
    // On the ground next to it, or 10 cm above its top.
    const ObjectId crate = above ? AddCrate(&scene, 0, 0.1, 0.2) : AddCrate(&scene, 0, 0.6, 0);
    scene.UpdateWorldPoses();
    auto backend = Build(scene);
    Simulate(backend.get(), &scene, 1.0);
    EXPECT_NEAR(Position(scene, crate).x, 0, 1e-9) << (above ? "above" : "beside");
    EXPECT_NEAR(Position(scene, crate).y, above ? 0.1 : 0.6, 1e-9);
  }
}

}  // namespace
}  // namespace swarmsim::box2d
