// The mills' cutting volumes (modules/mill/volume.h): the exact
// point-in-volume test on points a user can check by hand, its volume
// against the closed forms, and the bounds.
#include "modules/mill/volume.h"

#include <gtest/gtest.h>

#include <cmath>

namespace swarmsim::mill {
namespace {

constexpr double kPi = 3.141592653589793;

Volume Make(VolumeKind kind) {
  Volume v;
  v.kind = kind;
  v.range = 0.1;
  v.angle = 30 * kPi / 180;
  v.radius = 0.02;
  v.width = 0.04;
  v.height = 0.06;
  v.thickness = 0.01;
  return v;
}

TEST(MillVolumeTest, CylinderHandPoints) {
  const Volume v = Make(VolumeKind::kCylinder);
  EXPECT_TRUE(Contains(v, {0, 0, 0}));
  EXPECT_TRUE(Contains(v, {0, 0, 0.1}));      // the far face
  EXPECT_TRUE(Contains(v, {0.02, 0, 0.05}));  // the side
  EXPECT_FALSE(Contains(v, {0.02, 0.001, 0.05}));
  EXPECT_FALSE(Contains(v, {0, 0, -1e-9}));  // behind the mill
  EXPECT_FALSE(Contains(v, {0, 0, 0.1 + 1e-9}));
  EXPECT_FALSE(Contains(v, {NAN, 0, 0.05}));
}

TEST(MillVolumeTest, BoxAndPyramidHandPoints) {
  const Volume box = Make(VolumeKind::kBox);
  EXPECT_TRUE(Contains(box, {0.02, 0.03, 0.001}));
  EXPECT_FALSE(Contains(box, {0.021, 0, 0.05}));
  EXPECT_FALSE(Contains(box, {0, 0.031, 0.05}));
  const Volume pyramid = Make(VolumeKind::kPyramid);
  // Half the width at half the range.
  EXPECT_TRUE(Contains(pyramid, {0.01, 0.015, 0.05}));
  EXPECT_FALSE(Contains(pyramid, {0.0101, 0, 0.05}));
  EXPECT_FALSE(Contains(pyramid, {0, 0.0151, 0.05}));
  EXPECT_TRUE(Contains(pyramid, {0, 0, 0}));  // the apex
  EXPECT_FALSE(Contains(pyramid, {1e-6, 0, 0}));
}

TEST(MillVolumeTest, ConeIsASphericalSector) {
  const Volume v = Make(VolumeKind::kCone);
  const double t = std::tan(v.angle);
  EXPECT_TRUE(Contains(v, {0.05 * t * 0.999, 0, 0.05}));
  EXPECT_FALSE(Contains(v, {0.05 * t * 1.001, 0, 0.05}));
  EXPECT_TRUE(Contains(v, {0, 0, 0.1}));
  // On the axis a sphere of `range` bounds it, not a plane: off the axis at
  // z = 0.099 the sphere cuts first.
  EXPECT_FALSE(Contains(v, {0, 0.02, 0.099}));
  EXPECT_TRUE(Contains(v, {0, 0.013, 0.099}));
  EXPECT_FALSE(Contains(v, {0, 0, -0.01}));
}

TEST(MillVolumeTest, DiscIsAFlatSector) {
  Volume v = Make(VolumeKind::kDisc);
  EXPECT_TRUE(Contains(v, {0.005, 0, 0.1}));
  EXPECT_FALSE(Contains(v, {0.0051, 0, 0.05}));  // thicker than 0.01
  const double a = v.angle;
  EXPECT_TRUE(Contains(v, {0, 0.09 * std::sin(a) * 0.999, 0.09 * std::cos(a)}));
  EXPECT_FALSE(Contains(v, {0, 0.09 * std::sin(a) * 1.001, 0.09 * std::cos(a)}));
  v.angle = kPi / 2;                           // a half disc
  EXPECT_TRUE(Contains(v, {0, 0.099, 1e-6}));  // (cos 90 deg is not quite 0 in doubles)
  EXPECT_TRUE(Contains(v, {0, -0.07, 0.07}));
  EXPECT_FALSE(Contains(v, {0, 0.07, -0.001}));
}

// Points on a fine grid inside the bounds: their share times the bounds'
// volume approaches the closed form; none inside lies outside the bounds.
TEST(MillVolumeTest, VolumesMatchTheirClosedFormsAndStayInTheirBounds) {
  for (VolumeKind kind : {VolumeKind::kCone, VolumeKind::kCylinder, VolumeKind::kPyramid,
                          VolumeKind::kDisc, VolumeKind::kBox}) {
    const Volume v = Make(kind);
    Vec3 lo, hi;
    Bounds(v, &lo, &hi);
    constexpr int kN = 160;
    const Vec3 pad = (hi - lo) * 0.05;
    const Vec3 g_lo = lo - pad, g_hi = hi + pad;
    const Vec3 step = (g_hi - g_lo) / kN;
    int64_t inside = 0;
    for (int i = 0; i < kN; ++i)
      for (int j = 0; j < kN; ++j)
        for (int k = 0; k < kN; ++k) {
          const Vec3 p{g_lo.x + (i + 0.5) * step.x, g_lo.y + (j + 0.5) * step.y,
                       g_lo.z + (k + 0.5) * step.z};
          if (!Contains(v, p)) continue;
          ++inside;
          EXPECT_TRUE(p.x >= lo.x && p.x <= hi.x && p.y >= lo.y && p.y <= hi.y && p.z >= lo.z &&
                      p.z <= hi.z)
              << ToString(kind);
        }
    const double measured = static_cast<double>(inside) * step.x * step.y * step.z;
    EXPECT_NEAR(measured, ExactVolume(v), 0.03 * ExactVolume(v)) << ToString(kind);
  }
}

TEST(MillVolumeTest, WorldBoundsFollowThePose) {
  const Volume v = Make(VolumeKind::kCylinder);
  // The mill at (1, 2, 3) pointing along world +x (z turned onto x).
  const Pose X_WM{{1, 2, 3}, Quat::FromAxisAngle({0, 1, 0}, kPi / 2)};
  Vec3 lo, hi;
  WorldBounds(v, X_WM, &lo, &hi);
  EXPECT_NEAR(lo.x, 1, 1e-12);
  EXPECT_NEAR(hi.x, 1.1, 1e-12);
  EXPECT_NEAR(lo.y, 1.98, 1e-12);
  EXPECT_NEAR(hi.z, 3.02, 1e-12);
}

}  // namespace
}  // namespace swarmsim::mill
