// The collision module (modules/collision/module.cc) through a World:
// distance and collision objects computed at the start and after each
// step's physics, thresholds, what they record into the metrics, objects
// that move, and entities that name nothing.
#include "modules/collision/module.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "modules/collision/rows.h"
#include "tests/modules/module_world.h"

namespace swarmsim::collision {
namespace {

using testing::ModuleWorld;

// Two unit cubes, /a at the origin and /b at x = 3 (facing faces 2 m apart);
// b is a robot, so that it may move (static scene shapes are fixed).
struct TwoCubes {
  ModuleWorld w;
  ObjectId a = w.Box("a", {}, {}, {1, 1, 1});
  ObjectId b = w.Box("b", {}, {{3, 0, 0}, {}}, {1, 1, 1});
  TwoCubes() { w.scene().MakeModelInstance(b, "cube", "b"); }

  ObjectId Distance(const std::string& name, double threshold = INFINITY, bool record = true) {
    DistanceRow row;
    row.entity[0] = "/a";
    row.entity[1] = "/b";
    row.threshold = threshold;
    row.record = record;
    return w.Add("distance", name, {}, {}, &row);
  }
  ObjectId Collision(const std::string& name, int contacts) {
    CollisionRow row;
    row.entity[0] = "/a";
    row.entity[1] = "/b";
    row.contacts = contacts;
    return w.Add("collision", name, {}, {}, &row);
  }
  DistanceRow& distance(ObjectId id) { return w.RowOf<DistanceRow>("distance", id); }
  CollisionRow& collision(ObjectId id) { return w.RowOf<CollisionRow>("collision", id); }
};

TEST(CollisionModuleTest, ADistanceObjectMeasuresTheGapWithItsClosestPoints) {
  TwoCubes s;
  const ObjectId gap = s.Distance("gap");
  ASSERT_EQ(s.w.Run(0), "");  // computed at the start already
  const DistanceRow& d = s.distance(gap);
  ASSERT_TRUE(d.found);
  EXPECT_NEAR(d.distance, 2, 1e-6);
  EXPECT_NEAR(d.p1.x, 0.5, 1e-6);
  EXPECT_NEAR(d.p2.x, 2.5, 1e-6);
  EXPECT_EQ(d.o1, s.a);
  EXPECT_EQ(d.o2, s.b);
  // After b moves, the next step's reading follows.
  s.w.scene().SetLocalPose(s.b, {{1.75, 0, 0}, {}});
  ASSERT_EQ(s.w.Run(1), "");
  EXPECT_NEAR(s.distance(gap).distance, 0.75, 1e-6);
}

TEST(CollisionModuleTest, NothingBeyondTheThresholdIsMeasured) {
  TwoCubes s;
  const ObjectId gap = s.Distance("gap", 1.5);
  ASSERT_EQ(s.w.Run(1), "");
  EXPECT_FALSE(s.distance(gap).found);
  EXPECT_EQ(s.distance(gap).distance, INFINITY);
  EXPECT_TRUE(s.distance(gap).o1.IsNull());
}

TEST(CollisionModuleTest, ACollisionObjectSeesOverlapsAndKeepsItsContacts) {
  TwoCubes s;
  const ObjectId touch = s.Collision("touch", 8);
  ASSERT_EQ(s.w.Run(1), "");
  EXPECT_FALSE(s.collision(touch).colliding);
  EXPECT_TRUE(s.collision(touch).contact_points.empty());
  s.w.scene().SetLocalPose(s.b, {{0.9, 0, 0}, {}});  // 0.1 m into a
  ASSERT_EQ(s.w.Run(1), "");
  const CollisionRow& c = s.collision(touch);
  EXPECT_TRUE(c.colliding);
  EXPECT_EQ(c.o1, s.a);
  EXPECT_EQ(c.o2, s.b);
  ASSERT_FALSE(c.contact_points.empty());
  EXPECT_LE(c.contact_points.size(), 8u);
  for (const Vec3& p : c.contact_points) {  // inside the overlap
    EXPECT_GE(p.x, 0.4 - 1e-6);
    EXPECT_LE(p.x, 0.5 + 1e-6);
  }
}

// The metrics of a step: NAME.distance and the closest points, NAME.colliding
// and the contact count; none for an object with record off.
TEST(CollisionModuleTest, RecordedObjectsWriteTheirMetrics) {
  TwoCubes s;
  s.Distance("gap");
  s.Distance("quiet", INFINITY, /*record=*/false);
  s.Collision("touch", 4);
  ASSERT_EQ(s.w.Run(1), "");
  std::vector<std::string> names;
  double gap = NAN, x2 = NAN, colliding = NAN;
  for (const MetricSample& m : s.w.world().TakeMetrics()) {
    names.push_back(m.name);
    if (m.name == "gap.distance") gap = m.value;
    if (m.name == "gap.x2") x2 = m.value;
    if (m.name == "touch.colliding") colliding = m.value;
    EXPECT_EQ(m.step, 1);
  }
  EXPECT_EQ(names,
            (std::vector<std::string>{"gap.distance", "gap.x1", "gap.y1", "gap.z1", "gap.x2",
                                      "gap.y2", "gap.z2", "touch.colliding", "touch.contacts"}));
  EXPECT_NEAR(gap, 2, 1e-6);
  EXPECT_NEAR(x2, 2.5, 1e-6);
  EXPECT_EQ(colliding, 0);
}

TEST(CollisionModuleTest, EntitiesThatNameNothingAreErrorsAtTheStart) {
  TwoCubes s;
  DistanceRow row;
  row.entity[0] = "/a";
  row.entity[1] = "/nothing";
  row.where = "world.yaml:3:12";
  s.w.Add("distance", "gap", {}, {}, &row);
  const std::string error = s.w.Run(0);
  EXPECT_CONTAINS(error, "world.yaml:3:12: distance object /gap");
  EXPECT_CONTAINS(error, "/nothing");
}

}  // namespace
}  // namespace swarmsim::collision
