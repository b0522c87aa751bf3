// A path's curve (modules/paths/curve.cc): arc length, poses along straight
// and smooth curves, open ends clamped and closed curves wrapped, the frame
// that follows the tangent or the points' orientations.
#include "modules/paths/curve.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

namespace swarmsim::paths {
namespace {

void ExpectNear(const Vec3& a, const Vec3& b, double tol) {
  EXPECT_NEAR(a.x, b.x, tol);
  EXPECT_NEAR(a.y, b.y, tol);
  EXPECT_NEAR(a.z, b.z, tol);
}

// The same rotation (q and -q are one rotation).
void ExpectSameRotation(const Quat& a, const Quat& b, double tol) {
  const double dot = a.w * b.w + a.x * b.x + a.y * b.y + a.z * b.z;
  EXPECT_NEAR(std::abs(dot), 1, tol);
}

// An L: 3 m along +x, then 4 m along +y.
PathCurve LinearL() {
  return PathCurve({{0, 0, 0}, {3, 0, 0}, {3, 4, 0}}, Interpolation::kLinear, false);
}

TEST(PathCurveTest, AStraightPathIsAsLongAsItsSegmentsAndPosesFollowThem) {
  const PathCurve curve = LinearL();
  EXPECT_DOUBLE_EQ(curve.length(), 7);
  EXPECT_DOUBLE_EQ(curve.LengthAtPoint(0), 0);
  EXPECT_DOUBLE_EQ(curve.LengthAtPoint(1), 3);
  EXPECT_DOUBLE_EQ(curve.LengthAtPoint(2), 7);
  // On the first leg x points along +x; on the second along +y; z stays up.
  const Pose X_PC1 = curve.PoseAt(1.5);
  ExpectNear(X_PC1.p, {1.5, 0, 0}, 1e-12);
  EXPECT_NEAR(X_PC1.q.Yaw(), 0, 1e-12);
  const Pose X_PC2 = curve.PoseAt(5);
  ExpectNear(X_PC2.p, {3, 2, 0}, 1e-12);
  EXPECT_NEAR(X_PC2.q.Yaw(), M_PI / 2, 1e-12);
  ExpectNear(X_PC2.q.Rotate({0, 0, 1}), {0, 0, 1}, 1e-12);
}

TEST(PathCurveTest, AnOpenPathClampsAndAClosedOneWraps) {
  const PathCurve open = LinearL();
  EXPECT_DOUBLE_EQ(open.Normalize(-2), 0);
  EXPECT_DOUBLE_EQ(open.Normalize(9), 7);
  ExpectNear(open.PoseAt(100).p, {3, 4, 0}, 1e-12);
  ExpectNear(open.PoseAt(-100).p, {0, 0, 0}, 1e-12);

  // A unit square, closed: 4 m around, the fourth side back to the start.
  const PathCurve square({{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}}, Interpolation::kLinear,
                         true);
  EXPECT_TRUE(square.closed());
  EXPECT_DOUBLE_EQ(square.length(), 4);
  EXPECT_DOUBLE_EQ(square.Normalize(5), 1);
  EXPECT_DOUBLE_EQ(square.Normalize(-1), 3);
  EXPECT_DOUBLE_EQ(square.Normalize(4), 0);
  const Pose X_PC = square.PoseAt(3.5);  // halfway down the closing side
  ExpectNear(X_PC.p, {0, 0.5, 0}, 1e-12);
  EXPECT_NEAR(X_PC.q.Yaw(), -M_PI / 2, 1e-12);
  ExpectNear(square.PoseAt(4.25).p, square.PoseAt(0.25).p, 1e-12);
}

// A smooth curve passes through its control points, and is parametrised by
// arc length: a short step along s moves that far along the curve.
TEST(PathCurveTest, ASmoothCurvePassesThroughItsPointsAtArcLength) {
  std::vector<Vec3> points;
  for (int i = 0; i < 6; ++i)
    points.push_back({std::cos(i * M_PI / 3), std::sin(i * M_PI / 3), 0.2 * (i % 2)});
  const PathCurve curve(points, Interpolation::kSmooth, true);
  double polygon = 0;
  for (size_t i = 0; i < points.size(); ++i)
    polygon += (points[(i + 1) % points.size()] - points[i]).Norm();
  // Longer than the polygon through the same points (a curve between them).
  EXPECT_GT(curve.length(), polygon);
  EXPECT_LT(curve.length(), 1.5 * polygon);
  for (size_t i = 0; i < points.size(); ++i)
    ExpectNear(curve.PoseAt(curve.LengthAtPoint(i)).p, points[i], 1e-9);
  const double ds = 1e-4;
  for (double s = 0.1; s < curve.length(); s += 0.37) {
    const double chord = (curve.PoseAt(s + ds).p - curve.PoseAt(s).p).Norm();
    EXPECT_NEAR(chord, ds, 1e-9) << "at s = " << s;
    // x is the tangent: the chord's direction.
    const Vec3 tangent = (curve.PoseAt(s + ds).p - curve.PoseAt(s - ds).p) * (1 / (2 * ds));
    ExpectNear(curve.PoseAt(s).q.Rotate({1, 0, 0}), tangent.Normalized(), 1e-6);
  }
}

// Equally spaced points on a line: the smooth curve is that line, as long
// as the straight one.
TEST(PathCurveTest, ASmoothCurveThroughEquallySpacedPointsOnALineIsTheLine) {
  const std::vector<Vec3> points{{0, 0, 0}, {1, 1, 0}, {2, 2, 0}, {3, 3, 0}};
  const PathCurve smooth(points, Interpolation::kSmooth, false);
  EXPECT_NEAR(smooth.length(), 3 * std::sqrt(2.0), 1e-9);
  const Pose X_PC = smooth.PoseAt(smooth.length() / 3);
  ExpectNear(X_PC.p, {1, 1, 0}, 1e-9);
  EXPECT_NEAR(X_PC.q.Yaw(), M_PI / 4, 1e-9);
}

// With an orientation per point the frame turns from each point's to the
// next one's by arc length, whatever the tangent does.
TEST(PathCurveTest, OrientationsAreSlerpedByArcLength) {
  const PathCurve curve({{0, 0, 0}, {2, 0, 0}}, Interpolation::kLinear, false,
                        {Quat::FromYaw(0), Quat::FromYaw(M_PI / 2)});
  ASSERT_EQ(curve.orientations().size(), 2u);
  EXPECT_NEAR(curve.PoseAt(0.5).q.Yaw(), M_PI / 8, 1e-12);
  EXPECT_NEAR(curve.PoseAt(1).q.Yaw(), M_PI / 4, 1e-12);
  EXPECT_NEAR(curve.PoseAt(2).q.Yaw(), M_PI / 2, 1e-12);
  // A count that is not one per point is ignored: the tangent frame.
  const PathCurve tangent({{0, 0, 0}, {2, 0, 0}}, Interpolation::kLinear, false,
                          {Quat::FromYaw(1)});
  EXPECT_TRUE(tangent.orientations().empty());
  EXPECT_NEAR(tangent.PoseAt(1).q.Yaw(), 0, 1e-12);
}

// A vertical segment still gets an orthonormal frame with x along it.
TEST(PathCurveTest, AVerticalSegmentHasAFrameAlongIt) {
  const PathCurve lift({{0, 0, 0}, {0, 0, 2}}, Interpolation::kLinear, false);
  const Pose X_PC = lift.PoseAt(1);
  ExpectNear(X_PC.p, {0, 0, 1}, 1e-12);
  ExpectNear(X_PC.q.Rotate({1, 0, 0}), {0, 0, 1}, 1e-12);
  EXPECT_NEAR(X_PC.q.Rotate({0, 1, 0}).Dot(X_PC.q.Rotate({0, 0, 1})), 0, 1e-12);
}

TEST(PathCurveTest, FromAxesAndSlerp) {
  for (double yaw : {0.0, 0.5, 2.0, 3.1, -2.5}) {
    const Quat q = Quat::FromYaw(yaw);
    ExpectSameRotation(FromAxes(q.Rotate({1, 0, 0}), q.Rotate({0, 1, 0}), q.Rotate({0, 0, 1})), q,
                       1e-12);
  }
  const Quat r = Quat::FromRollPitchYaw(0.3, -1.2, 2.9);
  ExpectSameRotation(FromAxes(r.Rotate({1, 0, 0}), r.Rotate({0, 1, 0}), r.Rotate({0, 0, 1})), r,
                     1e-12);
  const Quat a = Quat::FromYaw(0.2), b = Quat::FromYaw(1.4);
  ExpectSameRotation(Slerp(a, b, 0), a, 1e-12);
  ExpectSameRotation(Slerp(a, b, 1), b, 1e-12);
  EXPECT_NEAR(Slerp(a, b, 0.25).Yaw(), 0.5, 1e-12);
  // The short way: from yaw 170 deg to -170 deg through 180, not through 0.
  const Quat c = Quat::FromYaw(170 * M_PI / 180), d = Quat::FromYaw(-170 * M_PI / 180);
  EXPECT_NEAR(std::abs(Slerp(c, d, 0.5).Yaw()), M_PI, 1e-9);
}

}  // namespace
}  // namespace swarmsim::paths
