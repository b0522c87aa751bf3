// The `mill` and `cuttable` object types (modules/mill/objects.cc): their
// keys read into rows (a size only where the volume has it, half-angles in
// range, a block's voxel grid and its limit) with the errors a user gets,
// copies starting afresh, and scaling.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "modules/mill/rows.h"
#include "tests/modules/entry_reader.h"
#include "tests/modules/module_world.h"

namespace swarmsim::mill {
namespace {

using testing::EntryReader;
using testing::ErrorOf;
using testing::ModuleWorld;

template <typename Row>
std::string ReadError(const char* type, const EntryReader& entry) {
  ModuleWorld w;
  Row row;
  return ErrorOf([&] { testing::ReadRow(w.scene(), type, entry, &row); });
}

TEST(MillObjectsTest, ReadsAMillsVolume) {
  ModuleWorld w;
  EntryReader cone;
  cone.strings["volume"] = {"cone"};
  cone.numbers["range"] = {0.2};
  cone.numbers["angle_deg"] = {45};
  cone.numbers["enabled"] = {0};
  MillRow m;
  testing::ReadRow(w.scene(), "mill", cone, &m);
  EXPECT_EQ(m.volume.kind, VolumeKind::kCone);
  EXPECT_DOUBLE_EQ(m.volume.range, 0.2);
  EXPECT_NEAR(m.volume.angle, M_PI / 4, 1e-15);
  EXPECT_FALSE(m.enabled);
  EXPECT_TRUE(m.record);

  EntryReader box;
  box.strings["volume"] = {"box"};
  box.numbers["width"] = {0.3};
  box.numbers["height"] = {0.1};
  MillRow b;
  testing::ReadRow(w.scene(), "mill", box, &b);
  EXPECT_EQ(b.volume.kind, VolumeKind::kBox);
  EXPECT_DOUBLE_EQ(b.volume.width, 0.3);
  EXPECT_DOUBLE_EQ(b.volume.height, 0.1);
  EXPECT_DOUBLE_EQ(b.volume.range, 0.05);  // the default
}

TEST(MillObjectsTest, ASizeOfAnotherVolumeOrAnAngleOutOfRangeIsAnError) {
  EntryReader radius;
  radius.strings["volume"] = {"box"};
  radius.numbers["radius"] = {0.1};
  EXPECT_CONTAINS(ReadError<MillRow>("mill", radius),
                  "entry.radius: 'radius' applies to cylinder mills only (this is a box)");
  EntryReader thickness;  // the default volume: a cylinder
  thickness.numbers["thickness"] = {0.1};
  EXPECT_CONTAINS(ReadError<MillRow>("mill", thickness),
                  "'thickness' applies to disc mills only (this is a cylinder)");
  EntryReader cone;
  cone.strings["volume"] = {"cone"};
  cone.numbers["angle_deg"] = {90};
  EXPECT_CONTAINS(ReadError<MillRow>("mill", cone),
                  "entry.angle_deg: 'angle_deg' must be above 0 and below 90 degrees (got 90)");
  EntryReader disc;
  disc.strings["volume"] = {"disc"};
  disc.numbers["angle_deg"] = {90};
  EXPECT_EQ(ReadError<MillRow>("mill", disc), "");  // a disc may reach 90
  disc.numbers["angle_deg"] = {0};
  EXPECT_CONTAINS(ReadError<MillRow>("mill", disc),
                  "'angle_deg' must be above 0 and up to 90 degrees (got 0)");
  EntryReader kind;
  kind.strings["volume"] = {"sphere"};
  EXPECT_CONTAINS(ReadError<MillRow>("mill", kind), "entry.volume: unknown 'sphere'");
}

TEST(MillObjectsTest, ACuttablesGridIsCountedFromItsSizeAndResolution) {
  ModuleWorld w;
  EntryReader entry;
  entry.numbers["size"] = {0.2, 0.1, 0.05};
  entry.numbers["resolution"] = {0.01};
  CuttableRow c;
  testing::ReadRow(w.scene(), "cuttable", entry, &c);
  EXPECT_EQ(c.nx, 20u);
  EXPECT_EQ(c.ny, 10u);
  EXPECT_EQ(c.nz, 5u);
  EXPECT_EQ(c.remaining, 1000);
  // A side shorter than the resolution is still one voxel; one that does
  // not divide is rounded up.
  entry.numbers["size"] = {0.005, 0.025, 0.1};
  testing::ReadRow(w.scene(), "cuttable", entry, &c);
  EXPECT_EQ(c.nx, 1u);
  EXPECT_EQ(c.ny, 3u);
  EXPECT_EQ(c.nz, 10u);
  EXPECT_EQ(c.remaining, 30);
  entry.numbers["size"] = {1, 1, 1};
  entry.numbers["resolution"] = {0.001};
  EXPECT_CONTAINS(ReadError<CuttableRow>("cuttable", entry),
                  "entry.resolution: the block would have 1000 x 1000 x 1000 = 1000000000 voxels, "
                  "more than 50000000");
}

TEST(MillObjectsTest, CopiesStartAfreshAndScaleWithTheirModel) {
  ModuleWorld w;
  const ObjectId model = w.scene().AddDummy("model", {}, {});
  MillRow m;
  m.volume.kind = VolumeKind::kCylinder;
  m.volume.radius = 0.02;
  m.removed = 1;
  m.removed_total = 2;
  w.Add("mill", "mill", model, {}, &m);
  CuttableRow c;
  c.remaining = 10;  // of 8000: cut
  c.digest = 77;
  w.Add("cuttable", "block", model, {}, &c);
  const ObjectId copy = w.scene().DuplicateSubtree(model, {});
  const std::vector<ObjectId> parts = w.scene().children(copy);
  ASSERT_EQ(parts.size(), 2u);
  const MillRow& mill = w.RowOf<MillRow>("mill", parts[0]);
  EXPECT_EQ(mill.removed, 0);
  EXPECT_EQ(mill.removed_total, 0);
  EXPECT_DOUBLE_EQ(mill.volume.radius, 0.02);
  const CuttableRow& block = w.RowOf<CuttableRow>("cuttable", parts[1]);
  EXPECT_EQ(block.remaining, 8000);
  EXPECT_EQ(block.digest, 0u);
  w.scene().ScaleSubtree(copy, 2);
  EXPECT_DOUBLE_EQ(w.RowOf<MillRow>("mill", parts[0]).volume.radius, 0.04);
  const CuttableRow& scaled = w.RowOf<CuttableRow>("cuttable", parts[1]);
  EXPECT_DOUBLE_EQ(scaled.size.x, 0.2);
  EXPECT_DOUBLE_EQ(scaled.resolution, 0.01);
  EXPECT_EQ(scaled.nx, 20u);  // the grid stays
}

}  // namespace
}  // namespace swarmsim::mill
