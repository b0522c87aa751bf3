// modules/planning/planner.h: plans checked with the test's own geometry (a
// disc robot among axis-aligned boxes, no FCL), Dubins curvature, seeds,
// threads, and the statuses of impossible requests.
#include "modules/planning/planner.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <thread>
#include <vector>

namespace swarmsim::planning {
namespace {

struct Box {
  double x0, y0, x1, y1;
};

// A 20 x 20 m yard: walls around, a wall with a gap, and crates.
std::vector<Box> Clutter() {
  std::vector<Box> boxes = {{-10.2, -10.2, 10.2, -10}, {-10.2, 10, 10.2, 10.2},
                            {-10.2, -10.2, -10, 10.2}, {10, -10.2, 10.2, 10.2},
                            {-0.2, -10, 0.2, -1},      {-0.2, 1, 0.2, 10}};
  for (int i = 0; i < 6; ++i)
    for (int j = 0; j < 4; ++j) {
      const double x = -8 + 3 * i + (j % 2), y = -7 + 4.5 * j;
      if (std::abs(x) < 1.5) continue;
      boxes.push_back({x - 0.4, y - 0.4, x + 0.4, y + 0.4});
    }
  return boxes;
}

// Is a disc of radius r at (x, y) clear of every box?
bool Clear(const std::vector<Box>& boxes, double x, double y, double r) {
  for (const Box& b : boxes) {
    const double dx = std::max({b.x0 - x, 0.0, x - b.x1});
    const double dy = std::max({b.y0 - y, 0.0, y - b.y1});
    if (dx * dx + dy * dy < r * r) return false;
  }
  return true;
}

constexpr double kRadius = 0.25;

PlanRequest Request(Space space, double gx, double gy, uint64_t seed = 7) {
  PlanRequest r;
  r.space = space;
  r.lo = {-10, -10, 0};
  r.hi = {10, 10, 2};
  r.turning_radius = 0.8;
  r.resolution = 0.02;
  r.time_limit = 1;
  r.seed = seed;
  r.start = {{-8.5, -8.5, 0.1}, Quat::FromYaw(0)};
  r.goal = {{gx, gy, 0.1}, Quat::FromYaw(M_PI / 2)};
  return r;
}

PlanResult PlanIn(const std::vector<Box>& boxes, const PlanRequest& r) {
  return Plan(r, [&](const Pose& X) { return Clear(boxes, X.p.x, X.p.y, kRadius); });
}

// Every 5 mm along the plan's polyline the disc is clear (with 1 mm of slack
// for the planner's own check spacing).
void ExpectCollisionFree(const std::vector<Box>& boxes, const PlanResult& p) {
  ASSERT_GE(p.dense.size(), 2u);
  for (size_t i = 0; i + 1 < p.dense.size(); ++i) {
    const Vec3 a = p.dense[i].p, b = p.dense[i + 1].p;
    const int n = 1 + static_cast<int>((b - a).Norm() / 0.005);
    for (int k = 0; k <= n; ++k) {
      const Vec3 q = a + (b - a) * (static_cast<double>(k) / n);
      ASSERT_TRUE(Clear(boxes, q.x, q.y, kRadius - 0.001))
          << "the plan hits an obstacle at (" << q.x << ", " << q.y << ")";
    }
  }
}

TEST(Planner, Se2PlanIsCollisionFreeAndEndsAtTheGoal) {
  const auto boxes = Clutter();
  const PlanResult p = PlanIn(boxes, Request(Space::kSe2, 8.5, 8.5));
  ASSERT_EQ(p.status, PlanStatus::kSolved) << p.reason;
  EXPECT_EQ(p.reason, "solved");
  ExpectCollisionFree(boxes, p);
  EXPECT_NEAR(p.dense.front().p.x, -8.5, 1e-9);
  EXPECT_NEAR(p.dense.back().p.x, 8.5, 1e-6);
  EXPECT_NEAR(p.dense.back().p.y, 8.5, 1e-6);
  // It passes the middle wall through its gap.
  bool through_gap = false;
  for (const Pose& X : p.dense) through_gap = through_gap || (std::abs(X.p.x) < 0.3);
  EXPECT_TRUE(through_gap);
}

// The circumradius of three consecutive points: never below the turning
// radius (straight runs: infinite).
double SmallestRadius(const std::vector<Pose>& path) {
  double smallest = INFINITY;
  for (size_t i = 1; i + 1 < path.size(); ++i) {
    const Vec3 a = path[i - 1].p, b = path[i].p, c = path[i + 1].p;
    const double ab = (b - a).Norm(), bc = (c - b).Norm(), ca = (a - c).Norm();
    const double cross = std::abs((b - a).Cross(c - a).z);
    if (cross < 1e-12 || ab < 1e-6 || bc < 1e-6) continue;
    smallest = std::min(smallest, ab * bc * ca / (2 * cross));
  }
  return smallest;
}

TEST(Planner, DubinsPlanRespectsTheTurningRadius) {
  const auto boxes = Clutter();
  const PlanResult p = PlanIn(boxes, Request(Space::kDubins, 8.5, 8.5));
  ASSERT_EQ(p.status, PlanStatus::kSolved) << p.reason;
  ExpectCollisionFree(boxes, p);
  EXPECT_GE(SmallestRadius(p.dense), 0.8 * 0.99);
  // Headings follow the curve: a car drives forwards along it.
  for (size_t i = 0; i + 1 < p.dense.size(); ++i) {
    const Vec3 d = p.dense[i + 1].p - p.dense[i].p;
    if (d.Norm() < 1e-4) continue;
    const double yaw = p.dense[i].q.Yaw();
    EXPECT_GT(d.x * std::cos(yaw) + d.y * std::sin(yaw), 0) << "backwards at point " << i;
  }
  EXPECT_NEAR(p.dense.back().q.Yaw(), M_PI / 2, 1e-6);
}

// A heading of exactly +pi (and a start facing -x, whose yaw reads +pi) is
// as good as -pi: solved in every planar space (QA: never solved, and the
// planner waited out its time on the wall clock).
TEST(Planner, AHeadingOfPiIsSolved) {
  for (const Space space : {Space::kSe2, Space::kDubins, Space::kReedsShepp}) {
    PlanRequest r = Request(space, 8.5, 8.5);
    r.goal.q = Quat::FromYaw(M_PI);
    r.start.q = Quat::FromYaw(M_PI);
    const PlanResult p = Plan(r, [](const Pose&) { return true; });
    ASSERT_EQ(p.status, PlanStatus::kSolved) << SpaceName(space) << ": " << p.reason;
    EXPECT_NEAR(std::abs(p.dense.back().q.Yaw()), M_PI, 1e-6);
  }
}

TEST(Planner, ReedsSheppAndSe3Solve) {
  const auto boxes = Clutter();
  const PlanResult rs = PlanIn(boxes, Request(Space::kReedsShepp, 8.5, 8.5));
  ASSERT_EQ(rs.status, PlanStatus::kSolved) << rs.reason;
  ExpectCollisionFree(boxes, rs);
  PlanRequest r3 = Request(Space::kSe3, 8.5, 8.5);
  r3.goal.p.z = 1.5;
  const PlanResult p3 = PlanIn(boxes, r3);
  ASSERT_EQ(p3.status, PlanStatus::kSolved) << p3.reason;
  ExpectCollisionFree(boxes, p3);
  EXPECT_NEAR(p3.dense.back().p.z, 1.5, 1e-6);
}

TEST(Planner, SameSeedSamePathOnAnyThreadDifferentSeedDifferentPath) {
  const auto boxes = Clutter();
  for (const Space space : {Space::kSe2, Space::kDubins}) {
    // Round the middle wall's lower end: no single curve does it.
    const PlanResult serial = PlanIn(boxes, Request(space, 8.5, -8.5, 11));
    ASSERT_EQ(serial.status, PlanStatus::kSolved);
    // Two plans at once on two threads, each the same as alone.
    PlanResult a, b;
    std::thread ta([&] { a = PlanIn(boxes, Request(space, 8.5, -8.5, 11)); });
    std::thread tb([&] { b = PlanIn(boxes, Request(space, 8.5, -8.5, 12)); });
    ta.join();
    tb.join();
    ASSERT_EQ(a.dense.size(), serial.dense.size());
    for (size_t i = 0; i < a.dense.size(); ++i) ASSERT_EQ(a.dense[i], serial.dense[i]);
    EXPECT_EQ(a.iterations, serial.iterations);
    ASSERT_EQ(b.status, PlanStatus::kSolved);
    EXPECT_NE(b.waypoints, serial.waypoints) << SpaceName(space);
  }
}

TEST(Planner, ImpossibleRequestsAreResultsWithReasons) {
  auto boxes = Clutter();
  // A goal inside a crate.
  EXPECT_EQ(PlanIn(boxes, Request(Space::kSe2, -7.6, -7)).reason, "invalid goal: in collision");
  EXPECT_EQ(PlanIn(boxes, Request(Space::kSe2, 12, 0)).reason, "invalid goal: outside bounds");
  PlanRequest start_bad = Request(Space::kDubins, 8.5, 8.5);
  start_bad.start.p = {-7.9, -7, 0.1};
  EXPECT_EQ(PlanIn(boxes, start_bad).reason, "invalid start: in collision");
  // A goal walled in by a ring of boxes.
  boxes.push_back({5, 5, 9, 5.2});
  boxes.push_back({5, 8.8, 9, 9});
  boxes.push_back({5, 5, 5.2, 9});
  boxes.push_back({8.8, 5, 9, 9});
  for (const Space space : {Space::kSe2, Space::kDubins}) {
    PlanRequest r = Request(space, 7, 7);
    r.time_limit = 0.2;
    const PlanResult p = PlanIn(boxes, r);
    EXPECT_EQ(p.status, PlanStatus::kFailed);
    EXPECT_EQ(p.reason, "goal enclosed/unreachable") << SpaceName(space);
    EXPECT_TRUE(p.dense.empty());
  }
}

TEST(Planner, TheTimeLimitIsAnIterationBudget) {
  auto boxes = Clutter();
  boxes.push_back({5, 5, 9, 5.2});
  boxes.push_back({5, 8.8, 9, 9});
  boxes.push_back({5, 5, 5.2, 9});
  boxes.push_back({8.8, 5, 9, 9});
  PlanRequest r = Request(Space::kSe2, 7, 7);
  r.time_limit = 0.05;
  EXPECT_EQ(PlanIn(boxes, r).iterations, std::llround(0.05 * kIterationsPerSecond));
}

TEST(Planner, SpaceNames) {
  Space s;
  EXPECT_TRUE(ParseSpace("reeds_shepp", &s));
  EXPECT_EQ(s, Space::kReedsShepp);
  EXPECT_FALSE(ParseSpace("se4", &s));
  EXPECT_STREQ(SpaceName(Space::kDubins), "dubins");
}

}  // namespace
}  // namespace swarmsim::planning
