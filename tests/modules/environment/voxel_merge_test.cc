// modules/environment/voxel_merge: the band's grids, their cell size and
// what they may cost; the shared real map's band merged into few boxes.
#include "modules/environment/voxel_merge.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "framework/error.h"
#include "modules/environment/octomap_map.h"
#include "tests/shared_maps.h"

namespace swarmsim {
namespace {

constexpr double kRes = 0.05;  // m

EnvironmentBox Cube(int i, int j, int k, int side) {
  return {{i * kRes, j * kRes, k * kRes},
          {(i + side) * kRes, (j + side) * kRes, (k + side) * kRes}};
}

EnvironmentMap MapOf(std::vector<EnvironmentBox> boxes) {
  EnvironmentMap map;
  map.source = "test.bt";
  map.resolution = kRes;
  map.lo = boxes.front().lo, map.hi = boxes.front().hi;
  for (const EnvironmentBox& b : boxes) {
    map.lo = {std::min(map.lo.x, b.lo.x), std::min(map.lo.y, b.lo.y), std::min(map.lo.z, b.lo.z)};
    map.hi = {std::max(map.hi.x, b.hi.x), std::max(map.hi.y, b.hi.y), std::max(map.hi.z, b.hi.z)};
  }
  map.boxes = std::move(boxes);
  return map;
}

// The fuzzer's 221-byte map: one pruned leaf 2^15 voxels wide. Its grid was
// 32768 x 32768 cells (1 GiB) whatever max_memory_mb said; a grid of leaves
// that big needs one cell.
TEST(VoxelMergeTest, OneHugePrunedLeafIsOneCellNotAGibibyte) {
  const std::string file = std::string(SWARMSIM_SOURCE_DIR) +
                           "/tests/data/fuzz/octomap/crashes/slow-1gib-grid-from-a-221-byte-map.bt";
  const EnvironmentMap map = environment::ReadOctomap(file, "tiny.bt", {});
  ASSERT_FALSE(map.boxes.empty());
  const environment::PlaneGrid grid =
      environment::ProjectBand(map, map.lo.z + 1e-3, map.lo.z + 0.2);
  EXPECT_LE(int64_t{grid.nx} * grid.ny, 4);
  EXPECT_DOUBLE_EQ(grid.x0 + grid.nx * grid.cell, map.hi.x);  // still the whole map
  EXPECT_DOUBLE_EQ(grid.y0 + grid.ny * grid.cell, map.hi.y);
  EXPECT_TRUE(grid.at(0, 0));
}

// Big aligned leaves merge to the same boxes as the same space in voxels.
TEST(VoxelMergeTest, CoarseCellsGiveTheSameBoxesAsVoxels) {
  // A 4-voxel leaf alone: cells of 4 voxels.
  const EnvironmentMap coarse = MapOf({Cube(0, 0, 0, 4)});
  const environment::PlaneGrid g = environment::ProjectBand(coarse, 1e-3, 0.1);
  EXPECT_EQ(g.nx, 1);
  EXPECT_DOUBLE_EQ(g.cell, 4 * kRes);
  // With one voxel beside it, the grid is in voxels; the leaf's boxes are unchanged.
  const EnvironmentMap fine = MapOf({Cube(0, 0, 0, 4), Cube(5, 0, 0, 1)});
  EXPECT_EQ(environment::ProjectBand(fine, 1e-3, 0.1).nx, 6);
  for (auto merge : {environment::MergeBand2D, environment::MergeBand3D}) {
    const auto a = merge(coarse, 1e-3, 0.1);
    const auto b = merge(fine, 1e-3, 0.1);
    ASSERT_EQ(a.size(), 1u);
    ASSERT_EQ(b.size(), 2u);
    EXPECT_EQ(a[0].lo.x, b[0].lo.x);  // bit for bit
    EXPECT_EQ(a[0].lo.y, b[0].lo.y);
    EXPECT_EQ(a[0].lo.z, b[0].lo.z);
    EXPECT_EQ(a[0].hi.x, b[0].hi.x);
    EXPECT_EQ(a[0].hi.y, b[0].hi.y);
    EXPECT_EQ(a[0].hi.z, b[0].hi.z);
    EXPECT_DOUBLE_EQ(a[0].hi.x, 4 * kRes);
    EXPECT_DOUBLE_EQ(a[0].hi.z, 2 * kRes);  // the band's voxel layers only (z below 0.1 m)
    EXPECT_DOUBLE_EQ(b[1].lo.x, 5 * kRes);
  }
}

// Two voxels far apart need a fine grid over everything between them: the
// map's max_memory_mb bounds it, with a message saying what to do.
TEST(VoxelMergeTest, AGridLargerThanMaxMemoryIsRefusedWithTheKeyToRaise) {
  EnvironmentMap map = MapOf({Cube(0, 0, 0, 1), Cube(2999, 2999, 0, 1)});  // 9 M cells
  map.max_grid_bytes = 1 << 20;
  try {
    environment::ProjectBand(map, 1e-3, 0.04);
    FAIL() << "a 9 MB grid under a 1 MiB limit";
  } catch (const Error& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("test.bt"), std::string::npos) << m;
    EXPECT_NE(m.find("3000 x 3000"), std::string::npos) << m;
    EXPECT_NE(m.find("max_memory_mb"), std::string::npos) << m;
  }
  map.max_grid_bytes = 16 << 20;
  const environment::PlaneGrid g = environment::ProjectBand(map, 1e-3, 0.04);
  EXPECT_EQ(g.nx, 3000);
  EXPECT_TRUE(g.at(2999, 2999));
  EXPECT_FALSE(g.at(1, 1));
}

// The shared map at foot-bot height: a few hundred merged boxes that cover
// exactly the band's voxels.
TEST(EnvironmentPhysicsTest, TheSharedMapsBandMergesIntoFewBoxesCoveringItsVoxels) {
  SWARMSIM_NEED_SHARED_MAP(path, "geb079.bt");
  const EnvironmentMap map = environment::ReadOctomap(path, "geb079.bt", {});
  const double lo = 0.001, hi = 0.145;  // a foot-bot's height range, 1 mm in
  int64_t voxels = 0;
  for (const EnvironmentBox& b : map.boxes) {
    const int64_t side = std::lround((b.hi.x - b.lo.x) / 0.08);
    for (int64_t k = 0; k < side; ++k) {
      const double bottom = b.lo.z + k * 0.08;
      if (bottom + 0.08 > lo && bottom < hi) voxels += side * side;
    }
  }
  const auto boxes = environment::MergeBand3D(map, lo, hi);
  int64_t covered = 0;
  for (const EnvironmentBox& b : boxes)
    covered += std::lround((b.hi.x - b.lo.x) / 0.08) * std::lround((b.hi.y - b.lo.y) / 0.08) *
               std::lround((b.hi.z - b.lo.z) / 0.08);
  EXPECT_EQ(covered, voxels);
  EXPECT_LT(boxes.size() * 4, static_cast<size_t>(voxels));
  const auto rects = environment::MergeBand2D(map, lo, hi);
  EXPECT_LT(rects.size(), boxes.size());
  std::printf("geb079.bt, band z %.3f..%.3f m: %lld voxels, %zu boxes (3D), %zu rectangles (2D)\n",
              lo, hi, static_cast<long long>(voxels), boxes.size(), rects.size());
}

}  // namespace
}  // namespace swarmsim
