#include "framework/spatial_grid.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <thread>
#include <vector>

namespace swarmsim {
namespace {

std::vector<uint32_t> BruteAabb(const std::vector<GridItem>& items, const Aabb2& box) {
  std::vector<uint32_t> out;
  for (uint32_t i = 0; i < items.size(); ++i)
    if (SpatialGrid::CircleIntersectsAabb(items[i], box)) out.push_back(i);
  return out;
}

std::vector<uint32_t> BruteCircle(const std::vector<GridItem>& items, double x, double y,
                                  double r) {
  std::vector<uint32_t> out;
  for (uint32_t i = 0; i < items.size(); ++i)
    if (SpatialGrid::CircleIntersectsCircle(items[i], x, y, r)) out.push_back(i);
  return out;
}

// Random circles around `centre` in a square of side `side`.
std::vector<GridItem> RandomItems(std::mt19937_64* rng, size_t n, double centre, double side,
                                  double max_radius) {
  std::uniform_real_distribution<double> pos(centre - side / 2, centre + side / 2);
  std::uniform_real_distribution<double> rad(0, max_radius);
  std::vector<GridItem> items(n);
  for (size_t i = 0; i < n; ++i) items[i] = {pos(*rng), pos(*rng), rad(*rng), uint32_t(i * 7)};
  return items;
}

// Compares many random AABB and circle queries against a brute-force scan.
void ExpectMatchesBruteForce(const SpatialGrid& grid, const std::vector<GridItem>& items,
                             std::mt19937_64* rng, double centre, double side, double max_query) {
  std::uniform_real_distribution<double> pos(centre - side * 0.6, centre + side * 0.6);
  std::uniform_real_distribution<double> ext(0, max_query);
  std::vector<uint32_t> got;
  for (int q = 0; q < 500; ++q) {
    const double x = pos(*rng), y = pos(*rng);
    const Aabb2 box{x, y, x + ext(*rng), y + ext(*rng)};
    grid.QueryAabb(box, &got);
    ASSERT_EQ(got, BruteAabb(items, box)) << "box query " << q;
    const double r = ext(*rng);
    grid.QueryCircle(x, y, r, &got);
    ASSERT_EQ(got, BruteCircle(items, x, y, r)) << "circle query " << q;
  }
}

TEST(SpatialGridTest, RandomQueriesMatchBruteForce) {
  std::mt19937_64 rng(42);
  for (size_t n : {1, 2, 10, 100, 3000}) {
    const double side = std::sqrt(double(n));  // about one item per m^2
    const auto items = RandomItems(&rng, n, 0, side, 0.3);
    SpatialGrid grid;
    grid.Build(items);
    EXPECT_EQ(grid.size(), n);
    EXPECT_LE(double(grid.cells_x()) * grid.cells_y(), SpatialGrid::kMaxCellsPerItem * n);
    ExpectMatchesBruteForce(grid, items, &rng, 0, side, 2.0);
  }
}

TEST(SpatialGridTest, ForcedCellSizesAndMixedRadiiMatchBruteForce) {
  std::mt19937_64 rng(7);
  auto items = RandomItems(&rng, 500, 3, 20, 0.2);
  items[10].radius = 8;  // far bigger than a cell: goes to the oversize list
  items[300].radius = 3;
  for (double cell : {0.05, 0.5, 1.0, 7.0, 100.0}) {
    SpatialGrid grid;
    grid.Build(items, cell);
    ExpectMatchesBruteForce(grid, items, &rng, 3, 20, 3.0);
  }
  SpatialGrid grid;
  grid.Build(items, 1.0);
  EXPECT_GE(grid.oversize_count(), 2u);
}

TEST(SpatialGridTest, RebuildReusesTheGridAndForgetsOldItems) {
  std::mt19937_64 rng(3);
  SpatialGrid grid;
  for (int step = 0; step < 5; ++step) {
    const auto items = RandomItems(&rng, 200 + 50 * step, step * 10.0, 15, 0.2);
    grid.Build(items);
    ExpectMatchesBruteForce(grid, items, &rng, step * 10.0, 15, 2.0);
  }
}

TEST(SpatialGridTest, EmptyGridFindsNothing) {
  SpatialGrid grid;
  std::vector<uint32_t> got{1, 2, 3};
  grid.QueryAabb({-1e9, -1e9, 1e9, 1e9}, &got);  // before any Build
  EXPECT_TRUE(got.empty());
  grid.Build({});
  EXPECT_TRUE(grid.empty());
  grid.QueryAabb({-1e9, -1e9, 1e9, 1e9}, &got);
  EXPECT_TRUE(got.empty());
  grid.QueryCircle(0, 0, 1e9, &got);
  EXPECT_TRUE(got.empty());
  int visits = 0;
  grid.ForEachInAabb({-1, -1, 1, 1}, [&](uint32_t, const GridItem&) { ++visits; });
  EXPECT_EQ(visits, 0);
}

TEST(SpatialGridTest, ItemsOnCellBordersAreFound) {
  // Items exactly on the lines of a 1 m grid, touching each other.
  std::vector<GridItem> items;
  for (int i = 0; i <= 4; ++i)
    for (int j = 0; j <= 4; ++j) items.push_back({double(i), double(j), 0.5, 0});
  SpatialGrid grid;
  grid.Build(items, 1.0);
  std::vector<uint32_t> got;
  // A point query on a cell corner finds the item centred there.
  grid.QueryAabb({2, 2, 2, 2}, &got);
  EXPECT_EQ(got, (std::vector<uint32_t>{12}));
  // Midway between two items: both circles touch the point.
  grid.QueryAabb({2.5, 2, 2.5, 2}, &got);
  EXPECT_EQ(got, (std::vector<uint32_t>{12, 17}));
  // A box whose edge lies exactly on the rim of a circle (closed test).
  grid.QueryAabb({4.5, 4, 5, 5}, &got);
  EXPECT_EQ(got, (std::vector<uint32_t>{24}));
  grid.QueryCircle(5, 4, 0.5, &got);  // circles touching at one point
  EXPECT_EQ(got, (std::vector<uint32_t>{24}));
  // Every cell border and corner.
  for (double x = -0.5; x <= 4.5; x += 0.5)
    for (double y = -0.5; y <= 4.5; y += 0.5) {
      grid.QueryAabb({x, y, x, y}, &got);
      ASSERT_EQ(got, BruteAabb(items, {x, y, x, y})) << x << ", " << y;
      grid.QueryCircle(x, y, 0.25, &got);
      ASSERT_EQ(got, BruteCircle(items, x, y, 0.25)) << x << ", " << y;
    }
}

TEST(SpatialGridTest, HugeCoordinatesMatchBruteForce) {
  std::mt19937_64 rng(11);
  for (double centre : {1e9, -3e12, 5e15}) {
    // Side proportional to the magnitude so positions are not all equal.
    const double side = std::max(100.0, std::abs(centre) * 1e-12 * 1e4);
    const auto items = RandomItems(&rng, 1000, centre, side, side / 50);
    SpatialGrid grid;
    grid.Build(items);
    ExpectMatchesBruteForce(grid, items, &rng, centre, side, side / 10);
  }
  // Two clusters 1e12 m apart: the cell count stays capped.
  auto items = RandomItems(&rng, 500, 0, 30, 0.2);
  const auto far = RandomItems(&rng, 500, 1e12, 30, 0.2);
  items.insert(items.end(), far.begin(), far.end());
  SpatialGrid grid;
  grid.Build(items);
  EXPECT_LE(double(grid.cells_x()) * grid.cells_y(), SpatialGrid::kMaxCellsPerItem * 1000);
  ExpectMatchesBruteForce(grid, items, &rng, 0, 30, 2.0);
  ExpectMatchesBruteForce(grid, items, &rng, 1e12, 30, 2.0);
  // A spread near the double range, and a tiny forced cell.
  const std::vector<GridItem> extreme = {{-1e307, 0, 1, 0}, {1e307, 5, 1, 0}, {0, 0, 1e300, 0}};
  for (double cell : {0.0, 1e-300}) {
    grid.Build(extreme, cell);
    std::vector<uint32_t> got;
    grid.QueryCircle(1e307, 5, 0.5, &got);
    EXPECT_EQ(got, (std::vector<uint32_t>{1}));
    grid.QueryAabb({-1, -1, 1, 1}, &got);
    EXPECT_EQ(got, (std::vector<uint32_t>{2}));
  }
}

TEST(SpatialGridTest, NonFiniteItemsAndQueriesAreHarmless) {
  const double inf = std::numeric_limits<double>::infinity();
  const double nan = std::numeric_limits<double>::quiet_NaN();
  std::vector<GridItem> items = {
      {0, 0, 1, 0}, {nan, 0, 1, 0}, {inf, 0, 1, 0}, {2, 2, nan, 0}, {3, 3, -1, 0}};
  SpatialGrid grid;
  grid.Build(items);
  std::vector<uint32_t> got;
  grid.QueryAabb({-10, -10, 10, 10}, &got);
  EXPECT_EQ(got, (std::vector<uint32_t>{0, 4}));  // a negative radius is read as 0
  grid.QueryAabb({-inf, -inf, inf, inf}, &got);
  EXPECT_EQ(got, (std::vector<uint32_t>{0, 2, 4}));  // an infinite box holds x = +inf
  grid.QueryAabb({nan, 0, 1, 1}, &got);
  EXPECT_TRUE(got.empty());
  grid.QueryCircle(0, 0, -1, &got);
  EXPECT_TRUE(got.empty());
}

TEST(SpatialGridTest, ForEachVisitsInAscendingOrderAndMayNest) {
  std::mt19937_64 rng(5);
  const auto items = RandomItems(&rng, 400, 0, 20, 0.3);
  SpatialGrid grid;
  grid.Build(items, 0.7);
  std::vector<uint32_t> visited;
  int inner_total = 0;
  grid.ForEachInCircle(0, 0, 5, [&](uint32_t i, const GridItem& item) {
    visited.push_back(i);
    EXPECT_EQ(item.id, items[i].id);
    // A nested query from inside the callback does not disturb the outer one.
    grid.ForEachInCircle(item.x, item.y, 1, [&](uint32_t, const GridItem&) { ++inner_total; });
  });
  EXPECT_EQ(visited, BruteCircle(items, 0, 0, 5));
  EXPECT_GT(inner_total, 0);
}

TEST(SpatialGridTest, ConcurrentQueriesAgree) {
  std::mt19937_64 rng(9);
  const auto items = RandomItems(&rng, 5000, 0, 70, 0.2);
  SpatialGrid grid;
  grid.Build(items);
  std::vector<std::vector<uint32_t>> results(4);
  std::vector<std::thread> threads;
  for (int t = 0; t < 4; ++t)
    threads.emplace_back([&, t] {
      for (int q = 0; q < 2000; ++q) {
        const double x = -35 + 70.0 * q / 2000;
        grid.ForEachInCircle(x, x * 0.5, 1.5,
                             [&](uint32_t i, const GridItem&) { results[t].push_back(i); });
      }
    });
  for (auto& t : threads) t.join();
  for (int t = 1; t < 4; ++t) EXPECT_EQ(results[t], results[0]);
  EXPECT_FALSE(results[0].empty());
}

}  // namespace
}  // namespace swarmsim
