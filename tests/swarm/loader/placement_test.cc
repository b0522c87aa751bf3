// Distributing copies: no overlaps, inside the region, clear of walls and
// obstacles, varied headings, deterministic, and a clear error when full.
#include "swarm/loader/placement.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "framework/error.h"
#include "framework/registry.h"
#include "swarm/loader/world_loader.h"
#include "tests/framework/fakes.h"

namespace swarmsim {
namespace {

// Smallest centre distance minus the sum of radii over all pairs, via a
// sort on x (exact, and fast enough for 10,000 discs).
double MinGap(const std::vector<Placement2>& p, double radius) {
  std::vector<Placement2> s = p;
  std::sort(s.begin(), s.end(), [](const auto& a, const auto& b) { return a.x < b.x; });
  double best = INFINITY;
  for (size_t i = 0; i < s.size(); ++i)
    for (size_t j = i + 1; j < s.size() && s[j].x - s[i].x < best + 2 * radius; ++j)
      best = std::min(best, std::hypot(s[j].x - s[i].x, s[j].y - s[i].y) - 2 * radius);
  return best;
}

double HeadingSpread(const std::vector<Placement2>& p) {
  double mean = 0, var = 0;
  for (const auto& q : p) mean += q.yaw;
  mean /= static_cast<double>(p.size());
  for (const auto& q : p) var += (q.yaw - mean) * (q.yaw - mean);
  return std::sqrt(var / static_cast<double>(p.size()));
}

TEST(PlacementTest, TenThousandCopiesDoNotOverlap) {
  // Foot-bots at one per m^2 (the diffusion world at --set robots=10000).
  const double r = 0.085, clearance = 0.02, half = 50;
  Placer placer(1);
  const std::vector<Obstacle2> walls = {
      {Obstacle2::Kind::kBox, 0, half + 0.05, 0, half + 0.1, 0.05, 0},
      {Obstacle2::Kind::kBox, 0, -half - 0.05, 0, half + 0.1, 0.05, 0},
      {Obstacle2::Kind::kBox, half + 0.05, 0, 0, 0.05, half, 0},
      {Obstacle2::Kind::kBox, -half - 0.05, 0, 0, 0.05, half, 0}};
  for (const auto& w : walls) placer.AddObstacle(w);
  const auto p = placer.Distribute({-half, -half, half, half}, 10000, r, clearance, 0);
  ASSERT_EQ(p.size(), 10000u);
  EXPECT_GE(MinGap(p, r), clearance);
  for (const auto& q : p) {
    ASSERT_LE(std::abs(q.x), half - r);
    ASSERT_LE(std::abs(q.y), half - r);
    for (const auto& w : walls) ASSERT_GE(w.Distance(q.x, q.y), r + clearance);
    ASSERT_GE(q.yaw, -M_PI);
    ASSERT_LT(q.yaw, M_PI);
  }
  // Uniform headings in [-pi, pi): standard deviation pi / sqrt(3).
  EXPECT_NEAR(HeadingSpread(p), M_PI / std::sqrt(3.0), 0.1);
}

TEST(PlacementTest, KeepsClearOfObstaclesAndEarlierBodies) {
  Placer placer(3);
  const Obstacle2 box{Obstacle2::Kind::kBox, 1, 1, 0, 0.8, 0.3, M_PI / 6};
  const Obstacle2 disc{Obstacle2::Kind::kCircle, -1, -1, 0.5};
  placer.AddObstacle(box);
  placer.AddObstacle(disc);
  placer.AddBody(0, 0, 0.4);
  const double r = 0.1, clearance = 0.05;
  const auto p = placer.Distribute({-2, -2, 2, 2}, 60, r, clearance, 0);
  ASSERT_EQ(p.size(), 60u);
  EXPECT_GE(MinGap(p, r), clearance);
  for (const auto& q : p) {
    EXPECT_GE(box.Distance(q.x, q.y), r + clearance);
    EXPECT_GE(disc.Distance(q.x, q.y), r + clearance);
    EXPECT_GE(std::hypot(q.x, q.y), 0.4 + r + clearance);
    EXPECT_LE(std::abs(q.x), 2 - r);
    EXPECT_LE(std::abs(q.y), 2 - r);
  }
  // A second batch avoids the first.
  const auto more = placer.Distribute({-2, -2, 2, 2}, 30, r, clearance, 1);
  ASSERT_EQ(more.size(), 30u);
  std::vector<Placement2> all = p;
  all.insert(all.end(), more.begin(), more.end());
  EXPECT_GE(MinGap(all, r), clearance);
}

// Bodies are filed in a grid over the region being filled: those placed in
// another region before (a grid of its own, rebuilt), fixed ones outside
// the grid, bigger discs than the grid's cells were for, and regions far
// larger than their copies all keep the same rule: no two discs closer
// than their radii and the clearance.
TEST(PlacementTest, EveryBodyIsKeptClearOfWhateverRegionsItWasPlacedIn) {
  Placer placer(5);
  const double clearance = 0.02;
  std::vector<std::pair<Placement2, double>> all;  // every disc, with its radius
  const auto add = [&all](const std::vector<Placement2>& p, double r) {
    for (const Placement2& q : p) all.push_back({q, r});
  };
  // Fixed bodies inside and outside the regions to come.
  for (const auto& [x, y, r] : std::vector<std::array<double, 3>>{
           {0.5, 0.5, 0.3}, {3.2, 0.4, 0.2}, {-0.4, 2.5, 0.25}, {10, 10, 1}}) {
    placer.AddBody(x, y, r);
    all.push_back({{x, y, 0}, r});
  }
  add(placer.Distribute({0, 0, 3, 3}, 300, 0.05, clearance, 0), 0.05);
  // A query anywhere sees every body: the far fixed one outside this grid,
  // and a disc placed in it.
  EXPECT_FALSE(placer.IsFree(10.5, 10, 0.1, 0));
  EXPECT_TRUE(placer.IsFree(12, 12, 0.1, 0));
  EXPECT_TRUE(placer.IsFree(1e300, -1e300, 0.1, 0)) << "a far point: no cell, no body";
  EXPECT_FALSE(placer.IsFree(all.back().first.x + 0.05, all.back().first.y, 0.05, 0));
  // An overlapping region: a new grid, the first batch filed in it.
  add(placer.Distribute({1.5, 1.5, 4, 4}, 150, 0.05, clearance, 1), 0.05);
  // Bigger discs than the grid was built for, and a region reaching the far body.
  add(placer.Distribute({0, 0, 11, 11}, 40, 0.3, clearance, 2), 0.3);
  // A sparse region: few copies in a wide one (coarser cells).
  add(placer.Distribute({-500, -500, 500, 500}, 20, 0.1, clearance, 3), 0.1);
  ASSERT_EQ(all.size(), 4u + 300 + 150 + 40 + 20);
  for (size_t i = 0; i < all.size(); ++i)
    for (size_t j = i + 1; j < all.size(); ++j) {
      const auto& [a, ra] = all[i];
      const auto& [b, rb] = all[j];
      if (i < 4 && j < 4) continue;  // the fixed ones among themselves need not keep clear
      ASSERT_GE(std::hypot(a.x - b.x, a.y - b.y), ra + rb + clearance - 1e-12) << i << " " << j;
    }
}

TEST(PlacementTest, BoxDistanceIsExact) {
  const Obstacle2 box{Obstacle2::Kind::kBox, 0, 0, 0, 1, 0.5, M_PI / 2};  // long side along y
  EXPECT_NEAR(box.Distance(0, 2), 1, 1e-12);
  EXPECT_NEAR(box.Distance(1.5, 0), 1, 1e-12);
  EXPECT_NEAR(box.Distance(0, 0), -0.5, 1e-12);
  EXPECT_NEAR(box.Distance(1.5, 2), std::hypot(1, 1), 1e-12);
}

TEST(PlacementTest, SameSeedSamePlacesOtherSeedOthers) {
  auto run = [](uint64_t seed, uint64_t stream) {
    Placer placer(seed);
    return placer.Distribute({0, 0, 5, 5}, 40, 0.1, 0, stream);
  };
  const auto a = run(1, 0), b = run(1, 0), c = run(2, 0), d = run(1, 1);
  ASSERT_EQ(a.size(), 40u);
  for (size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].x, b[i].x);
    EXPECT_EQ(a[i].yaw, b[i].yaw);
  }
  EXPECT_NE(a[0].x, c[0].x);
  EXPECT_NE(a[0].x, d[0].x);
}

