// The paths module (modules/paths/module.cc) through a World: a path's
// followers placed at its start, carried along it at its velocity each
// actuate phase keeping their offsets, clamped at an open path's end,
// wrapped around a closed one, stopping at paused points, and moved to a
// requested position.
#include "modules/paths/module.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <vector>

#include "modules/graphs/rows.h"
#include "modules/paths/curve.h"
#include "modules/paths/rows.h"
#include "modules/proximity/proximity_sensor.h"
#include "tests/modules/module_world.h"

namespace swarmsim::paths {
namespace {

using testing::ModuleWorld;

// Steps of 1/8 s, so that positions add up exactly.
constexpr double kStep = 0.125;

struct PathScene {
  ModuleWorld w{"kinematic", 1, kStep};
  ObjectId path, rider;
  std::shared_ptr<const PathCurve> curve;

  // A path along `points` whose child `rider` (a box 0.2 m above the
  // curve's frame) follows it at `velocity`.
  PathScene(std::vector<Vec3> points, bool closed, double velocity, double start = 0,
            std::vector<double> pauses = {}) {
    curve = std::make_shared<const PathCurve>(std::move(points), Interpolation::kLinear, closed);
    PathRow row;
    row.curve = curve;
    row.velocity = velocity;
    row.position = start;
    row.pauses = std::move(pauses);
    row.followers = {"rider"};
    path = w.Add(kTypeName, "path", {}, {{1, 2, 0}, {}}, &row);
    rider = w.Box("rider", path, {{0, 0, 0.2}, {}}, {0.1, 0.1, 0.1});
  }
  PathRow& row() { return w.RowOf<PathRow>(kTypeName, path); }
  // The rider's pose in the path's frame.
  Pose X_PR() { return w.scene().local_pose(rider); }
};

void ExpectNear(const Vec3& a, const Vec3& b, double tol) {
  EXPECT_NEAR(a.x, b.x, tol);
  EXPECT_NEAR(a.y, b.y, tol);
  EXPECT_NEAR(a.z, b.z, tol);
}

TEST(PathsModuleTest, StartPlacesTheFollowersAtTheStartKeepingTheirOffsets) {
  PathScene s({{0, 0, 0}, {2, 0, 0}, {2, 2, 0}}, false, 0, /*start=*/3);
  EXPECT_EQ(s.w.Run(0), "");
  // 3 m along: 1 m up the second leg, x along +y, the offset 0.2 m up.
  ExpectNear(s.X_PR().p, {2, 1, 0.2}, 1e-12);
  EXPECT_NEAR(s.X_PR().q.Yaw(), M_PI / 2, 1e-12);
  // In the world, once a step has run: the path's own pose composed.
  ASSERT_EQ(s.w.Run(1), "");
  ExpectNear(s.w.scene().world_pose(s.rider).p, {3, 3, 0.2}, 1e-12);
}

// A follower outside any robot carrying a static shape is sensed where the
// path has put it (the static index follows it), not where the file did:
// a robot's sensor across the path sees the rider pass, and only then.
TEST(PathsModuleTest, AStaticShapeRidingAPathIsSensedWhereItGoes) {
  PathScene s({{0, 0, 0}, {2, 0, 0}}, false, 0.5);  // the rider at x = 1 + n / 16 after n steps
  const ObjectId bot = s.w.Robot("bot", {{2.5, 0, 0}, {}});
  ProximitySensorData ray;
  ray.settings.Edit().range = 5;
  const ObjectId eye = proximity::AddSensor(
      &s.w.scene(), "eye", bot, {{0, 0, 0.2}, Quat::FromAxisAngle({1, 0, 0}, -M_PI / 2)},
      ray);  // looking along +y, across the path
  ASSERT_EQ(s.w.Run(1), "");
  EXPECT_FALSE(proximity::Sensor(s.w.scene(), eye).detected);
  ASSERT_EQ(s.w.Run(24), "");  // sensed as step 24 left it: at x = 2.5
  EXPECT_TRUE(proximity::Sensor(s.w.scene(), eye).detected);
  EXPECT_NEAR(proximity::Sensor(s.w.scene(), eye).distance, 1.95, 1e-9);
  EXPECT_EQ(proximity::Sensor(s.w.scene(), eye).detected_object, s.rider);
  ASSERT_EQ(s.w.Run(8), "");  // gone by, at x = 3
  EXPECT_FALSE(proximity::Sensor(s.w.scene(), eye).detected);
}

// What observes the start (a graph's step-0 sample here; the recording's
// and the video's first frame alike) sees the followers where the path put
// them, not where the file did: modules that only observe start last, and
// the start places the followers in the world.
TEST(PathsModuleTest, TheStartsObserversSeeTheFollowersWhereThePathPutThem) {
  PathScene s({{0, 0, 0}, {2, 0, 0}}, false, 0.5, /*start=*/1);
  graphs::GraphRow row;
  graphs::ParseStream("position /path/rider x", &row.streams);
  row.png = false;
  s.w.Add("graph", "trace", {}, {}, &row);
  ASSERT_EQ(s.w.Run(1), "");
  testing::TempDir dir;
  s.w.world().WriteOutputs(dir.path());
  // The path's frame at x = 1, its rider 1 m along: x = 2 at time 0, 2.0625 after a step.
  EXPECT_EQ(testing::ReadFile(dir.path() / "graphs" / "trace.csv"),
            "time,position /path/rider x\n0,2\n0.125,2.0625\n");
}

TEST(PathsModuleTest, FollowersMoveAtTheVelocityAndStopAtAnOpenPathsEnd) {
  PathScene s({{0, 0, 0}, {2, 0, 0}}, false, 0.5);
  EXPECT_EQ(s.w.Run(8), "");  // 1 s
  EXPECT_NEAR(s.row().position, 0.5, 1e-12);
  ExpectNear(s.X_PR().p, {0.5, 0, 0.2}, 1e-12);
  EXPECT_EQ(s.w.Run(50), "");  // 7.25 s in all: past the end of the 2 m path
  EXPECT_DOUBLE_EQ(s.row().position, 2);
  ExpectNear(s.X_PR().p, {2, 0, 0.2}, 1e-12);
  // Backwards from the end.
  s.row().velocity = -1;
  EXPECT_EQ(s.w.Run(4), "");  // 0.5 s
  EXPECT_NEAR(s.row().position, 1.5, 1e-12);
}

TEST(PathsModuleTest, AClosedPathWrapsAround) {
  PathScene s({{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}}, true, 1);
  EXPECT_EQ(s.w.Run(36), "");  // 4.5 m on a 4 m loop
  EXPECT_NEAR(s.row().position, 0.5, 1e-9);
  ExpectNear(s.X_PR().p, {0.5, 0, 0.2}, 1e-9);
  s.row().velocity = -1;
  EXPECT_EQ(s.w.Run(8), "");  // 1 m back, past the start
  EXPECT_NEAR(s.row().position, 3.5, 1e-9);
  ExpectNear(s.X_PR().p, {0, 0.5, 0.2}, 1e-9);
}

// A pause of 0.5 s at the middle point: the followers arrive there in the
// eighth step, wait four more steps of 1/8 s, then go on.
TEST(PathsModuleTest, FollowersWaitAtAPausedPoint) {
  PathScene s({{0, 0, 0}, {1, 0, 0}, {2, 0, 0}}, false, 1, 0, {0, 0.5, 0});
  std::vector<double> positions;
  ASSERT_EQ(s.w.Run(0), "");
  for (int i = 0; i < 20; ++i) {
    s.w.world().Step();
    positions.push_back(s.row().position);
  }
  for (int i = 0; i < 8; ++i) EXPECT_DOUBLE_EQ(positions[i], kStep * (i + 1)) << "step " << i;
  for (int i = 8; i < 12; ++i) EXPECT_DOUBLE_EQ(positions[i], 1) << "step " << i;
  for (int i = 12; i < 20; ++i)
    EXPECT_DOUBLE_EQ(positions[i], 1 + kStep * (i - 11)) << "step " << i;
}

TEST(PathsModuleTest, ARequestedPositionIsAppliedInTheActuatePhase) {
  PathScene s({{0, 0, 0}, {4, 0, 0}}, false, 0);
  ASSERT_EQ(s.w.Run(1), "");
  s.row().requested_position = 2.5;
  EXPECT_EQ(s.row().position, 0);
  ASSERT_EQ(s.w.Run(1), "");
  EXPECT_DOUBLE_EQ(s.row().position, 2.5);
  EXPECT_TRUE(std::isnan(s.row().requested_position));
  ExpectNear(s.X_PR().p, {2.5, 0, 0.2}, 1e-12);
}

TEST(PathsModuleTest, FindFollowerFindsOnlyThePathsChildren) {
  PathScene s({{0, 0, 0}, {1, 0, 0}}, false, 0);
  const ObjectId elsewhere = s.w.scene().AddDummy("elsewhere", {}, {});
  const uint32_t path_slot = s.w.scene().SlotOf(s.path);
  EXPECT_EQ(FindFollower(s.w.scene(), path_slot, "rider"), s.w.scene().SlotOf(s.rider));
  EXPECT_EQ(FindFollower(s.w.scene(), path_slot, "elsewhere"), kNoSlot);
  EXPECT_TRUE(s.w.scene().IsValid(elsewhere));
}

}  // namespace
}  // namespace swarmsim::paths
