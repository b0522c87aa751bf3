// The mill module (modules/mill/module.cc) through a World: a mill cuts the
// voxels of a cuttable block whose centres lie in its volume, once; a
// disabled mill cuts nothing; of two mills the first takes a voxel both
// reach; what it records into the metrics and mill.csv.
#include "modules/mill/module.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "modules/mill/rows.h"
#include "tests/modules/module_world.h"

namespace swarmsim::mill {
namespace {

using testing::ModuleWorld;
using testing::ReadFile;
using testing::TempDir;

// A block of `size` cut into voxels of `resolution` (as the reader does).
CuttableRow Block(const Vec3& size, double resolution) {
  CuttableRow c;
  c.size = size;
  c.resolution = resolution;
  c.nx = VoxelsAlong(size.x, resolution);
  c.ny = VoxelsAlong(size.y, resolution);
  c.nz = VoxelsAlong(size.z, resolution);
  c.remaining = c.voxel_count();
  return c;
}

// A box mill `width` x `height` reaching `range` along its +z.
MillRow BoxMill(double width, double height, double range) {
  MillRow m;
  m.volume.kind = VolumeKind::kBox;
  m.volume.width = width;
  m.volume.height = height;
  m.volume.range = range;
  return m;
}

// A 10 cm cube of 1 cm voxels centred at the origin, and a box mill at the
// origin covering its upper half (z from 0 to 5 cm): 500 voxel centres.
struct HalfCut {
  ModuleWorld w;
  const CuttableRow block_row = Block({0.1, 0.1, 0.1}, 0.01);
  ObjectId block = w.Add("cuttable", "block", {}, {}, &block_row);
  const MillRow mill_row = BoxMill(0.1, 0.1, 0.05);
  ObjectId mill = w.Add("mill", "cutter", {}, {}, &mill_row);
  CuttableRow& cuttable() { return w.RowOf<CuttableRow>("cuttable", block); }
  MillRow& cutter() { return w.RowOf<MillRow>("mill", mill); }
};

TEST(MillModuleTest, AMillCutsTheVoxelsWhoseCentresAreInsideItOnce) {
  HalfCut s;
  ASSERT_EQ(s.cuttable().voxel_count(), 1000);
  ASSERT_EQ(s.w.Run(1), "");
  EXPECT_EQ(s.cuttable().remaining, 500);
  EXPECT_NE(s.cuttable().digest, 0u);
  EXPECT_NEAR(s.cutter().removed, 500 * 1e-6, 1e-15);
  EXPECT_NEAR(s.cutter().removed_total, 500 * 1e-6, 1e-15);
  // Nothing is left where it cuts: the next step removes nothing more.
  ASSERT_EQ(s.w.Run(1), "");
  EXPECT_EQ(s.cuttable().remaining, 500);
  EXPECT_EQ(s.cutter().removed, 0);
  EXPECT_NEAR(s.cutter().removed_total, 500 * 1e-6, 1e-15);
  // Moved down 2 cm, it takes two more layers.
  s.w.scene().SetLocalPose(s.mill, {{0, 0, -0.02}, {}});
  ASSERT_EQ(s.w.Run(1), "");
  EXPECT_EQ(s.cuttable().remaining, 300);
  EXPECT_NEAR(s.cutter().removed, 200 * 1e-6, 1e-15);
}

TEST(MillModuleTest, ADisabledMillCutsNothing) {
  HalfCut s;
  s.cutter().enabled = false;
  ASSERT_EQ(s.w.Run(2), "");
  EXPECT_EQ(s.cuttable().remaining, 1000);
  EXPECT_EQ(s.cuttable().digest, 0u);
  EXPECT_EQ(s.cutter().removed_total, 0);
}

// Two mills reaching the same voxels: the first (in row order) takes them,
// and the same cut gives the same digest whichever mills made it.
TEST(MillModuleTest, AVoxelTwoMillsReachGoesToTheFirst) {
  HalfCut s;
  const MillRow quarter = BoxMill(0.1, 0.1, 0.025);
  const ObjectId second = s.w.Add("mill", "second", {}, {}, &quarter);
  ASSERT_EQ(s.w.Run(1), "");
  EXPECT_EQ(s.cuttable().remaining, 500);
  EXPECT_NEAR(s.cutter().removed, 500 * 1e-6, 1e-15);
  EXPECT_EQ(s.w.RowOf<MillRow>("mill", second).removed, 0);
  const uint64_t digest = s.cuttable().digest;
  HalfCut alone;
  ASSERT_EQ(alone.w.Run(1), "");
  EXPECT_EQ(alone.cuttable().digest, digest);
}

TEST(MillModuleTest, RecordsMetricsAndWritesMillCsv) {
  HalfCut s;
  ASSERT_EQ(s.w.Run(1), "");
  double removed = NAN, remaining = NAN;
  for (const MetricSample& m : s.w.world().TakeMetrics()) {
    if (m.name == "cutter.removed") removed = m.value;
    if (m.name == "block.remaining") remaining = m.value;
  }
  EXPECT_NEAR(removed, 500e-6, 1e-15);
  EXPECT_NEAR(remaining, 500e-6, 1e-15);
  TempDir dir;
  s.w.world().WriteOutputs(dir.path());
  const std::string csv = ReadFile(dir.path() / "mill.csv");
  EXPECT_EQ(csv.substr(0, csv.find('\n')),
            "object,type,removed_m3,voxels,voxels_left,volume_left_m3");
  EXPECT_CONTAINS(csv, "/cutter,mill,0.0005,,,\n");
  EXPECT_CONTAINS(csv, "/block,cuttable,0.0005,1000,500,0.0005\n");
  bool listed = false;
  for (const OutputFile& f : s.w.world().ListOutputs()) listed |= f.path == "mill.csv";
  EXPECT_TRUE(listed);
}

// A block removed while mills run: the module forgets its voxels, and a
// new block in its place is whole.
TEST(MillModuleTest, ARemovedBlockIsForgotten) {
  HalfCut s;
  ASSERT_EQ(s.w.Run(1), "");
  s.w.scene().RemoveSubtree(s.block);
  ASSERT_EQ(s.w.Run(1), "");
  const CuttableRow fresh = Block({0.1, 0.1, 0.1}, 0.01);
  s.w.scene().SetLocalPose(s.mill, {{0, 0, 0.2}, {}});  // out of reach
  const ObjectId again = s.w.Add("cuttable", "block", {}, {}, &fresh);
  ASSERT_EQ(s.w.Run(1), "");
  EXPECT_EQ(s.w.RowOf<CuttableRow>("cuttable", again).remaining, 1000);
}

}  // namespace
}  // namespace swarmsim::mill