TEST(PlacementTest, FixedHeading) {
  Placer placer(1);
  for (const auto& q : placer.Distribute({0, 0, 3, 3}, 20, 0.1, 0, 0, 0.5)) EXPECT_EQ(q.yaw, 0.5);
}

TEST(PlacementTest, FullRegionStopsEarly) {
  Placer placer(1);
  // At most 25 discs of radius 0.1 fit in a 1 m square.
  const auto p = placer.Distribute({0, 0, 1, 1}, 1000, 0.1, 0, 0);
  EXPECT_GT(p.size(), 5u);
  EXPECT_LE(p.size(), 25u);
  EXPECT_GE(MinGap(p, 0.1), 0);
  // Too small for even one.
  EXPECT_TRUE(placer.Distribute({0, 0, 0.1, 0.1}, 1, 0.1, 0, 1).empty());
}

// --- Through the loader ------------------------------------------------------------------

ModuleRegistry TestRegistry() {
  ModuleRegistry r;
  r.RegisterDynamics({"", "box2d", "1", "test double"}, {},
                     [] { return std::make_unique<testing::NullDynamics>(); });
  // The robots' proximity rings: the proximity module's type (a null backend).
  proximity::Register(&r, {"", "proximity", "1", "test double"},
                      [] { return std::make_unique<testing::NullProximity>(); });
  return r;
}

