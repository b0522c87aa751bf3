// Placing and building the `models:` entries' copies (swarm/loader/
// world_copies.cc): fixed copies where their entry says, distributed ones
// in their region or on a lattice in index order, copies with values of
// their own sharing the scaled mesh; placement mistakes found only while
// placing (a lattice that does not fit) named at their file:line:column.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include "framework/world.h"
#include "swarm/loader/world_loader.h"
#include "tests/framework/error_of.h"
#include "tests/swarm/loader/world_dir_test.h"

namespace swarmsim {
namespace {

class WorldCopiesTest : public testing::WorldDirTest {
 protected:
  void SetUp() override {
    WorldDirTest::SetUp();
    Write("bot.yaml", "model: bot\nobjects: {name: body, type: dummy}\n");
  }
  std::string ErrorOfWorld(const std::string& world) {
    return testing::ErrorOf([&] { Load(world); });
  }
};

TEST_F(WorldCopiesTest, ACopyIsPlacedWhereItsEntrySays) {
  LoadedWorld w = Load(
      "simulation: {physics: kinematic}\n"
      "models:\n"
      "  - {model: bot.yaml, position: [1, 2], heading_deg: 90}\n"
      "  - {model: bot.yaml, position: [3, 4, 0.5], count: 1}\n"
      "  - model: bot.yaml\n"
      "    count: 20\n"
      "    distribute: {region: {min: [10, 20], max: [12, 21]}}\n");
  const Scene& scene = w.world->scene();
  ASSERT_EQ(scene.instances().size(), 22u);
  const Pose first = scene.world_pose(scene.instance(0).root);
  EXPECT_NEAR(first.p.x, 1, 1e-12);
  EXPECT_NEAR(first.p.y, 2, 1e-12);
  EXPECT_NEAR(first.p.z, 0, 1e-12) << "on the ground";
  const Vec3 forward = first.q.Rotate({1, 0, 0});
  EXPECT_NEAR(forward.x, 0, 1e-12);
  EXPECT_NEAR(forward.y, 1, 1e-12) << "heading 90 degrees: facing +y";
  EXPECT_NEAR(scene.world_pose(scene.instance(1).root).p.z, 0.5, 1e-12);
  for (int k = 2; k < 22; ++k) {
    const Vec3 p = scene.world_pose(scene.instance(k).root).p;
    EXPECT_TRUE(p.x >= 10 && p.x <= 12 && p.y >= 20 && p.y <= 21)
        << k << ": " << p.x << ", " << p.y;
  }
}

TEST_F(WorldCopiesTest, ALatticePlacesCopiesInIndexOrderAtTheSpacing) {
  Write("disc.yaml",
        "model: disc\n"
        "objects: {name: body, type: shape, shape: cylinder, radius: 0.0165, height: 0.03}\n");
  LoadedWorld w = Load(
      "simulation: {physics: kinematic}\n"
      "models:\n"
      "  - model: disc.yaml\n"
      "    count: 6\n"
      "    distribute: {region: {min: [1, 1], max: [2, 2]}, heading_deg: 0,\n"
      "                 lattice: {spacing: 0.05, columns: 3}}\n");
  const Scene& scene = w.world->scene();
  ASSERT_EQ(scene.instances().size(), 6u);
  for (int k = 0; k < 6; ++k) {
    const Pose X = scene.world_pose(scene.instance(k).root);
    EXPECT_NEAR(X.p.x, 1.45 + 0.05 * (k % 3), 1e-12) << k;
    EXPECT_NEAR(X.p.y, 1.475 + 0.05 * (k / 3), 1e-12) << k;
    EXPECT_NEAR(X.q.Yaw(), 0, 1e-12);
  }
  const std::string head =
      "simulation: {physics: kinematic}\nmodels:\n  - {model: disc.yaml, count: 400, "
      "distribute: {region: {min: [0, 0], max: [0.5, 0.5]}, ";
  EXPECT_CONTAINS(ErrorOfWorld(head + "lattice: {spacing: 0.03}}}\n"),
                  "world.yaml:3:108: a lattice 'spacing' of 0.03 m is less than the footprint "
                  "diameter of the disc model (0.033 m): neighbouring copies would overlap");
  EXPECT_CONTAINS(ErrorOfWorld(head + "lattice: {spacing: 0.05}}}\n"),
                  "world.yaml:3:98: the lattice does not fit: disc copy 0 of 400 would leave the "
                  "region from [0, 0] to [0.5, 0.5] or overlap");
  EXPECT_CONTAINS(ErrorOfWorld(head + "lattice: {spacing: 0.05, shape: round}}}\n"),
                  "'shape' must be square or hexagonal (got 'round')");
  EXPECT_CONTAINS(ErrorOfWorld(head + "clearance: 0.01, lattice: {spacing: 0.05}}}\n"),
                  "'clearance' is for random placement; a lattice's 'spacing' sets the gap");
}

TEST_F(WorldCopiesTest, SpatialOrderNumbersTheDrawnCopiesAlongTheArena) {
  Write("disc.yaml",
        "model: disc\nobjects: {name: body, type: shape, shape: cylinder, radius: 0.05, "
        "height: 0.1}\n");
  const auto world = [](const std::string& order) {
    return "simulation: {physics: kinematic, seed: 3}\nmodels:\n"
           "  - {model: disc.yaml, count: 400, distribute: {region: {min: [0, 0], max: [10, "
           "10]}" +
           order + "}}\n";
  };
  const auto positions = [](const LoadedWorld& w) {
    std::vector<std::pair<double, double>> p;
    for (const ModelInstance& inst : w.world->scene().instances()) {
      const Pose X = w.world->scene().world_pose(inst.root);
      p.emplace_back(X.p.x, X.p.y);
    }
    return p;
  };
  const auto mean_step = [](const std::vector<std::pair<double, double>>& p) {
    double sum = 0;
    for (size_t k = 1; k < p.size(); ++k)
      sum += std::hypot(p[k].first - p[k - 1].first, p[k].second - p[k - 1].second);
    return sum / static_cast<double>(p.size() - 1);
  };
  const auto drawn = positions(Load(world("")));
  const auto same = positions(Load(world(", order: random")));
  auto spatial = positions(Load(world(", order: spatial")));
  ASSERT_EQ(drawn.size(), 400u);
  EXPECT_EQ(drawn, same);  // random: the default
  // Drawn, copy k + 1 is anywhere (about 5 m on average in a 10 m square);
  // numbered along the curve, it stands near copy k.
  EXPECT_GT(mean_step(drawn), 3);
  EXPECT_LT(mean_step(spatial), 1);
  // The same places, renumbered.
  auto sorted_drawn = drawn;
  std::sort(sorted_drawn.begin(), sorted_drawn.end());
  std::sort(spatial.begin(), spatial.end());
  EXPECT_EQ(sorted_drawn, spatial);
  // Mistakes, at their place in the file.
  EXPECT_CONTAINS(ErrorOfWorld(world(", order: sideways")),
                  "world.yaml:3:94: 'order' must be random or spatial (got 'sideways')");
  EXPECT_CONTAINS(ErrorOfWorld(world(", order: spatial, lattice: {spacing: 0.2}")),
                  "'order' is for random placement; a lattice numbers its copies row by row");
  EXPECT_CONTAINS(
      ErrorOfWorld("simulation: {physics: kinematic}\nmodels:\n"
                   "  - {model: disc.yaml, count: 4, distribute: {order: spatial, region: "
                   "{min: [0, 0], max: [2, 2]}},\n"
                   "     instances: [{index: 1, parameters: {}}]}\n"),
      "'order: spatial' renumbers the copies by where they stand, and 'instances' gives values "
      "to copies by number: use one or the other");
}

// A fixed copy clear of the walls but outside them loads (an observer, a
// beacon may stand there), with a warning naming it and the arena's extent;
// inside, near the inner edge or without an arena, nothing is said. So
// does a region to distribute copies in that reaches past the walls.
TEST_F(WorldCopiesTest, CopiesPlacedOutsideTheArenaAreWarnedOf) {
  const auto warnings = [&](const std::string& arena, const std::string& position) {
    std::string all;
    for (const std::string& w : Load("simulation: {physics: kinematic}\n" + arena +
                                     "models: [{model: bot.yaml, position: " + position + "}]\n")
                                    .warnings)
      all += w + "\n";
    return all;
  };
  EXPECT_CONTAINS(warnings("arena: {size: 4}\n", "[3, 0.5]"),
                  "world.yaml:3:38: this bot at [3, 0.5] stands outside the arena's walls (the "
                  "arena is [-2, -2] to [2, 2])");
  EXPECT_CONTAINS(warnings("arena: {size: [4, 2]}\n", "[0, -1.5]"), "outside the arena's walls");
  for (const auto& [arena, position] : {std::pair{"arena: {size: 4}\n", "[1.5, -1.5]"},
                                        {"arena: {size: 4}\n", "[1.99, 0]"},
                                        {"", "[30, 0]"}})
    EXPECT_EQ(warnings(arena, position).find("outside the arena"), std::string::npos)
        << arena << position;
  // A region to distribute in that reaches past the walls: copies drawn
  // there stand outside (it said nothing).
  const auto distributed = [&](const std::string& region) {
    std::string all;
    for (const std::string& w : Load("simulation: {physics: kinematic}\narena: {size: 4}\n"
                                     "models: [{model: bot.yaml, count: 3, distribute: {region: " +
                                     region + "}}]\n")
                                    .warnings)
      all += w + "\n";
    return all;
  };
  EXPECT_CONTAINS(distributed("{min: [3, 3], max: [6, 6]}"),
                  "world.yaml:3:59: the region from [3, 3] to [6, 6] reaches outside the "
                  "arena's walls (the arena is [-2, -2] to [2, 2]): bot copies drawn there "
                  "stand outside them");
  for (const std::string region :
       {"{min: [-2, -2], max: [2, 2]}", "{min: [0, 0], max: [1, 1]}", "arena"})
    EXPECT_EQ(distributed(region).find("outside the arena"), std::string::npos) << region;
}

// An obstacle is one to placement when it reaches into the copies' heights
// (the band from the ground to the tallest copy's top, as the engines'
// rule for static shapes): a shade hung 0.5 m above 2 cm robots refused
// the one under it as "overlapping"; a floor slab below them is none either.
TEST_F(WorldCopiesTest, OnlyObstaclesAtTheCopiesHeightsKeepThemAway) {
  Write("puck.yaml",
        "model: puck\nobjects: {name: body, type: shape, shape: cylinder, radius: 0.02, "
        "height: 0.02}\n");
  const auto world = [](const std::string& obstacle_z, const std::string& placement) {
    return "simulation: {physics: kinematic}\narena: {size: 2}\nobstacles:\n"
           "  - {shape: box, size: [0.4, 0.4, 0.02], position: [0.5, 0, " +
           obstacle_z + "]}\nmodels:\n  - " + placement + "\n";
  };
  const std::string under = "{model: puck.yaml, position: [0.5, 0]}";
  EXPECT_EQ(ErrorOfWorld(world("0.5", under)), "");     // above
  EXPECT_EQ(ErrorOfWorld(world("-0.01", under)), "");   // a slab, top at z = 0
  EXPECT_CONTAINS(ErrorOfWorld(world("0.015", under)),  // reaching 5 mm in
                  "world.yaml:6:34: this puck at [0.5, 0] overlaps a wall, an obstacle");
  // Distributed copies: under the shade, some stand below it.
  const auto inside = [&](const std::string& z) {
    LoadedWorld w = Load(world(z,
                               "{model: puck.yaml, count: 20, distribute: {region: {min: [0.35, "
                               "-0.15], max: [0.65, 0.15]}}}"));
    return w.world->scene().instances().size();
  };
  EXPECT_EQ(inside("0.5"), 20u);
  EXPECT_CONTAINS(ErrorOfWorld(world("0.01",
                                     "{model: puck.yaml, count: 20, distribute: "
                                     "{region: {min: [0.35, -0.15], max: [0.65, "
                                     "0.15]}}}")),
                  "cannot place 20 puck copies");
}

TEST_F(WorldCopiesTest, CopiesThatCannotBePlacedApartAreNamedWithTheirCount) {
  Write("disc.yaml",
        "model: disc\nobjects: {name: body, type: shape, shape: cylinder, radius: 0.5, "
        "height: 0.1}\n");
  // Two fixed copies on one spot: the second is refused at its position.
  EXPECT_CONTAINS(ErrorOfWorld("simulation: {physics: kinematic}\nmodels:\n"
                               "  - {model: disc.yaml, position: [0, 0]}\n"
                               "  - {model: disc.yaml, position: [0.5, 0]}\n"),
                  "world.yaml:4:34: this disc at [0.5, 0] overlaps a wall, an obstacle, the map "
                  "or another placed copy (its footprint: a disc of radius 0.5 m about [x, y] "
                  "that holds every shape of the model)");
  // Distributed copies keep clear of fixed ones listed after them: 100
  // pebbles around a disc that fills a fifth of their region (placed
  // blindly, each would land on it with a chance of about 1 in 4, all 100
  // missing it with one of 1e-13), and too many for their region are
  // refused naming how many fitted.
  Write("pebble.yaml",
        "model: pebble\nobjects: {name: body, type: shape, shape: cylinder, radius: 0.05, "
        "height: 0.1}\n");
  LoadedWorld w = Load(
      "simulation: {physics: kinematic}\nmodels:\n"
      "  - {model: pebble.yaml, count: 100, distribute: {region: {min: [0, 0], max: [2, 2]}}}\n"
      "  - {model: disc.yaml, position: [1, 1]}\n");
  const Scene& scene = w.world->scene();
  ASSERT_EQ(scene.instances().size(), 101u);
  for (int k = 0; k < 100; ++k) {
    const Vec3 p = scene.world_pose(scene.instance(k).root).p;
    EXPECT_GE(std::hypot(p.x - 1, p.y - 1), 0.55 - 1e-9) << k;
  }
  const std::string e = ErrorOfWorld(
      "simulation: {physics: kinematic}\nmodels:\n"
      "  - {model: disc.yaml, count: 9, distribute: {region: {min: [0, 0], max: [3, 1]}}}\n");
  EXPECT_CONTAINS(e, "world.yaml:3:");
  EXPECT_CONTAINS(e, "cannot place 9 disc copies in the region");
  EXPECT_CONTAINS(e, "without overlap (placed ");
}

TEST_F(WorldCopiesTest, ScaledCopiesWithTheirOwnValuesShareTheScaledMesh) {
  Write("cube.obj",
        "v -1 -1 -1\nv 1 -1 -1\nv 1 1 -1\nv -1 1 -1\nv -1 -1 1\nv 1 -1 1\nv 1 1 1\nv -1 1 1\n"
        "f 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\nf 4 1 5 8\n");
  Write("cube.yaml",
        "model: cube\n"
        "parameters: {m: 1}\n"
        "objects: {type: shape, shape: mesh, file: cube.obj, dynamic: true, mass: $m}\n");
  const LoadedWorld w = Load(
      "simulation: {physics: kinematic}\n"
      "models:\n"
      "  - {model: cube.yaml, count: 3, scale: 0.1, "
      "distribute: {region: {min: [-5, -5], max: [5, 5]}},\n"
      "     instances: [{index: 1, parameters: {m: 2}}]}\n");
  const Scene& scene = w.world->scene();
  const ShapeData& own = scene.shape(scene.instance(1).root);
  EXPECT_DOUBLE_EQ(own.mass, 2 * 0.001);  // its own mass, scaled by 0.1^3
  EXPECT_DOUBLE_EQ(scene.shape(scene.instance(0).root).mass, 0.001);
  for (int k : {0, 2}) EXPECT_EQ(scene.shape(scene.instance(k).root).mesh, own.mesh) << k;
  EXPECT_DOUBLE_EQ(own.mesh->CenteredExtents().x, 0.2);
}

// What a progress line is made of while a large world loads: the copies
// drawn at random (every 4,096 and at the end), then their arrays'
// memory populated (in bytes), then the copies built (every 256 and at the
// end), each stage counting up to its total, in that order.
TEST_F(WorldCopiesTest, TheLoadTellsItsProgressStageByStage) {
  using Stage = LoadOptions::LoadStage;
  struct Told {
    Stage stage;
    int64_t done, total;
  };
  std::vector<Told> told;
  LoadOptions options;
  options.threads = 2;
  options.progress = [&told](Stage stage, int64_t done, int64_t total) {
    told.push_back({stage, done, total});
  };
  LoadWorld(Write("world.yaml",
                  "simulation: {physics: kinematic}\n"
                  "models:\n"
                  "  - {model: bot.yaml, position: [-1, -1]}\n"
                  "  - model: bot.yaml\n"
                  "    count: 10000\n"
                  "    distribute: {region: {min: [0, 0], max: [100, 100]}}\n"),
            options, registry_);
  ASSERT_FALSE(told.empty());
  // Stage by stage, each counting up; "building them" (none built yet) is
  // said before the memory they need is populated.
  std::vector<int64_t> placed, built;
  int64_t populated_total = -1;
  size_t last_placing = 0, first_populating = told.size(), last_populating = 0;
  for (size_t i = 0; i < told.size(); ++i) {
    const Told& t = told[i];
    EXPECT_LE(t.done, t.total) << i;
    if (t.stage == Stage::kPlacing) {
      EXPECT_EQ(t.total, 10000) << "the drawn copies, not the fixed one";
      if (!placed.empty()) {
        EXPECT_GT(t.done, placed.back()) << i;
      }
      placed.push_back(t.done);
      last_placing = i;
    } else if (t.stage == Stage::kPopulating) {
      EXPECT_GT(t.total, 10000 * 64) << "bytes of 10,000 copies' rows";
      EXPECT_TRUE(populated_total < 0 || populated_total == t.total);
      populated_total = t.total;
      first_populating = std::min(first_populating, i);
      last_populating = i;
    } else {
      EXPECT_EQ(t.total, 10001) << "every copy";
      if (!built.empty()) {
        EXPECT_GE(t.done, built.back()) << i;
      }
      built.push_back(t.done);
    }
  }
  ASSERT_GE(placed.size(), 3u) << "at 4,095, 8,191 and the end";
  EXPECT_EQ(placed.back(), 10000);
  ASSERT_GE(populated_total, 0) << "the arrays' memory was not told";
  EXPECT_EQ(told[last_populating].done, populated_total) << "it ends at its total";
  EXPECT_LT(last_placing, first_populating);
  ASSERT_GE(built.size(), 3u);
  EXPECT_EQ(built.back(), 10001);
  EXPECT_EQ(told.back().stage, Stage::kBuilding);
}

}  // namespace
}  // namespace swarmsim
