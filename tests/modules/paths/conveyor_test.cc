// Conveyors (modules/paths/conveyor.cc): the belt's box segments made when
// the world starts (their sizes, poses and surface speeds, corners closed
// on the outside, curvature on smooth bends), a new speed applied in the
// actuate phase, and the type's keys.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "modules/paths/curve.h"
#include "modules/paths/rows.h"
#include "tests/framework/error_of.h"
#include "tests/modules/entry_reader.h"
#include "tests/modules/module_world.h"

namespace swarmsim::paths {
namespace {

using testing::EntryReader;
using testing::ErrorOf;
using testing::ModuleWorld;

void ExpectNear(const Vec3& a, const Vec3& b, double tol) {
  EXPECT_NEAR(a.x, b.x, tol);
  EXPECT_NEAR(a.y, b.y, tol);
  EXPECT_NEAR(a.z, b.z, tol);
}

ConveyorRow Belt(std::vector<Vec3> points, Interpolation interpolation, bool closed, double speed) {
  ConveyorRow row;
  row.curve = std::make_shared<const PathCurve>(std::move(points), interpolation, closed);
  row.speed = speed;
  return row;
}

// The conveyor's belt segments, in order.
std::vector<ObjectId> Segments(Scene& scene, ObjectId conveyor) {
  const std::vector<ObjectId> children = scene.children(conveyor);
  std::vector<ObjectId> out;
  for (uint32_t k = 0;; ++k) {
    auto it = std::find_if(children.begin(), children.end(),
                           [&](ObjectId c) { return scene.name(c) == BeltSegmentName(k); });
    if (it == children.end()) return out;
    out.push_back(*it);
  }
}

TEST(ConveyorTest, AStraightBeltIsOneSegmentWithItsTopOnTheLine) {
  ModuleWorld w;
  const ConveyorRow row = Belt({{0, 0, 0}, {2, 0, 0}}, Interpolation::kLinear, false, 0.4);
  const ObjectId conveyor = w.Add(kConveyorTypeName, "conveyor", {}, {{0, 0, 0.5}, {}}, &row);
  ASSERT_EQ(w.Run(0), "");
  const std::vector<ObjectId> segments = Segments(w.scene(), conveyor);
  ASSERT_EQ(segments.size(), 1u);
  EXPECT_EQ(w.RowOf<ConveyorRow>(kConveyorTypeName, conveyor).segments, 1u);
  const ShapeData& belt = w.scene().shape(segments[0]);
  ExpectNear(belt.size, {2, 0.3, 0.05}, 1e-12);  // the default width and thickness
  EXPECT_DOUBLE_EQ(belt.friction, 0.7);
  ExpectNear(w.scene().local_pose(segments[0]).p, {1, 0, -0.025}, 1e-12);
  ExpectNear(belt.surface_velocity, {0.4, 0, 0}, 1e-12);
  ExpectNear(belt.surface_angular_velocity, {0, 0, 0}, 1e-12);
}

// A 45-degree corner: two segments, each reaching past the corner by
// width/2 x tan(22.5 deg), so that their outer edges meet; straight
// segments do not turn what they carry.
TEST(ConveyorTest, ACornerIsClosedOnTheOutside) {
  ModuleWorld w;
  const Vec3 d{std::sqrt(0.5), std::sqrt(0.5), 0};  // the second leg's direction
  ConveyorRow row =
      Belt({{0, 0, 0}, {1, 0, 0}, Vec3{1, 0, 0} + d}, Interpolation::kLinear, false, 1);
  row.width = 0.2;
  const ObjectId conveyor = w.Add(kConveyorTypeName, "conveyor", {}, {}, &row);
  ASSERT_EQ(w.Run(0), "");
  const std::vector<ObjectId> segments = Segments(w.scene(), conveyor);
  ASSERT_EQ(segments.size(), 2u);
  const double reach = 0.1 * std::tan(M_PI / 8);
  EXPECT_NEAR(w.scene().shape(segments[0]).size.x, 1 + reach, 1e-12);
  EXPECT_NEAR(w.scene().shape(segments[1]).size.x, 1 + reach, 1e-12);
  ExpectNear(w.scene().local_pose(segments[0]).p, {(1 + reach) / 2, 0, -0.025}, 1e-12);
  EXPECT_NEAR(w.scene().local_pose(segments[1]).q.Yaw(), M_PI / 4, 1e-12);
  ExpectNear(w.scene().local_pose(segments[1]).p, Vec3{1, 0, -0.025} + d * (1 - (1 + reach) / 2),
             1e-12);
  // The outer (right-hand) edges meet: the first's far corner is the
  // second's near one.
  const Vec3 right0 = w.scene().local_pose(segments[0]) * Vec3{(1 + reach) / 2, -0.1, 0};
  const Vec3 right1 = w.scene().local_pose(segments[1]) * Vec3{-(1 + reach) / 2, -0.1, 0};
  ExpectNear(right0, right1, 1e-12);
  for (const ObjectId s : segments)
    ExpectNear(w.scene().shape(s).surface_angular_velocity, {0, 0, 0}, 1e-12);
}

// A smooth loop of radius 1 m: segments no longer than segment_length, and
// each turns what it carries about the loop's centre (curvature ~ 1/R).
TEST(ConveyorTest, ASmoothLoopIsCutIntoShortSegmentsThatTurnWithTheBend) {
  ModuleWorld w;
  std::vector<Vec3> circle;
  for (int i = 0; i < 8; ++i) circle.push_back({std::cos(i * M_PI / 4), std::sin(i * M_PI / 4), 0});
  ConveyorRow row = Belt(circle, Interpolation::kSmooth, true, 0.5);
  row.segment_length = 0.1;
  const ObjectId conveyor = w.Add(kConveyorTypeName, "conveyor", {}, {}, &row);
  ASSERT_EQ(w.Run(0), "");
  const std::vector<ObjectId> segments = Segments(w.scene(), conveyor);
  const double length = row.curve->length();
  EXPECT_GE(segments.size(), static_cast<size_t>(length / 0.1));
  const ConveyorRow& built = w.RowOf<ConveyorRow>(kConveyorTypeName, conveyor);
  ASSERT_EQ(built.curvature->size(), segments.size());
  // The segments' turns add up to one turn around; the eight spline pieces
  // are alike, so the segments are about length / n long each.
  double sum = 0;
  for (size_t k = 0; k < segments.size(); ++k) {
    const double curvature = (*built.curvature)[k];
    EXPECT_GT(curvature, 0.5) << "segment " << k;  // counter-clockwise: to the left
    EXPECT_LT(curvature, 1.5) << "segment " << k;
    sum += curvature;
    const ShapeData& belt = w.scene().shape(segments[k]);
    EXPECT_NEAR(belt.surface_angular_velocity.z, 0.5 * curvature, 1e-12);
  }
  EXPECT_NEAR(sum / segments.size(), 2 * M_PI / length, 0.01 * 2 * M_PI / length);
}

TEST(ConveyorTest, ANewSpeedReachesTheBeltInTheActuatePhase) {
  ModuleWorld w;
  const ConveyorRow row = Belt({{0, 0, 0}, {2, 0, 0}}, Interpolation::kLinear, false, 0.4);
  const ObjectId conveyor = w.Add(kConveyorTypeName, "conveyor", {}, {}, &row);
  ASSERT_EQ(w.Run(1), "");
  ConveyorRow& c = w.RowOf<ConveyorRow>(kConveyorTypeName, conveyor);
  c.requested_speed = -0.25;
  const ObjectId segment = Segments(w.scene(), conveyor).at(0);
  EXPECT_DOUBLE_EQ(w.scene().shape(segment).surface_velocity.x, 0.4);
  ASSERT_EQ(w.Run(1), "");
  EXPECT_DOUBLE_EQ(c.speed, -0.25);
  EXPECT_DOUBLE_EQ(w.scene().shape(segment).surface_velocity.x, -0.25);
}

TEST(ConveyorTest, ReadsItsKeysAndRefusesBadOnes) {
  ModuleWorld w;
  EntryReader entry;
  entry.points["points"] = {{0, 0, 0}, {1, 0, 0}, {1, 2, 0}};
  entry.numbers["width"] = {0.5};
  entry.numbers["speed"] = {-0.3};
  entry.numbers["color"] = {1, 0, 0.5};
  entry.strings["interpolation"] = {"smooth"};
  ConveyorRow row;
  testing::ReadRow(w.scene(), kConveyorTypeName, entry, &row);
  EXPECT_DOUBLE_EQ(row.width, 0.5);
  EXPECT_DOUBLE_EQ(row.speed, -0.3);
  EXPECT_DOUBLE_EQ(row.thickness, 0.05);
  ExpectNear(row.color, {1, 0, 0.5}, 0);
  EXPECT_EQ(row.curve->interpolation(), Interpolation::kSmooth);
  EXPECT_EQ(row.curve->points().size(), 3u);

  entry.numbers["width"] = {0};
  EXPECT_CONTAINS(ErrorOf([&] { testing::ReadRow(w.scene(), kConveyorTypeName, entry, &row); }),
                  "entry.width: must be a positive number");
  entry.numbers["width"] = {0.5};
  entry.points["points"] = {{0, 0, 0}, {1, 0, 0}, {1, 0, 0}};
  EXPECT_CONTAINS(ErrorOf([&] { testing::ReadRow(w.scene(), kConveyorTypeName, entry, &row); }),
                  "entry.points[2]: points[2] repeats points[1]");
}

}  // namespace
}  // namespace swarmsim::paths