std::string Data(const std::string& name) {
  return std::string(SWARMSIM_SOURCE_DIR) + "/tests/data/worlds/" + name;
}

TEST(PlacementTest, LoadedRobotsAvoidWallsObstaclesAndEachOther) {
  const ModuleRegistry registry = TestRegistry();
  LoadedWorld loaded = LoadWorld(Data("obstacles.yaml"), {}, registry);
  const Scene& scene = loaded.world->scene();
  ASSERT_EQ(loaded.world->robot_count(), 200);
  // Every static shape outside the robots (walls, obstacles) as a plane footprint.
  std::vector<Obstacle2> statics;
  for (uint32_t row = 0; row < scene.shapes().size(); ++row) {
    const uint32_t slot = scene.shape_owners()[row];
    if (scene.instance_of_at(slot) >= 0) continue;
    const ShapeData& s = scene.shapes()[row];
    const Pose& X = scene.world_pose_at(slot);
    if (s.kind == ShapeKind::kBox)
      statics.push_back(
          {Obstacle2::Kind::kBox, X.p.x, X.p.y, 0, s.size.x / 2, s.size.y / 2, X.q.Yaw()});
    else
      statics.push_back({Obstacle2::Kind::kCircle, X.p.x, X.p.y, s.size.x});
  }
  ASSERT_EQ(statics.size(), 4u + 3u);
  const double radius = 0.085, clearance = 0.02;  // foot-bot body, the world's clearance
  std::vector<Placement2> robots;
  double min_x = INFINITY, max_x = -INFINITY;
  for (const ModelInstance& inst : scene.instances()) {
    const Pose X = scene.world_pose(inst.root);
    robots.push_back({X.p.x, X.p.y, X.q.Yaw()});
    min_x = std::min(min_x, X.p.x);
    max_x = std::max(max_x, X.p.x);
    EXPECT_LE(std::abs(X.p.x), 4 - radius);  // arena: 8 x 6 m inside the walls
    EXPECT_LE(std::abs(X.p.y), 3 - radius);
    for (const Obstacle2& o : statics) EXPECT_GE(o.Distance(X.p.x, X.p.y), radius + clearance);
  }
  EXPECT_GE(MinGap(robots, radius), clearance);
  EXPECT_GT(HeadingSpread(robots), 1.5);
  EXPECT_GT(max_x - min_x, 6);  // spread over the arena, not bunched
}

TEST(PlacementTest, TooFullArenaIsAClearError) {
  const ModuleRegistry registry = TestRegistry();
  try {
    LoadWorld(Data("too_full.yaml"), {}, registry);
    FAIL() << "expected an error";
  } catch (const Error& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("too_full.yaml:9:12:"), std::string::npos) << message;
    EXPECT_NE(
        message.find("cannot place 10,000 footbot copies in the arena without overlap (placed "),
        std::string::npos)
        << message;
    EXPECT_NE(message.find("enlarge the arena or reduce count"), std::string::npos) << message;
  }
}

// --- distribute.order: spatial -------------------------------------------------------

// Mean distance from copy k to copy k + 1, m.
double MeanStep(const std::vector<Placement2>& p) {
  double sum = 0;
  for (size_t k = 1; k < p.size(); ++k) sum += std::hypot(p[k].x - p[k - 1].x, p[k].y - p[k - 1].y);
  return sum / static_cast<double>(p.size() - 1);
}

