// Reading OctoMap files into the environment map (octomap_map.cc): the
// shared real map against the counts of /work/shared/maps/README.md, its
// offset and z range, small hand-made .bt and .ot files, a missing file and
// an empty map.

#include "modules/environment/octomap_map.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>
#include <vector>

#include "framework/error.h"
#include "tests/framework/error_of.h"
#include "tests/modules/environment/octomap_files.h"
#include "tests/shared_maps.h"

namespace swarmsim::environment {
namespace {

namespace fs = std::filesystem;
using swarmsim::testing::ErrorOf;

using octomap_test::BinaryHeader;
using octomap_test::OctomapFileTest;
using octomap_test::OneVoxelBinary;
using octomap_test::OneVoxelFull;

TEST(OctomapMapTest, ReadsTheSharedMapAsItsReadmeSays) {
  SWARMSIM_NEED_SHARED_MAP(path, "geb079.bt");
  OctomapReport report;
  const EnvironmentMap map = ReadOctomap(path, "geb079.bt", {}, &report);
  EXPECT_EQ(report.nodes, 532566u);
  EXPECT_EQ(report.leaves, 428144u);
  EXPECT_EQ(report.occupied_leaves, 143729u);
  EXPECT_EQ(map.boxes.size(), 143729u);
  EXPECT_TRUE(report.warnings.empty());
  EXPECT_DOUBLE_EQ(map.resolution, 0.08);
  EXPECT_EQ(map.source, "geb079.bt");
  EXPECT_NEAR(map.lo.x, -8.00, 1e-9);
  EXPECT_NEAR(map.lo.y, -7.52, 1e-9);
  EXPECT_NEAR(map.lo.z, -0.32, 1e-9);
  EXPECT_NEAR(map.hi.x, 30.96, 1e-9);
  EXPECT_NEAR(map.hi.y, 7.44, 1e-9);
  EXPECT_NEAR(map.hi.z, 2.80, 1e-9);
  // Pruned leaves are cubes of 0.08 x 2^k m, on the voxel grid.
  std::map<long, int> sides;
  for (const EnvironmentBox& b : map.boxes) {
    const double side = b.hi.x - b.lo.x;
    ASSERT_NEAR(b.hi.y - b.lo.y, side, 1e-9);
    ASSERT_NEAR(b.hi.z - b.lo.z, side, 1e-9);
    ++sides[std::lround(side / 0.08)];
  }
  for (const auto& [voxels, count] : sides)
    EXPECT_TRUE(voxels == 1 || voxels == 2 || voxels == 4 || voxels == 8) << voxels;
}

TEST(OctomapMapTest, OffsetAndZRangeMoveAndCutTheMap) {
  SWARMSIM_NEED_SHARED_MAP(path, "geb079.bt");
  OctomapOptions options;
  options.offset = {1, 2, -0.5};
  const EnvironmentMap moved = ReadOctomap(path, "geb079.bt", options);
  ASSERT_EQ(moved.boxes.size(), 143729u);
  EXPECT_NEAR(moved.lo.x, -7.0, 1e-9);
  EXPECT_NEAR(moved.lo.z, -0.82, 1e-9);
  EXPECT_NEAR(moved.hi.y, 9.44, 1e-9);
  // z_range is in the world frame, on voxel centres: pruned leaves are cut.
  options.z_min = 0.0;
  options.z_max = 0.5;
  const EnvironmentMap cut = ReadOctomap(path, "geb079.bt", options);
  ASSERT_FALSE(cut.boxes.empty());
  EXPECT_LT(cut.boxes.size(), 143729u);
  size_t voxels_in_band = 0;
  for (const EnvironmentBox& b : moved.boxes)
    for (double z = b.lo.z + 0.04; z < b.hi.z; z += 0.08)
      voxels_in_band += (z >= 0 && z <= 0.5) ? std::lround((b.hi.x - b.lo.x) / 0.08) *
                                                   std::lround((b.hi.y - b.lo.y) / 0.08)
                                             : 0;
  size_t voxels_kept = 0;
  for (const EnvironmentBox& b : cut.boxes) {
    ASSERT_GE(b.lo.z + 0.04, 0.0);
    ASSERT_LE(b.hi.z - 0.04, 0.5);
    voxels_kept += std::lround((b.hi.x - b.lo.x) / 0.08) * std::lround((b.hi.y - b.lo.y) / 0.08) *
                   std::lround((b.hi.z - b.lo.z) / 0.08);
  }
  EXPECT_EQ(voxels_kept, voxels_in_band);
}

TEST_F(OctomapFileTest, ReadsAHandMadeBinaryFile) {
  OctomapReport report;
  const EnvironmentMap map = ReadOctomap(Write("one.bt", OneVoxelBinary()), "one.bt", {}, &report);
  ASSERT_EQ(map.boxes.size(), 1u);
  EXPECT_NEAR(map.boxes[0].lo.x, 0, 1e-12);
  EXPECT_NEAR(map.boxes[0].hi.z, 0.1, 1e-12);
  EXPECT_EQ(report.nodes, 17u);
}

TEST_F(OctomapFileTest, ReadsAnOtOfAnOcTreeAtItsThreshold) {
  const std::string file = Write("one.ot", OneVoxelFull(2.0f));  // p = 0.88
  EXPECT_EQ(ReadOctomap(file, "one.ot", {}).boxes.size(), 1u);
  OctomapOptions strict;
  strict.occupancy_threshold = 0.9;
  OctomapReport report;
  EXPECT_EQ(ReadOctomap(file, "one.ot", strict, &report).boxes.size(), 0u);
  ASSERT_EQ(report.warnings.size(), 1u);
  EXPECT_CONTAINS(report.warnings[0], "no occupied voxel");
}

TEST_F(OctomapFileTest, AMissingFileSaysSo) {
  EXPECT_CONTAINS(ErrorOf([&] { ReadOctomap(dir_ / "nope.bt", "nope.bt", {}); }),
                  "octomap nope.bt: no such file");
}

TEST_F(OctomapFileTest, AnEmptyMapIsAWarning) {
  OctomapReport report;
  const EnvironmentMap map =
      ReadOctomap(Write("free.bt", OneVoxelBinary(/*free leaf*/ 1)), "free.bt", {}, &report);
  EXPECT_TRUE(map.boxes.empty());
  ASSERT_EQ(report.warnings.size(), 1u);
  EXPECT_CONTAINS(report.warnings[0], "no occupied voxel");
}

}  // namespace
}  // namespace swarmsim::environment
