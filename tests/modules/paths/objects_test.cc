// The `path` object type (modules/paths/objects.cc): its keys read into a
// row (points, interpolation, orientations, pauses, followers) with the
// errors a user gets, the check that followers are children, scaling that
// keeps copies sharing one curve, and the state hash following the
// position.
#include <gtest/gtest.h>

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

EntryReader Square() {
  EntryReader entry;
  entry.points["points"] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
  return entry;
}

std::string ReadError(const EntryReader& entry) {
  ModuleWorld w;
  PathRow row;
  return ErrorOf([&] { testing::ReadRow(w.scene(), kTypeName, entry, &row); });
}

TEST(PathObjectsTest, ReadsAPathsKeys) {
  ModuleWorld w;
  EntryReader entry = Square();
  entry.numbers["closed"] = {1};
  entry.numbers["velocity"] = {0.2};
  entry.numbers["start"] = {5};  // past the 4 m loop: wrapped
  entry.numbers["pauses"] = {0, 1, 0, 2};
  entry.numbers["yaw_deg"] = {0, 90, 180, 270};
  entry.strings["followers"] = {"cart", "cart2"};
  PathRow row;
  testing::ReadRow(w.scene(), kTypeName, entry, &row);
  EXPECT_TRUE(row.curve->closed());
  EXPECT_DOUBLE_EQ(row.curve->length(), 4);
  EXPECT_DOUBLE_EQ(row.velocity, 0.2);
  EXPECT_DOUBLE_EQ(row.position, 1);
  EXPECT_EQ(row.pauses, (std::vector<double>{0, 1, 0, 2}));
  EXPECT_EQ(row.followers, (std::vector<std::string>{"cart", "cart2"}));
  EXPECT_EQ(row.where, "entry.followers");
  ASSERT_EQ(row.curve->orientations().size(), 4u);
  EXPECT_NEAR(row.curve->PoseAt(1.5).q.Yaw(), 3 * M_PI / 4, 1e-12);
  EXPECT_EQ(row.curve->interpolation(), Interpolation::kLinear);
}

TEST(PathObjectsTest, BadPathsAreErrorsNamingTheKey) {
  EntryReader repeat;
  repeat.points["points"] = {{0, 0, 0}, {1, 0, 0}, {1, 0, 0}};
  EXPECT_CONTAINS(
      ReadError(repeat),
      "entry.points[2]: points[2] repeats points[1]: a path segment must have a length");
  EntryReader loop = Square();
  loop.points["points"].push_back({0, 0, 0});
  loop.numbers["closed"] = {1};
  EXPECT_CONTAINS(ReadError(loop), "entry.points[4]: the last point repeats the first");
  EntryReader both = Square();
  both.numbers["yaw_deg"] = {0, 0, 0, 0};
  both.points["orientations_deg"] = {{0, 0, 0}, {0, 0, 0}, {0, 0, 0}, {0, 0, 0}};
  EXPECT_CONTAINS(ReadError(both), "entry.orientations_deg: give 'yaw_deg' or 'orientations_deg'");
  EntryReader few = Square();
  few.points["orientations_deg"] = {{0, 0, 0}, {0, 0, 0}, {0, 0, 0}, {0, 0, 0}, {0, 0, 0}};
  EXPECT_CONTAINS(ReadError(few), "needs one [roll, pitch, yaw] per point (4), got 5");
  EntryReader pauses = Square();
  pauses.numbers["pauses"] = {1, 2};
  EXPECT_CONTAINS(ReadError(pauses), "entry.pauses");
  EntryReader negative = Square();
  negative.numbers["pauses"] = {1, -1, 0, 0};
  EXPECT_CONTAINS(ReadError(negative), "entry.pauses: must be a non-negative number");
  EntryReader interpolation = Square();
  interpolation.strings["interpolation"] = {"smoth"};
  EXPECT_CONTAINS(ReadError(interpolation), "entry.interpolation: unknown 'smoth'");
  EXPECT_CONTAINS(ReadError(EntryReader{}), "entry.points: is required");
}

// A follower that is not a child of its path is an error once the world is
// built, naming where `followers` was written.
TEST(PathObjectsTest, AFollowerMustBeAChildOfThePath) {
  ModuleWorld w;
  PathRow row;
  row.curve = std::make_shared<const PathCurve>(std::vector<Vec3>{{0, 0, 0}, {1, 0, 0}},
                                                Interpolation::kLinear, false);
  row.followers = {"cart"};
  row.where = "world.yaml:7:18";
  const ObjectId path = w.Add(kTypeName, "rail", {}, {}, &row);
  w.Box("cart", {}, {}, {0.1, 0.1, 0.1});  // a sibling, not a child
  const ObjectTypeDescriptor& type =
      w.scene().type_descriptor(testing::TypeNamed(w.scene(), kTypeName));
  EXPECT_EQ(ErrorOf([&] { type.check(w.scene(), path, &w.RowOf<PathRow>(kTypeName, path)); }),
            "world.yaml:7:18: path /rail: follower 'cart' is not a child of the path");
  w.Box("cart", path, {}, {0.1, 0.1, 0.1});
  EXPECT_EQ(ErrorOf([&] { type.check(w.scene(), path, &w.RowOf<PathRow>(kTypeName, path)); }), "");
}

// Scaling a model by 2 doubles its path's points, position and speed; two
// copies scaled in one call share one scaled curve.
TEST(PathObjectsTest, ScalingDoublesThePathAndCopiesShareTheCurve) {
  ModuleWorld w;
  const ObjectId root = w.scene().AddDummy("model", {}, {});
  PathRow row;
  row.curve = std::make_shared<const PathCurve>(std::vector<Vec3>{{0, 0, 0}, {1, 0, 0}},
                                                Interpolation::kLinear, false);
  row.position = 0.25;
  row.velocity = 0.5;
  const ObjectId a = w.Add(kTypeName, "a", root, {}, &row);
  const ObjectId b = w.Add(kTypeName, "b", root, {}, &row);
  w.scene().ScaleSubtree(root, 2);
  const PathRow& ra = w.RowOf<PathRow>(kTypeName, a);
  const PathRow& rb = w.RowOf<PathRow>(kTypeName, b);
  EXPECT_DOUBLE_EQ(ra.curve->length(), 2);
  EXPECT_DOUBLE_EQ(ra.position, 0.5);
  EXPECT_DOUBLE_EQ(ra.velocity, 1);
  EXPECT_EQ(ra.curve, rb.curve);
  EXPECT_NE(ra.curve, row.curve);
}

TEST(PathObjectsTest, TheStateHashFollowsThePosition) {
  ModuleWorld w;
  PathRow row;
  row.curve = std::make_shared<const PathCurve>(std::vector<Vec3>{{0, 0, 0}, {1, 0, 0}},
                                                Interpolation::kLinear, false);
  const ObjectId path = w.Add(kTypeName, "rail", {}, {}, &row);
  ASSERT_EQ(w.Run(0), "");
  const uint64_t before = w.world().StateHash();
  w.RowOf<PathRow>(kTypeName, path).position = 0.5;
  EXPECT_NE(w.world().StateHash(), before);
}

}  // namespace
}  // namespace swarmsim::paths
