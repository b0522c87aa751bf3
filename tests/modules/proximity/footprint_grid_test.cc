// modules/proximity/footprint_grid.cc: the robot broad phase of the
// early-out. It must find every shape of another robot whose square meets
// a box (the rays it lets through do the exact tests), skip the asking
// robot's own shapes and the listed ones, and keep oversize or unbounded
// squares.
#include "modules/proximity/footprint_grid.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <vector>

namespace swarmsim::proximity {
namespace {

Aabb2 Square(double x, double y, double half) { return {x - half, y - half, x + half, y + half}; }

bool Meets(const Aabb2& a, const Aabb2& b) {
  return a.min_x <= b.max_x && b.min_x <= a.max_x && a.min_y <= b.max_y && b.min_y <= a.max_y;
}

TEST(FootprintGridTest, FindsOtherRobotsButNotTheAskingOne) {
  // Robot 0 at the origin, robot 1 at x = 1 (two shapes), a wall-less crate
  // of no robot at x = -1.
  const std::vector<Aabb2> squares = {Square(0, 0, 0.1), Square(1, 0, 0.1), Square(1.1, 0, 0.05),
                                      Square(-1, 0, 0.2)};
  const std::vector<int32_t> instances = {0, 1, 1, -1};
  const std::vector<ObjectId> ids = {{1, 1}, {2, 1}, {3, 1}, {4, 1}};
  FootprintGrid grid;
  grid.Build(squares, instances, ids);
  // Robot 0 looking around itself sees nothing but itself.
  EXPECT_FALSE(grid.AnyOther(Square(0, 0, 0.3), 0, {}));
  // Reaching robot 1: both its shapes, ascending.
  std::vector<uint32_t> found;
  grid.Others(Square(0.5, 0, 0.65), 0, {}, &found);
  EXPECT_EQ(found, (std::vector<uint32_t>{1, 2}));
  // A scene sensor (no robot) near the origin sees robot 0.
  EXPECT_TRUE(grid.AnyOther(Square(0, 0, 0.3), -1, {}));
  // Robot 1 reaching the crate; the crate skipped (a sensor mounted on it).
  EXPECT_TRUE(grid.AnyOther(Square(-0.5, 0, 0.35), 1, {}));
  const ObjectId crate = ids[3];
  EXPECT_FALSE(grid.AnyOther(Square(-0.75, 0, 0.1), 1, {&crate, 1}));
}

TEST(FootprintGridTest, OversizeAndUnboundedSquaresAreAlwaysScanned) {
  constexpr double kInf = std::numeric_limits<double>::infinity();
  const std::vector<Aabb2> squares = {Square(0, 0, 0.05), Square(0, 0, 500),
                                      Aabb2{-kInf, 3, kInf, 4}};
  const std::vector<int32_t> instances = {0, 1, 2};
  const std::vector<ObjectId> ids = {{1, 1}, {2, 1}, {3, 1}};
  FootprintGrid grid;
  grid.Build(squares, instances, ids);
  std::vector<uint32_t> found;
  grid.Others(Square(400, 0, 1), 0, {}, &found);  // far out, inside the huge square only
  EXPECT_EQ(found, (std::vector<uint32_t>{1}));
  grid.Others(Square(1e6, 3.5, 1), 0, {}, &found);  // the unbounded strip, far along x
  EXPECT_EQ(found, (std::vector<uint32_t>{2}));
}

// Against brute force over random swarms: the grid's answer is exactly the
// shapes whose squares meet the box (of another robot, not skipped).
TEST(FootprintGridTest, MatchesBruteForceOnRandomSwarms) {
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> pos(-20, 20), half(0.01, 0.3), box_half(0.01, 2);
  for (int trial = 0; trial < 5; ++trial) {
    std::vector<Aabb2> squares;
    std::vector<int32_t> instances;
    std::vector<ObjectId> ids;
    for (int i = 0; i < 400; ++i) {
      squares.push_back(Square(pos(rng), pos(rng), half(rng)));
      instances.push_back(i % 7 == 0 ? -1 : i / 3);  // robots of three shapes, some loose shapes
      ids.push_back({static_cast<uint32_t>(i + 1), 1});
    }
    FootprintGrid grid;
    grid.Build(squares, instances, ids);
    std::vector<uint32_t> found, expected;
    for (int q = 0; q < 500; ++q) {
      const Aabb2 box = Square(pos(rng), pos(rng), box_half(rng));
      const int instance = q % 2 ? instances[q % squares.size()] : -1;
      const ObjectId skip = ids[(q * 13) % ids.size()];
      expected.clear();
      for (uint32_t i = 0; i < squares.size(); ++i)
        if (Meets(squares[i], box) && !(instance >= 0 && instances[i] == instance) &&
            ids[i] != skip)
          expected.push_back(i);
      grid.Others(box, instance, {&skip, 1}, &found);
      ASSERT_EQ(found, expected) << "trial " << trial << " query " << q;
      ASSERT_EQ(grid.AnyOther(box, instance, {&skip, 1}), !expected.empty());
    }
  }
}

}  // namespace
}  // namespace swarmsim::proximity
