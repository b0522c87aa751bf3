// modules/proximity/ray_cast.cc: the exact ray tests, on primitives in
// their own frame and on shapes placed at a world pose, and the bounds and
// footprints the module's indexes are built from.
#include "modules/proximity/ray_cast.h"

#include <gtest/gtest.h>

#include <cmath>

#include "framework/scene.h"

namespace swarmsim::proximity {
namespace {

ShapeData Box(double x, double y, double z) {
  ShapeData s;
  s.kind = ShapeKind::kBox;
  s.size = {x, y, z};
  return s;
}
ShapeData Cylinder(double radius, double height) {
  ShapeData s;
  s.kind = ShapeKind::kCylinder;
  s.size = {radius, 0, height};
  return s;
}
ShapeData Sphere(double radius) {
  ShapeData s;
  s.kind = ShapeKind::kSphere;
  s.size = {radius, 0, 0};
  return s;
}

// --- The primitives on their own -------------------------------------------------------

TEST(RayPrimitivesTest, InsideStartsHitAtZero) {
  double t = -1;
  EXPECT_TRUE(RayBox({0, 0, 0}, {1, 0, 0}, {1, 1, 1}, 5, &t));
  EXPECT_EQ(t, 0);
  EXPECT_TRUE(RayCylinder({0.1, 0, 0.2}, {0, 0, 1}, 0.5, 0.5, 5, &t));
  EXPECT_EQ(t, 0);
  EXPECT_TRUE(RaySphere({0, 0.2, 0}, {0, 1, 0}, 0.5, 5, &t));
  EXPECT_EQ(t, 0);
}

TEST(RayPrimitivesTest, BehindAndParallelRaysMiss) {
  double t;
  EXPECT_FALSE(RayBox({2, 0, 0}, {1, 0, 0}, {1, 1, 1}, 5, &t));         // pointing away
  EXPECT_FALSE(RayBox({-2, 1.5, 0}, {1, 0, 0}, {1, 1, 1}, 5, &t));      // parallel, outside
  EXPECT_FALSE(RayCylinder({-2, 0, 0.6}, {1, 0, 0}, 0.5, 0.5, 5, &t));  // above the top cap
  EXPECT_FALSE(RayCylinder({0.6, 0, -3}, {0, 0, 1}, 0.5, 0.5, 5, &t));  // along the axis, outside
  EXPECT_FALSE(RaySphere({-2, 0.51, 0}, {1, 0, 0}, 0.5, 5, &t));
}

TEST(RayPrimitivesTest, CapsSidesAndTangents) {
  double t;
  ASSERT_TRUE(RayCylinder({0.2, 0.1, -3}, {0, 0, 1}, 0.5, 0.5, 5, &t));  // bottom cap
  EXPECT_NEAR(t, 2.5, 1e-15);
  const Vec3 diagonal = Vec3{1, 0, 1}.Normalized();  // enters through the side
  ASSERT_TRUE(RayCylinder({-1.5, 0, -1.0}, diagonal, 0.5, 0.5, 5, &t));
  EXPECT_NEAR(t, std::sqrt(2.0), 1e-12);
  ASSERT_TRUE(RaySphere({-2, 0.5, 0}, {1, 0, 0}, 0.5, 5, &t));  // tangent: touching counts
  EXPECT_NEAR(t, 2, 1e-12);
}

// --- Shapes placed in the world -----------------------------------------------------------

// A box 0.2 m thick along its x, turned 90 degrees about z at (2, 0, 0.5):
// its 1 m side now runs along the world's x, its thickness along y.
TEST(RayCastTest, TurnedBoxIsHitAtItsWorldFace) {
  const PlacedShape box =
      PlaceShape(Box(0.2, 1, 1), {{2, 0, 0.5}, Quat::FromYaw(M_PI / 2)}, ObjectId{}, -1);
  double t = 0;
  ASSERT_TRUE(RayCast(box, {0, 0, 0.5}, {1, 0, 0}, 10, &t));
  EXPECT_NEAR(t, 1.5, 1e-12);
  // Beside its thickness, or too short to reach it: nothing.
  EXPECT_FALSE(RayCast(box, {0, 0.15, 0.5}, {1, 0, 0}, 10, &t));
  EXPECT_FALSE(RayCast(box, {0, 0, 0.5}, {1, 0, 0}, 1.4, &t));
  // From the other side, along -x.
  ASSERT_TRUE(RayCast(box, {4, 0.05, 0.5}, {-1, 0, 0}, 10, &t));
  EXPECT_NEAR(t, 1.5, 1e-12);
}

TEST(RayCastTest, SphereAndUprightCylinderAtTheirPoses) {
  double t = 0;
  const PlacedShape sphere = PlaceShape(Sphere(0.5), {{0, 3, 0}, {}}, ObjectId{}, -1);
  ASSERT_TRUE(RayCast(sphere, {0, 0, 0}, {0, 1, 0}, 10, &t));
  EXPECT_NEAR(t, 2.5, 1e-12);
  const PlacedShape cylinder = PlaceShape(Cylinder(0.25, 1), {{-2, 0, 0}, {}}, ObjectId{}, -1);
  ASSERT_TRUE(RayCast(cylinder, {0, 0, 0}, {-1, 0, 0}, 10, &t));
  EXPECT_NEAR(t, 1.75, 1e-12);
  // Above its top (z = 0.5) the ray passes.
  EXPECT_FALSE(RayCast(cylinder, {0, 0, 0.6}, {-1, 0, 0}, 10, &t));
}

TEST(RayCastTest, PlacedShapeKeepsItsIdAndRobot) {
  const ObjectId id{7, 1};
  const PlacedShape shape = PlaceShape(Sphere(0.1), {}, id, 3);
  EXPECT_EQ(shape.id, id);
  EXPECT_EQ(shape.instance, 3);
}

// --- Bounds and footprints ------------------------------------------------------------------

TEST(RayCastTest, WorldBoundsOfATurnedBoxAreItsTurnedExtents) {
  const PlacedShape box =
      PlaceShape(Box(2, 0.2, 0.4), {{1, 1, 0}, Quat::FromYaw(M_PI / 2)}, ObjectId{}, -1);
  Vec3 lo, hi;
  WorldBounds(box, &lo, &hi);
  EXPECT_NEAR(lo.x, 0.9, 1e-12);
  EXPECT_NEAR(hi.x, 1.1, 1e-12);
  EXPECT_NEAR(lo.y, 0, 1e-12);
  EXPECT_NEAR(hi.y, 2, 1e-12);
  EXPECT_NEAR(lo.z, -0.2, 1e-12);
  EXPECT_NEAR(hi.z, 0.2, 1e-12);
}

TEST(RayCastTest, FootprintRadiusGrowsWhenAShapeTilts) {
  const ShapeData cylinder = Cylinder(0.1, 1);
  // Upright: its own radius.
  EXPECT_NEAR(WorldFootprintRadius(cylinder, {}), 0.1, 1e-12);
  // Lying down: half its length sticks out sideways.
  const Pose lying{{}, Quat::FromAxisAngle({1, 0, 0}, M_PI / 2)};
  const double radius = WorldFootprintRadius(cylinder, lying);
  EXPECT_GE(radius, 0.5);
  // The memo gives the same radius, again and again.
  FootprintMemo memo;
  EXPECT_EQ(WorldFootprintRadius(cylinder, lying, &memo), radius);
  EXPECT_EQ(WorldFootprintRadius(cylinder, lying, &memo), radius);
}

TEST(RayCastTest, MayOverlapCubeRulesOutOnlyFarCubes) {
  const PlacedShape sphere = PlaceShape(Sphere(1), {}, ObjectId{}, -1);
  EXPECT_TRUE(MayOverlapCube(sphere, {1.2, 0, 0}, 0.5, 0));  // the cube reaches x = 0.7
  EXPECT_FALSE(MayOverlapCube(sphere, {3, 0, 0}, 0.5, 0));   // from x = 2.5
  EXPECT_TRUE(MayOverlapCube(sphere, {3, 0, 0}, 0.5, 1.6));  // grown by the margin
  EXPECT_FALSE(MayOverlapCube(sphere, {1, 1, 1}, 0.1, 0));   // off the corner, outside
}

}  // namespace
}  // namespace swarmsim::proximity
