// The `planning_task` object type (modules/planning/objects.cc): its keys
// read into a row (space, robot, obstacles, planar or 3D bounds, sizes,
// time limit) with the errors a user gets, the check of its paths, copies
// keeping the settings only, and scaling.
#include <gtest/gtest.h>

#include <string>

#include "modules/planning/rows.h"
#include "tests/modules/entry_reader.h"
#include "tests/modules/module_world.h"

namespace swarmsim::planning {
namespace {

using testing::EntryReader;
using testing::ErrorOf;
using testing::ModuleWorld;

std::string ReadError(const EntryReader& entry) {
  ModuleWorld w;
  PlanningTaskRow row;
  return ErrorOf([&] { testing::ReadRow(w.scene(), kTypeName, entry, &row); });
}

TEST(PlanningObjectsTest, ReadsATasksKeys) {
  ModuleWorld w;
  EntryReader entry;
  entry.strings["space"] = {"dubins"};
  entry.strings["robot"] = {":/chassis"};
  entry.strings["obstacles"] = {"everything_else"};
  entry.numbers["bounds"] = {-5, -4, 5, 4};
  entry.numbers["turning_radius"] = {1.5};
  entry.numbers["resolution"] = {0.1};
  entry.numbers["time_limit"] = {2};
  PlanningTaskRow t;
  testing::ReadRow(w.scene(), kTypeName, entry, &t);
  EXPECT_EQ(t.space, Space::kDubins);
  EXPECT_EQ(t.robot, ":/chassis");
  EXPECT_EQ(t.obstacles, "everything_else");
  EXPECT_TRUE(t.has_bounds);
  EXPECT_EQ(t.lo, (Vec3{-5, -4, 0}));
  EXPECT_EQ(t.hi, (Vec3{5, 4, 0}));
  EXPECT_DOUBLE_EQ(t.turning_radius, 1.5);
  EXPECT_DOUBLE_EQ(t.resolution, 0.1);
  EXPECT_DOUBLE_EQ(t.time_limit, 2);
  EXPECT_EQ(t.where, "entry.robot");

  EntryReader se3;
  se3.strings["space"] = {"se3"};
  se3.numbers["bounds"] = {-1, -2, 0, 1, 2, 3};
  PlanningTaskRow s;
  testing::ReadRow(w.scene(), kTypeName, se3, &s);
  EXPECT_EQ(s.space, Space::kSe3);
  EXPECT_EQ(s.lo, (Vec3{-1, -2, 0}));
  EXPECT_EQ(s.hi, (Vec3{1, 2, 3}));
  EXPECT_EQ(s.where, "entry.space");
}

TEST(PlanningObjectsTest, BadTasksAreErrorsNamingTheKey) {
  EntryReader space;
  space.strings["space"] = {"se4"};
  EXPECT_CONTAINS(ReadError(space), "entry.space: unknown 'se4'");
  EntryReader robot;
  robot.strings["robot"] = {"chassis"};
  EXPECT_CONTAINS(ReadError(robot),
                  "entry.robot: 'chassis' is not an object path ('/...', ':...', './...')");
  EntryReader obstacles;
  obstacles.strings["obstacles"] = {"walls"};
  EXPECT_CONTAINS(ReadError(obstacles),
                  "entry.obstacles: 'walls' is neither an object path ('/...', ':...', './...') "
                  "nor 'environment' or 'everything_else'");
  EntryReader flat;
  flat.numbers["bounds"] = {1, 0, -1, 2};
  EXPECT_CONTAINS(
      ReadError(flat),
      "entry.bounds: each minimum must be below its maximum ([xmin, ymin, xmax, ymax])");
  EntryReader count;
  count.numbers["bounds"] = {0, 0, 1, 1, 1, 1};  // six numbers for a planar space
  EXPECT_CONTAINS(ReadError(count), "entry.bounds");
  EntryReader time;
  time.numbers["time_limit"] = {0};
  EXPECT_CONTAINS(ReadError(time), "entry.time_limit: must be a positive number of seconds");
}

TEST(PlanningObjectsTest, TheCheckNamesARobotOrObstaclesThatMatchNothing) {
  ModuleWorld w;
  const ObjectId bot = w.Robot("bot", {});
  PlanningTaskRow row;
  row.robot = ":";
  row.obstacles = "/walls";
  row.where = "world.yaml:8:12";
  const ObjectId task = w.Add(kTypeName, "task", bot, {}, &row);
  const ObjectTypeDescriptor& type =
      w.scene().type_descriptor(testing::TypeNamed(w.scene(), kTypeName));
  const std::string error = ErrorOf([&] { type.check(w.scene(), task, &row); });
  EXPECT_CONTAINS(error, "world.yaml:8:12: planning task /bot/task");
  EXPECT_CONTAINS(error, "/walls");
  w.Box("walls", {}, {}, {1, 1, 1});
  EXPECT_EQ(ErrorOf([&] { type.check(w.scene(), task, &row); }), "");
}

// A copy plans afresh (no result, no path of its own yet) and scaling its
// model scales its lengths.
TEST(PlanningObjectsTest, ACopyKeepsTheSettingsOnlyAndLengthsScale) {
  ModuleWorld w;
  const ObjectId model = w.scene().AddDummy("model", {}, {});
  PlanningTaskRow row;
  row.space = Space::kReedsShepp;
  row.turning_radius = 0.8;
  row.resolution = 0.02;
  row.status = PlanStatus::kSolved;
  row.reason = "solved";
  row.iterations = 99;
  row.path = model;
  w.Add(kTypeName, "task", model, {}, &row);
  const ObjectId copy = w.scene().DuplicateSubtree(model, {});
  const ObjectId copied = w.scene().children(copy).at(0);
  const PlanningTaskRow& c = w.RowOf<PlanningTaskRow>(kTypeName, copied);
  EXPECT_EQ(c.space, Space::kReedsShepp);
  EXPECT_EQ(c.status, PlanStatus::kNone);
  EXPECT_EQ(c.iterations, 0);
  EXPECT_TRUE(c.path.IsNull());
  w.scene().ScaleSubtree(copy, 2);
  const PlanningTaskRow& scaled = w.RowOf<PlanningTaskRow>(kTypeName, copied);
  EXPECT_DOUBLE_EQ(scaled.turning_radius, 1.6);
  EXPECT_DOUBLE_EQ(scaled.resolution, 0.04);
}

}  // namespace
}  // namespace swarmsim::planning