TEST(PlacementTest, SpatialOrderRenumbersTheSameCopiesSoThatNeighboursGetNearNumbers) {
  // 10,000 foot-bots at one per m^2: drawn at random, copy k + 1 is on
  // average about half the arena's side (52 m) from copy k; along the
  // curve, about one cell (a footprint, 0.19 m) to a few.
  const double r = 0.085, clearance = 0.02, half = 50;
  Placer placer(1);
  const std::vector<Placement2> drawn =
      placer.Distribute({-half, -half, half, half}, 10000, r, clearance, 0);
  ASSERT_EQ(drawn.size(), 10000u);
  std::vector<Placement2> sorted = drawn;
  SortAlongCurve(&sorted, 2 * r + clearance);
  EXPECT_GT(MeanStep(drawn), 30);
  EXPECT_LT(MeanStep(sorted), 2);
  // Every copy within 4 m of the one before it, but for a few jumps
  // between the curve's quadrants.
  int far = 0;
  for (size_t k = 1; k < sorted.size(); ++k)
    far += std::hypot(sorted[k].x - sorted[k - 1].x, sorted[k].y - sorted[k - 1].y) > 4;
  EXPECT_LT(far, 20);
  // The same poses, only renumbered.
  const auto key = [](const Placement2& a, const Placement2& b) {
    return std::tie(a.x, a.y, a.yaw) < std::tie(b.x, b.y, b.yaw);
  };
  std::vector<Placement2> a = drawn, b = sorted;
  std::sort(a.begin(), a.end(), key);
  std::sort(b.begin(), b.end(), key);
  for (size_t k = 0; k < a.size(); ++k) {
    ASSERT_EQ(a[k].x, b[k].x);
    ASSERT_EQ(a[k].y, b[k].y);
    ASSERT_EQ(a[k].yaw, b[k].yaw);
  }
  // Copies in one cell keep their order; a single copy or none is left alone.
  std::vector<Placement2> same = {{1, 1, 0.1}, {1, 1, 0.2}, {1, 1, 0.3}};
  SortAlongCurve(&same, 0.2);
  EXPECT_EQ(same[0].yaw, 0.1);
  EXPECT_EQ(same[2].yaw, 0.3);
  std::vector<Placement2> none;
  SortAlongCurve(&none, 0.2);
  EXPECT_TRUE(none.empty());
}

// --- distribute.lattice ---------------------------------------------------------------

TEST(PlacementTest, SquareLatticeIsCentredRowByRowFromTheLowerLeft) {
  Placer placer(1);
  int64_t bad = 0;
  const Region2 region{-1, -1, 1, 1};
  const std::vector<Placement2> p = placer.Lattice(region, 7, 0.0165, 0.05, false, 3, 0, 0.0, &bad);
  EXPECT_EQ(bad, -1);
  ASSERT_EQ(p.size(), 7u);
  // 3 columns, 3 rows (the last holds one): a 0.1 x 0.1 block centred at the origin.
  EXPECT_DOUBLE_EQ(p[0].x, -0.05);
  EXPECT_DOUBLE_EQ(p[0].y, -0.05);
  EXPECT_DOUBLE_EQ(p[2].x, 0.05);
  EXPECT_DOUBLE_EQ(p[3].y, 0.0);
  EXPECT_DOUBLE_EQ(p[6].x, -0.05);
  EXPECT_DOUBLE_EQ(p[6].y, 0.05);
  for (const Placement2& q : p) EXPECT_EQ(q.yaw, 0.0);
  EXPECT_EQ(placer.body_count(), 7u);  // later entries keep clear of them
  EXPECT_FALSE(placer.IsFree(0, 0, 0.01, 0));
}

TEST(PlacementTest, HexagonalLatticeNeighboursAreAllOneSpacingApart) {
  Placer placer(1);
  int64_t bad = 0;
  const double s = 0.06;
  const std::vector<Placement2> p =
      placer.Lattice({-1, -1, 1, 1}, 25, 0.0165, s, true, 5, 0, std::nullopt, &bad);
  ASSERT_EQ(p.size(), 25u);
  // Copy 12 (row 2, column 2) has six neighbours at exactly the spacing, no
  // other copy closer than the spacing.
  int at_spacing = 0;
  for (size_t k = 0; k < p.size(); ++k) {
    if (k == 12) continue;
    const double d = std::hypot(p[k].x - p[12].x, p[k].y - p[12].y);
    EXPECT_GE(d, s - 1e-12);
    if (std::abs(d - s) < 1e-12) ++at_spacing;
  }
  EXPECT_EQ(at_spacing, 6);
  EXPECT_GT(HeadingSpread(p), 1.0);  // random headings without heading_deg
}

TEST(PlacementTest, LatticeThatDoesNotFitNamesTheFirstCopyAndPlacesNothing) {
  Placer placer(1);
  placer.AddObstacle({Obstacle2::Kind::kCircle, 0.05, 0, 0.01});
  int64_t bad = 0;
  EXPECT_TRUE(placer.Lattice({-1, -1, 1, 1}, 9, 0.0165, 0.05, false, 3, 0, 0.0, &bad).empty());
  EXPECT_EQ(bad, 5);  // row 1, column 2: (0.05, 0)
  EXPECT_EQ(placer.body_count(), 0u);
  EXPECT_TRUE(
      placer.Lattice({-0.05, -0.05, 0.05, 0.05}, 9, 0.0165, 0.05, false, 3, 0, 0.0, &bad).empty());
  EXPECT_EQ(bad, 0);  // the block is wider than the region
}

}  // namespace
}  // namespace swarmsim
