// modules/collision's geometry (geometry.cc): temporal coherence (a hint)
// never changes an answer.

#include "modules/collision/geometry.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "framework/scene.h"
#include "modules/collision/prisms.h"

namespace swarmsim::collision {
namespace {

Pose At(double x, double y, double z, double yaw_deg = 0) {
  return {{x, y, z}, Quat::FromAxisAngle({0, 0, 1}, yaw_deg * M_PI / 180)};
}

ShapeData Shape(ShapeKind kind, const Vec3& size) {
  ShapeData s;
  s.kind = kind;
  s.size = size;
  return s;
}

// Random robots (bodies, wheels on their side, a tilted box) among pillars:
// every distance with last step's pair as a hint equals the one without.
TEST(CollisionGeometryTest, CoherenceNeverChangesTheAnswer) {
  Scene scene;
  for (int i = 0; i < 9; ++i)
    scene.AddShape("pillar", {}, At(-3 + 3 * (i % 3), -3 + 3 * (i / 3), 0.15),
                   Shape(ShapeKind::kCylinder, {0.15, 0.15, 0.3}));
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(-4, 4), yaw(-180, 180);
  std::vector<ObjectId> roots;
  for (int i = 0; i < 60; ++i) {
    const ObjectId body = scene.AddShape("body", {}, At(u(rng), u(rng), 0.07, yaw(rng)),
                                         Shape(ShapeKind::kCylinder, {0.085, 0.085, 0.14}));
    scene.AddShape("wheel", body, {{0, 0.07, -0.04}, Quat::FromAxisAngle({1, 0, 0}, M_PI / 2)},
                   Shape(ShapeKind::kCylinder, {0.03, 0.03, 0.02}));
    scene.AddShape("flag", body, {{0, 0, 0.1}, Quat::FromAxisAngle({1, 1, 0}, 0.4)},
                   Shape(ShapeKind::kBox, {0.05, 0.02, 0.1}));
    scene.MakeModelInstance(body, "bot", "bot#" + std::to_string(i));
    roots.push_back(body);
  }
  scene.UpdateWorldPoses();
  Geometry geometry;
  std::vector<uint32_t> hint_a(roots.size(), kNoSlot), hint_b(roots.size(), kNoSlot);
  for (int step = 0; step < 20; ++step) {
    geometry.Refresh(scene);
    for (size_t i = 0; i < roots.size(); ++i) {
      std::vector<uint32_t> sub;
      scene.CollectSubtree(roots[i].index(), &sub);
      std::sort(sub.begin(), sub.end());
      const std::vector<uint32_t> a = geometry.ShapesOf(scene, sub);
      for (const EntitySpec::Kind kind : {EntitySpec::kEnvironment, EntitySpec::kEverythingElse}) {
        const double threshold = kind == EntitySpec::kEnvironment ? INFINITY : 1.5;
        const DistanceAnswer cold = geometry.Distance(a, {kind, {}}, threshold, kNoSlot, kNoSlot);
        const DistanceAnswer warm =
            geometry.Distance(a, {kind, {}}, threshold, hint_a[i], hint_b[i]);
        ASSERT_EQ(cold.found, warm.found) << "robot " << i << " step " << step;
        if (cold.found) {
          EXPECT_NEAR(cold.distance, warm.distance, 1e-9) << i << " " << step;
        }
        if (kind == EntitySpec::kEverythingElse) hint_a[i] = warm.s1, hint_b[i] = warm.s2;
      }
    }
    // Everyone drifts 3 cm and turns a little.
    for (size_t i = 0; i < roots.size(); ++i) {
      const Pose X = scene.world_pose(roots[i]);
      scene.SetWorldPose(
          roots[i], {X.p + X.q.Rotate({0.03, 0, 0}), X.q * Quat::FromAxisAngle({0, 0, 1}, 0.05)});
    }
    scene.UpdateWorldPoses();
  }
}

// A static shape (no robot, not dynamic) moved by a script, a path or a
// joint: distances to the environment and collisions with it are measured
// where it is now, each time it moves (the environment tree follows it).
TEST(CollisionGeometryTest, MeasuresAStaticShapeWhereItWasMoved) {
  Scene scene;
  const ObjectId pillar =
      scene.AddShape("pillar", {}, At(2, 0, 0.15), Shape(ShapeKind::kBox, {0.2, 0.2, 0.3}));
  const ObjectId body =
      scene.AddShape("body", {}, At(0, 0, 0.15), Shape(ShapeKind::kBox, {0.2, 0.2, 0.3}));
  scene.MakeModelInstance(body, "bot", "bot#0");
  scene.UpdateWorldPoses();
  Geometry geometry;
  geometry.Refresh(scene);
  const std::vector<uint32_t> a = {body.index()};
  const Target environment{EntitySpec::kEnvironment, {}};
  EXPECT_NEAR(geometry.Distance(a, environment, 10, kNoSlot, kNoSlot).distance, 1.8, 1e-9);
  for (double x : {1.0, 3.0, 0.5}) {
    scene.SetWorldPose(pillar, At(x, 0, 0.15));
    geometry.Refresh(scene);
    const DistanceAnswer d = geometry.Distance(a, environment, 10, kNoSlot, kNoSlot);
    EXPECT_NEAR(d.distance, x - 0.2, 1e-9) << x;
    EXPECT_EQ(d.s2, pillar.index());
    EXPECT_FALSE(geometry.Collide(a, environment, 0).colliding) << x;
  }
  scene.SetWorldPose(pillar, At(0.1, 0, 0.15));
  geometry.Refresh(scene);
  const CollisionAnswer hit = geometry.Collide(a, environment, 0);
  EXPECT_TRUE(hit.colliding);
  EXPECT_EQ(hit.s2, pillar.index());
}

}  // namespace
}  // namespace swarmsim::collision
