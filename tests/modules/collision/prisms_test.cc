// modules/collision's prisms (prisms.cc): closed-form prism distances
// against hand computations.

#include "modules/collision/prisms.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "framework/scene.h"
#include "modules/collision/geometry.h"

namespace swarmsim::collision {
namespace {

Pose At(double x, double y, double z, double yaw_deg = 0) {
  return {{x, y, z}, Quat::FromAxisAngle({0, 0, 1}, yaw_deg * M_PI / 180)};
}

TEST(PrismsTest, CirclesApartInThePlaneAndInHeight) {
  double d;
  Vec3 pa, pb;
  // Radii 0.5 and 0.25, centres 2 apart: 1.25; heights overlap.
  ASSERT_TRUE(PrismDistance(CylinderPrism(At(0, 0, 0), 0.5, 1),
                            CylinderPrism(At(2, 0, 0.2), 0.25, 1), &d, &pa, &pb));
  EXPECT_DOUBLE_EQ(d, 1.25);
  EXPECT_DOUBLE_EQ(pa.x, 0.5);
  EXPECT_DOUBLE_EQ(pb.x, 1.75);
  EXPECT_DOUBLE_EQ(pa.z, pb.z);
  // Stacked off to the side: 1.25 in the plane, 0.3 in height.
  ASSERT_TRUE(PrismDistance(CylinderPrism(At(0, 0, 0), 0.5, 1),
                            CylinderPrism(At(2, 0, 1.0), 0.25, 0.4), &d, &pa, &pb));
  EXPECT_NEAR(d, std::hypot(1.25, 0.3), 1e-15);
  EXPECT_DOUBLE_EQ(pa.z, 0.5);
  EXPECT_DOUBLE_EQ(pb.z, 0.8);
}

TEST(PrismsTest, ACircleAgainstATurnedRectanglesCorner) {
  double d;
  Vec3 pa, pb;
  // A unit square turned 45 degrees: its corner at (sqrt(2)/2, 0).
  ASSERT_TRUE(PrismDistance(BoxPrism(At(0, 0, 0, 45), {1, 1, 1}),
                            CylinderPrism(At(2, 0, 0), 0.5, 1), &d, &pa, &pb));
  EXPECT_NEAR(d, 2 - std::sqrt(0.5) - 0.5, 1e-15);
  EXPECT_NEAR(pa.x, std::sqrt(0.5), 1e-15);
  EXPECT_NEAR(pa.y, 0, 1e-15);
}

TEST(PrismsTest, TwoRectanglesCornerToEdgeAndOverlapIsLeftToTheCaller) {
  double d;
  Vec3 pa, pb;
  ASSERT_TRUE(PrismDistance(BoxPrism(At(0, 0, 0, 45), {1, 1, 1}), BoxPrism(At(2, 0, 0), {1, 4, 1}),
                            &d, &pa, &pb));
  EXPECT_NEAR(d, 1.5 - std::sqrt(0.5), 1e-15);
  // Crossed bars overlap with no corner inside the other: not separated.
  EXPECT_FALSE(PrismDistance(BoxPrism(At(0, 0, 0), {4, 0.2, 1}), BoxPrism(At(0, 0, 0), {0.2, 4, 1}),
                             &d, &pa, &pb));
  // A tilted box has no prism.
  const Pose tilted{{0, 0, 0}, Quat::FromAxisAngle({1, 0, 0}, 0.3)};
  EXPECT_EQ(BoxPrism(tilted, {1, 1, 1}).kind, Prism::kNone);
}

}  // namespace
}  // namespace swarmsim::collision
