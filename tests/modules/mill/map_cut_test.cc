// Mills cutting the environment map (modules/mill/map_cut.h): the voxels
// whose centres are inside a volume go, exactly (checked voxel by voxel
// against the volume), what is left covers the rest exactly once, and a
// box nothing was cut from stays whole.
#include "modules/mill/map_cut.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

namespace swarmsim::mill {
namespace {

constexpr double kRes = 0.01;

// Voxel centres of a box at resolution kRes.
std::vector<Vec3> Centres(const EnvironmentBox& b) {
  std::vector<Vec3> out;
  const int n[3] = {static_cast<int>(std::lround((b.hi.x - b.lo.x) / kRes)),
                    static_cast<int>(std::lround((b.hi.y - b.lo.y) / kRes)),
                    static_cast<int>(std::lround((b.hi.z - b.lo.z) / kRes))};
  for (int z = 0; z < n[2]; ++z)
    for (int y = 0; y < n[1]; ++y)
      for (int x = 0; x < n[0]; ++x)
        out.push_back(
            {b.lo.x + (x + 0.5) * kRes, b.lo.y + (y + 0.5) * kRes, b.lo.z + (z + 0.5) * kRes});
  return out;
}

bool In(const EnvironmentBox& b, const Vec3& p) {
  return p.x > b.lo.x && p.x < b.hi.x && p.y > b.lo.y && p.y < b.hi.y && p.z > b.lo.z &&
         p.z < b.hi.z;
}

// Every voxel centre of `original` is in exactly one piece if it is outside
// the volume, in none if inside; returns the centres inside.
int64_t CheckPieces(const EnvironmentBox& original, const std::vector<EnvironmentBox>& pieces,
                    const Volume& v, const Pose& X_WM) {
  const Pose X_MW = X_WM.Inverse();
  int64_t inside = 0;
  for (const Vec3& p : Centres(original)) {
    int holders = 0;
    for (const EnvironmentBox& piece : pieces) holders += In(piece, p);
    const bool cut = Contains(v, X_MW * p);
    inside += cut;
    EXPECT_EQ(holders, cut ? 0 : 1) << p.x << " " << p.y << " " << p.z;
  }
  return inside;
}

TEST(MillMapCutTest, ABoxMillTakesExactlyTheVoxelsItCovers) {
  const EnvironmentBox box{{0, 0, 0}, {0.08, 0.08, 0.08}};  // 8 x 8 x 8 voxels
  Volume v;
  v.kind = VolumeKind::kBox;
  v.width = v.height = v.range = 0.04;
  const Pose X_WM{{0.02, 0.02, 0}, {}};  // covers [0, 0.04]^3: 4 x 4 x 4 centres
  std::vector<EnvironmentBox> left;
  EXPECT_EQ(CutBox(box, kRes, v, X_WM.Inverse(), &left), 64);
  EXPECT_EQ(CheckPieces(box, left, v, X_WM), 64);
  // The other seven octants stay whole.
  EXPECT_EQ(left.size(), 7u);
}

TEST(MillMapCutTest, ACylinderThroughAnOctreeLeafMatchesTheVoxelByVoxelAnswer) {
  const EnvironmentBox box{{-0.16, -0.16, 0}, {0.16, 0.16, 0.32}};  // 32^3 voxels
  Volume v;
  v.kind = VolumeKind::kCylinder;
  v.radius = 0.045;
  v.range = 0.5;
  // Slanted, through the box.
  const Pose X_WM{{-0.2, 0.01, 0.1}, Quat::FromRollPitchYaw(0.3, 1.2, 0.2)};
  std::vector<EnvironmentBox> left;
  const int64_t removed = CutBox(box, kRes, v, X_WM.Inverse(), &left);
  EXPECT_GT(removed, 1000);
  EXPECT_EQ(CheckPieces(box, left, v, X_WM), removed);
  // Far fewer pieces than voxels: whole parts stay whole.
  EXPECT_LT(left.size(), static_cast<size_t>(32 * 32 * 32 - removed) / 4);
}

TEST(MillMapCutTest, ABoxOutOfReachStaysAsItIs) {
  const EnvironmentBox box{{1, 1, 1}, {1.08, 1.08, 1.08}};
  Volume v;  // the default cylinder at the origin
  std::vector<EnvironmentBox> left;
  EXPECT_EQ(CutBox(box, kRes, v, Pose{}, &left), 0);
  ASSERT_EQ(left.size(), 1u);
  EXPECT_EQ(left[0].lo, box.lo);
  EXPECT_EQ(left[0].hi, box.hi);
}

EnvironmentMap TestMap() {
  // A floor of 0.08 m leaves, with a few 0.01 m and 0.04 m boxes on top.
  EnvironmentMap map;
  map.source = "test";
  map.resolution = kRes;
  for (int y = 0; y < 6; ++y)
    for (int x = 0; x < 6; ++x)
      map.boxes.push_back(
          {{x * 0.08 - 0.24, y * 0.08 - 0.24, -0.08}, {x * 0.08 - 0.16, y * 0.08 - 0.16, 0}});
  for (int i = 0; i < 5; ++i)
    map.boxes.push_back({{i * 0.04, 0, 0}, {i * 0.04 + 0.04, 0.04, 0.04}});
  for (int i = 0; i < 7; ++i)
    map.boxes.push_back({{-0.1, i * 0.01, 0}, {-0.09, i * 0.01 + 0.01, 0.01}});
  map.lo = {-0.24, -0.24, -0.08};
  map.hi = {0.24, 0.24, 0.04};
  return map;
}

TEST(MillMapCutTest, TheIndexFindsWhatABruteForceScanFinds) {
  const EnvironmentMap map = TestMap();
  MapIndex index;
  index.Build(map);
  EXPECT_TRUE(index.Follows(map));
  std::vector<uint32_t> found;
  for (int q = 0; q < 200; ++q) {
    const double cx = -0.3 + 0.003 * q, cy = 0.25 - 0.0025 * q, cz = -0.1 + 0.0007 * q;
    const double half = 0.005 + 0.0004 * (q % 50);
    const Vec3 lo{cx - half, cy - half, cz - half}, hi{cx + half, cy + half, cz + half};
    index.Query(lo, hi, &found);
    std::vector<uint32_t> expected;
    for (uint32_t b = 0; b < map.boxes.size(); ++b) {
      const EnvironmentBox& box = map.boxes[b];
      if (box.lo.x <= hi.x && lo.x <= box.hi.x && box.lo.y <= hi.y && lo.y <= box.hi.y &&
          box.lo.z <= hi.z && lo.z <= box.hi.z)
        expected.push_back(b);
    }
    EXPECT_EQ(found, expected) << q;
  }
}

// Two mills in one step: each cuts what the other left; the new map holds
// every voxel neither took, once, in the old map's order.
TEST(MillMapCutTest, TwoMillsInAStepCutTheMapOnce) {
  const EnvironmentMap map = TestMap();
  Volume v;
  v.kind = VolumeKind::kCylinder;
  v.radius = 0.03;
  v.range = 0.1;
  const Pose a{{0.02, 0.02, -0.06}, {}};  // up, through the floor
  const Pose b{{-0.12, 0.03, 0.005}, Quat::FromAxisAngle({0, 1, 0}, 1.5708)};  // along +x
  MapCutter cutter;
  const int64_t first = cutter.Cut(map, v, a);
  const int64_t second = cutter.Cut(map, v, b);
  EXPECT_GT(first, 0);
  EXPECT_GT(second, 0);
  const std::shared_ptr<const EnvironmentMap> next = cutter.Finish(map);
  ASSERT_NE(next, nullptr);
  EXPECT_EQ(next->resolution, kRes);
  EXPECT_EQ(next->source, "test");
  // Voxel by voxel: kept iff neither volume holds its centre.
  int64_t taken = 0;
  for (const EnvironmentBox& box : map.boxes)
    for (const Vec3& p : Centres(box)) {
      const bool cut = Contains(v, a.Inverse() * p) || Contains(v, b.Inverse() * p);
      taken += cut;
      int holders = 0;
      for (const EnvironmentBox& piece : next->boxes) holders += In(piece, p);
      EXPECT_EQ(holders, cut ? 0 : 1);
    }
  EXPECT_EQ(first + second, taken);
  // Nothing near: no new map.
  EXPECT_EQ(cutter.Cut(*next, v, Pose{{5, 5, 5}, {}}), 0);
  EXPECT_EQ(cutter.Finish(*next), nullptr);
}

}  // namespace
}  // namespace swarmsim::mill
