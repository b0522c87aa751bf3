// The `graph` object type (modules/graphs/objects.cc): its keys read into a
// row with the errors a user gets, the check that every stream's object
// exists and has the right type, and copies recording afresh.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "modules/graphs/rows.h"
#include "tests/modules/entry_reader.h"
#include "tests/modules/module_world.h"

namespace swarmsim::graphs {
namespace {

using testing::EntryReader;
using testing::ErrorOf;
using testing::ModuleWorld;

EntryReader Streams(std::vector<std::string> streams) {
  EntryReader entry;
  entry.strings["streams"] = std::move(streams);
  return entry;
}

std::string ReadError(const EntryReader& entry) {
  ModuleWorld w;
  GraphRow row;
  return ErrorOf([&] { testing::ReadRow(w.scene(), "graph", entry, &row); });
}

TEST(GraphObjectsTest, ReadsAGraphsKeys) {
  ModuleWorld w;
  EntryReader entry = Streams({"position /body", "speed = script"});
  entry.numbers["every"] = {5};
  entry.numbers["buffer"] = {1000};
  entry.numbers["cyclic"] = {1};
  entry.numbers["png"] = {0};
  entry.strings["title"] = {"Body"};
  GraphRow row;
  testing::ReadRow(w.scene(), "graph", entry, &row);
  ASSERT_EQ(row.streams.size(), 4u);  // x, y, z and the script's
  EXPECT_EQ(row.streams[3].name, "speed");
  EXPECT_EQ(row.kind, GraphKind::kTime);
  EXPECT_EQ(row.every, 5);
  EXPECT_EQ(row.buffer, 1000);
  EXPECT_TRUE(row.cyclic);
  EXPECT_FALSE(row.png);
  EXPECT_EQ(row.title, "Body");
  EXPECT_EQ(row.where, "entry.streams");
  ASSERT_EQ(row.script_values.size(), 4u);
  EXPECT_TRUE(std::isnan(row.script_values[3]));

  EntryReader xyz = Streams({"position /body"});
  xyz.strings["kind"] = {"xyz"};
  GraphRow curve;
  testing::ReadRow(w.scene(), "graph", xyz, &curve);
  EXPECT_EQ(curve.kind, GraphKind::kXyz);
  EXPECT_EQ(curve.streams.size(), 3u);
}

TEST(GraphObjectsTest, BadGraphsAreErrorsNamingTheKey) {
  EXPECT_CONTAINS(ReadError(EntryReader{}), "entry.streams: is required");
  EXPECT_CONTAINS(ReadError(Streams({})), "entry.streams: a graph needs at least one stream");
  EXPECT_CONTAINS(ReadError(Streams({"positon /body x"})),
                  "entry.streams: stream 'positon /body x': unknown stream kind 'positon'");
  EXPECT_CONTAINS(ReadError(Streams({"a = script", "a = position /b x"})),
                  "entry.streams: two streams are named 'a'; name one of them");
  EntryReader xy = Streams({"position /body"});
  xy.strings["kind"] = {"xy"};
  EXPECT_CONTAINS(ReadError(xy), "a kind: xy graph takes 2 streams (x, y), got 3");
  EntryReader kind = Streams({"script a"});
  kind.strings["kind"] = {"timeline"};
  EXPECT_CONTAINS(ReadError(kind), "entry.kind: unknown 'timeline'");
  EntryReader every = Streams({"script a"});
  every.numbers["every"] = {0};
  EXPECT_CONTAINS(ReadError(every), "entry.every: must be an integer from 1 to 1000000");
}

TEST(GraphObjectsTest, TheCheckNamesAStreamWhoseObjectIsMissingOrWrong) {
  ModuleWorld w;
  w.Box("body", {}, {}, {0.1, 0.1, 0.1});
  GraphRow row;
  ParseStream("position /body x", &row.streams);
  ParseStream("hip = joint /body", &row.streams);
  row.where = "world.yaml:12:14";
  const ObjectId graph = w.Add("graph", "g", {}, {}, &row);
  const ObjectTypeDescriptor& type =
      w.scene().type_descriptor(testing::TypeNamed(w.scene(), "graph"));
  EXPECT_EQ(ErrorOf([&] { type.check(w.scene(), graph, &row); }),
            "world.yaml:12:14: graph /g: stream 'hip': '/body' is a shape, not a joint");
  GraphRow fine;
  ParseStream("position /body x", &fine.streams);
  ParseStream("script speed", &fine.streams);
  EXPECT_EQ(ErrorOf([&] { type.check(w.scene(), graph, &fine); }), "");
}

// A model's copy records afresh: its settings, not the values its
// original's scripts set.
TEST(GraphObjectsTest, ACopyKeepsTheSettingsButNotTheScriptValues) {
  ModuleWorld w;
  const ObjectId root = w.scene().AddDummy("model", {}, {});
  GraphRow row;
  ParseStream("script speed", &row.streams);
  row.every = 7;
  const ObjectId graph = w.Add("graph", "g", root, {}, &row);
  w.RowOf<GraphRow>("graph", graph).script_values = {3.5};
  const ObjectId copy = w.scene().DuplicateSubtree(root, {});
  const ObjectId copied = w.scene().children(copy).at(0);
  const GraphRow& c = w.RowOf<GraphRow>("graph", copied);
  EXPECT_EQ(c.every, 7);
  ASSERT_EQ(c.script_values.size(), 1u);
  EXPECT_TRUE(std::isnan(c.script_values[0]));
}

}  // namespace
}  // namespace swarmsim::graphs
