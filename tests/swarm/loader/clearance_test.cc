// worlds/clearance.yaml: every robot's nearest-obstacle distance, with its
// closest points, recorded each step. The recorded points must lie on an
// obstacle's surface and on the robot, as far apart as the distance says,
// and the nearest anything within 1 m can be no farther than the nearest
// obstacle.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <map>
#include <string>

#include "tests/swarm/run_program.h"

namespace swarmsim {
namespace {

namespace fs = std::filesystem;

// Distance from p (x, y) to the surface of the obstacles of the world, in
// the plane (pillars r = 0.15 on a 1.5 m grid, the walls' inner faces at
// +-3 m, the crate 0.6 x 0.3 turned 30 degrees at (0.75, 2.25)).
double PlaneDistanceToObstacles(double x, double y) {
  double best = std::min({3 - x, 3 + x, 3 - y, 3 + y});
  for (int i = -1; i <= 1; ++i)
    for (int j = -1; j <= 1; ++j)
      best = std::min(best, std::abs(std::hypot(x - 1.5 * i, y - 1.5 * j) - 0.15));
  const double c = std::cos(M_PI / 6), s = std::sin(M_PI / 6);
  const double lx = c * (x - 0.75) + s * (y - 2.25), ly = -s * (x - 0.75) + c * (y - 2.25);
  const double qx = std::abs(lx) - 0.3, qy = std::abs(ly) - 0.15;
  const double outside = std::hypot(std::max(qx, 0.0), std::max(qy, 0.0));
  best = std::min(best, outside > 0 ? outside : std::abs(std::max(qx, qy)));
  return best;
}

TEST(ClearanceWorldTest, RecordedClosestPointsLieOnTheObstaclesAndOnTheRobots) {
  const fs::path out = testing::FreshTempDir("swarmsim_clearance", "run");
  const auto r =
      testing::RunProgram("run " + std::string(SWARMSIM_SOURCE_DIR) +
                          "/worlds/clearance.yaml --steps 30 --quiet --out " + out.string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  std::map<std::string, std::map<std::string, double>> last;  // robot -> metric -> value
  for (const testing::MetricRow& row : testing::ReadMetricsCsv(out / "metrics.csv"))
    if (row.step == 30) last[row.robot][row.metric] = row.value;
  int robots = 0;
  for (const auto& [robot, m] : last) {
    if (robot.empty()) continue;
    ++robots;
    const double d = m.at("to_obstacles.distance");
    const double x1 = m.at("to_obstacles.x1"), y1 = m.at("to_obstacles.y1"),
                 z1 = m.at("to_obstacles.z1");
    const double x2 = m.at("to_obstacles.x2"), y2 = m.at("to_obstacles.y2"),
                 z2 = m.at("to_obstacles.z2");
    EXPECT_GT(d, 0) << robot;
    EXPECT_NEAR(std::sqrt((x2 - x1) * (x2 - x1) + (y2 - y1) * (y2 - y1) + (z2 - z1) * (z2 - z1)), d,
                1e-6)
        << robot;
    // The obstacle's point is on an obstacle's surface; the robot's point is
    // as far from the obstacles (in the plane: every obstacle is taller than
    // the robot's parts are high) as the distance says.
    // Within 1e-5 m: a wheel (a cylinder on its side) is measured by FCL's
    // GJK, to its tolerance; upright shapes in closed form.
    EXPECT_NEAR(PlaneDistanceToObstacles(x2, y2), 0, 1e-5) << robot;
    EXPECT_NEAR(PlaneDistanceToObstacles(x1, y1), d, 1e-5) << robot;
    if (m.count("to_anything.distance") && d < 1) {
      EXPECT_LE(m.at("to_anything.distance"), d + 1e-12) << robot;
    }
  }
  EXPECT_EQ(robots, 40);
  fs::remove_all(out);
}

}  // namespace
}  // namespace swarmsim
