// The `distance` and `collision` object types (modules/collision/objects.cc):
// their keys read into rows with the errors a user gets, the check of
// their entities once the world is built, copies measuring afresh and a
// scaled threshold.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "modules/collision/rows.h"
#include "tests/modules/entry_reader.h"
#include "tests/modules/module_world.h"

namespace swarmsim::collision {
namespace {

using testing::EntryReader;
using testing::ErrorOf;
using testing::ModuleWorld;

EntryReader Between(std::vector<std::string> entities) {
  EntryReader entry;
  entry.strings["between"] = std::move(entities);
  return entry;
}

template <typename Row>
std::string ReadError(const char* type, const EntryReader& entry) {
  ModuleWorld w;
  Row row;
  return ErrorOf([&] { testing::ReadRow(w.scene(), type, entry, &row); });
}

TEST(CollisionObjectsTest, ReadsTheKeysOfBothTypes) {
  ModuleWorld w;
  EntryReader entry = Between({"/robot", "environment"});
  entry.numbers["threshold"] = {0.5};
  entry.numbers["record"] = {0};
  DistanceRow d;
  testing::ReadRow(w.scene(), "distance", entry, &d);
  EXPECT_EQ(d.entity[0], "/robot");
  EXPECT_EQ(d.entity[1], "environment");
  EXPECT_DOUBLE_EQ(d.threshold, 0.5);
  EXPECT_FALSE(d.record);
  EXPECT_EQ(d.where, "entry.between");

  EntryReader collision = Between({":/body", "everything_else"});
  collision.numbers["contacts"] = {12};
  CollisionRow c;
  testing::ReadRow(w.scene(), "collision", collision, &c);
  EXPECT_EQ(c.entity[1], "everything_else");
  EXPECT_EQ(c.contacts, 12);
  EXPECT_TRUE(c.record);
}

TEST(CollisionObjectsTest, BadEntriesAreErrorsNamingTheKey) {
  EXPECT_CONTAINS(ReadError<DistanceRow>("distance", Between({"/a"})),
                  "entry.between: 'between' takes two entities, [A, B] (got 1)");
  EXPECT_CONTAINS(ReadError<DistanceRow>("distance", Between({"robot", "/b"})),
                  "'robot' is neither an object path ('/...', ':...', './...') nor 'environment'");
  EXPECT_CONTAINS(ReadError<DistanceRow>("distance", Between({"environment", "/b"})),
                  "the first entity must be an object or a collection ('environment' may come "
                  "second)");
  EntryReader threshold = Between({"/a", "/b"});
  threshold.numbers["threshold"] = {0};
  EXPECT_CONTAINS(ReadError<DistanceRow>("distance", threshold),
                  "entry.threshold: must be a positive number");
  EntryReader contacts = Between({"/a", "/b"});
  contacts.numbers["contacts"] = {65};
  EXPECT_CONTAINS(ReadError<CollisionRow>("collision", contacts), "entry.contacts");
  EXPECT_CONTAINS(ReadError<CollisionRow>("collision", EntryReader{}), "entry.between");
}

TEST(CollisionObjectsTest, TheCheckRefusesTheSameObjectsOnBothSides) {
  ModuleWorld w;
  const ObjectId robot = w.scene().AddDummy("robot", {}, {});
  w.Box("body", robot, {}, {0.2, 0.2, 0.2});
  w.Box("wall", {}, {{2, 0, 0}, {}}, {0.1, 2, 1});
  DistanceRow row;
  row.entity[0] = "/robot";
  row.entity[1] = "/robot";
  row.where = "world.yaml:9:14";
  const ObjectId gap = w.Add("distance", "gap", {}, {}, &row);
  const ObjectTypeDescriptor& type =
      w.scene().type_descriptor(testing::TypeNamed(w.scene(), "distance"));
  EXPECT_EQ(ErrorOf([&] { type.check(w.scene(), gap, &row); }),
            "world.yaml:9:14: distance object /gap: '/robot' and '/robot' are the same objects: "
            "nothing to measure between them");
  row.entity[1] = "/wall";
  EXPECT_EQ(ErrorOf([&] { type.check(w.scene(), gap, &row); }), "");
  row.entity[1] = "environment";
  EXPECT_EQ(ErrorOf([&] { type.check(w.scene(), gap, &row); }), "");
}

// A model's copy measures afresh (no reading of its original's), and
// scaling it scales its threshold.
TEST(CollisionObjectsTest, CopiesMeasureAfreshAndThresholdsScale) {
  ModuleWorld w;
  const ObjectId model = w.scene().AddDummy("model", {}, {});
  DistanceRow row;
  row.entity[0] = "/a";
  row.entity[1] = "/b";
  row.threshold = 0.25;
  const ObjectId gap = w.Add("distance", "gap", model, {}, &row);
  DistanceRow& original = w.RowOf<DistanceRow>("distance", gap);
  original.found = true;
  original.distance = 0.1;
  const ObjectId copy = w.scene().DuplicateSubtree(model, {});
  const ObjectId copied = w.scene().children(copy).at(0);
  const DistanceRow& c = w.RowOf<DistanceRow>("distance", copied);
  EXPECT_FALSE(c.found);
  EXPECT_EQ(c.distance, INFINITY);
  EXPECT_EQ(c.entity[1], "/b");
  EXPECT_DOUBLE_EQ(c.threshold, 0.25);
  w.scene().ScaleSubtree(copy, 4);
  EXPECT_DOUBLE_EQ(w.RowOf<DistanceRow>("distance", copied).threshold, 1);
}

}  // namespace
}  // namespace swarmsim::collision
