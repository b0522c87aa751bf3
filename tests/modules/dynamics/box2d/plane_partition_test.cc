// The Box2D backend with the plane cut into regions (plane_partition.cc,
// physics_partitions): determinism for any thread count, how many regions,
// and what a partitioned diffusion run trades against one world.

#include "modules/dynamics/box2d/plane_partition.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "framework/dynamics_backend.h"
#include "framework/scene.h"
#include "framework/scheduler.h"
#include "framework/state_hash.h"
#include "modules/dynamics/box2d/box2d_backend.h"
#include "tests/modules/dynamics/box2d/box2d_scene.h"

namespace swarmsim::box2d {
namespace {

using namespace box2d::scene_kit;  // NOLINT: the scene helpers

// A backend with `partitions` regions (0: auto) stepping on `threads`.
struct Partitioned {
  Partitioned(const Scene& scene, int partitions, int threads = 2) : scheduler(threads) {
    DynamicsSettings settings;
    settings.partitions = partitions;
    settings.scheduler = &scheduler;
    backend = MakeBackend();
    backend->Build(scene, settings);
  }
  TaskScheduler scheduler;
  std::unique_ptr<DynamicsBackend> backend;
};

std::string Name(const char* prefix, int i) {
  std::string name = prefix;
  name += std::to_string(i);
  return name;
}

// A crate (dynamic box) standing on the floor.
ObjectId AddCrate(Scene* scene, double x, double y, double size, double mass) {
  ShapeData crate;
  crate.kind = ShapeKind::kBox;
  crate.size = {size, size, 0.1};
  crate.dynamic = true;
  crate.mass = mass;
  crate.friction = 0.5;
  return scene->AddShape("crate", {}, {{x, y, 0.05}, {}}, crate);
}

// A busy, walled scene of robots driving curves and pushing crates across
// borders: the state hash.
uint64_t BusyHash(int robots_count, int partitions, int threads, int* regions = nullptr) {
  Scene scene;
  AddFloor(&scene);
  const double side = std::sqrt(static_cast<double>(robots_count)) * 0.5;
  AddWall(&scene, 0, side / 2 + 0.05, side + 0.2, 0.1);
  AddWall(&scene, 0, -side / 2 - 0.05, side + 0.2, 0.1);
  AddWall(&scene, side / 2 + 0.05, 0, 0.1, side + 0.2);
  AddWall(&scene, -side / 2 - 0.05, 0, 0.1, side + 0.2);
  std::mt19937 random(7);
  std::uniform_real_distribution<double> unit(0, 1);
  std::vector<Robot> robots;
  const int per_row = static_cast<int>(std::ceil(std::sqrt(robots_count)));
  for (int i = 0; i < robots_count; ++i) {
    const double x = -side / 2 + 0.25 + 0.5 * (i % per_row),
                 y = -side / 2 + 0.25 + 0.5 * (i / per_row);
    if (i % 7 == 3)
      AddCrate(&scene, x, y, 0.1, 0.2);
    else
      robots.push_back(AddRobot(&scene, Name("r", i), x, y, 2 * M_PI * unit(random)));
  }
  StateHasher hasher;
  Partitioned world(scene, partitions, threads);
  for (size_t i = 0; i < robots.size(); ++i)
    SetWheelSpeeds(&scene, robots[i], 0.05 + 0.1 * unit(random), 0.05 + 0.1 * unit(random));
  Simulate(world.backend.get(), &scene, 4.0);
  for (uint32_t s = 0; s < scene.slot_count(); ++s) hasher.AddValue(scene.world_pose_at(s));
  world.backend->HashState(&hasher);
  if (regions) {
    PartitionedPlaneWorld probe(Options{}, {.partitions = partitions, .options = nullptr});
    probe.Build(scene);
    *regions = probe.region_count();
  }
  return hasher.Digest();
}

TEST(Box2dPartition, HashIsTheSameForAnyThreadCount) {
  const uint64_t one = BusyHash(200, 4, 1);
  EXPECT_EQ(BusyHash(200, 4, 2), one);
  EXPECT_EQ(BusyHash(200, 4, 4), one);
  EXPECT_NE(BusyHash(200, 1, 2), one);  // the partition is in effect (and part of the model)
}

TEST(Box2dPartition, AutoPicksRegionsFromTheSceneNotTheThreads) {
  int regions = 0;
  const uint64_t one = BusyHash(1500, 0, 1, &regions);
  EXPECT_EQ(regions, 1500 / PartitionedPlaneWorld::kAutoBodiesPerRegion);
  EXPECT_EQ(BusyHash(1500, 0, 2), one);
  EXPECT_EQ(BusyHash(1500, 0, 4), one);
  BusyHash(100, 0, 2, &regions);
  EXPECT_EQ(regions, 1);  // small swarms stay in one world
}

// Past kMaxStrips regions the arena is a grid (columns cut into rows), near
// square here, and the result is still the same for any thread count.
TEST(Box2dPartition, ManyRegionsAreAGridAndGiveTheSameHashForAnyThreadCount) {
  int regions = 0;
  const uint64_t one = BusyHash(1500, 36, 1, &regions);
  EXPECT_EQ(regions, 36);
  EXPECT_EQ(BusyHash(1500, 36, 2), one);
  EXPECT_EQ(BusyHash(1500, 36, 3), one);
  EXPECT_NE(BusyHash(1500, 6, 2), one);
  Scene scene;
  for (int i = 0; i < 1600; ++i) AddRobot(&scene, Name("r", i), 0.5 * (i % 40), 0.5 * (i / 40), 0);
  PartitionedPlaneWorld grid(Options{}, {.partitions = 36, .options = nullptr});
  grid.Build(scene);
  EXPECT_EQ(grid.column_count(), 6);
  EXPECT_EQ(grid.row_count(), 6);
  EXPECT_EQ(grid.body_count(), 1600);
  PartitionedPlaneWorld strips(Options{}, {.partitions = 16, .options = nullptr});
  strips.Build(scene);
  EXPECT_EQ(strips.column_count(), 16);
  EXPECT_EQ(strips.row_count(), 1);
  // A long arena (40 x 10 m) gets more columns than rows: regions stay near
  // square, and near the number asked for.
  Scene corridor;
  for (int i = 0; i < 1600; ++i)
    AddRobot(&corridor, Name("r", i), 0.5 * (i % 80), 0.5 * (i / 80), 0);
  PartitionedPlaneWorld long_grid(Options{}, {.partitions = 40, .options = nullptr});
  long_grid.Build(corridor);
  EXPECT_GT(long_grid.column_count(), long_grid.row_count());
  const double aspect = (39.5 / long_grid.column_count()) / (9.5 / long_grid.row_count());
  EXPECT_GT(aspect, 0.5);
  EXPECT_LT(aspect, 2.0);
  EXPECT_LE(long_grid.region_count(), 40);
  EXPECT_GE(long_grid.region_count(), 30);
}

// More regions than bodies: one region per body, none empty.
TEST(Box2dPartition, MorePartitionsThanBodiesIsOneRegionPerBody) {
  Scene scene;
  AddRobot(&scene, "a", 0, 0, 0);
  AddRobot(&scene, "b", 1, 0, 0);
  PartitionedPlaneWorld world(Options{}, {.partitions = 64, .options = nullptr});
  world.Build(scene);
  EXPECT_EQ(world.region_count(), 2);
  EXPECT_EQ(world.body_count(), 2);
}

// Diffusion as in worlds/diffusion.yaml, with the controller's rule in C++:
// drive straight; while another robot or a wall is within a bumper's reach
// ahead, turn in place (so robots do touch). Counts what a user of the
// statistics would look at.
struct DiffusionFigures {
  double mean_free_path = 0;     // m driven per contact onset (robot or wall)
  int robot_contacts = 0;        // onsets of robot-robot contact
  int wall_contacts = 0;         // onsets of robot-wall contact
  double wall_penetration = 0;   // m, deepest a robot went into a wall
  double robot_penetration = 0;  // m, deepest overlap of two robots
};

DiffusionFigures RunDiffusion(int partitions) {
  constexpr int kRobots = 400;
  constexpr double kSpeed = 0.1, kSense = 0.01;  // m/s; m, a bumper
  const double half = std::sqrt(kRobots) / 2;    // 1 robot per m^2
  Scene scene;
  AddFloor(&scene);
  AddWall(&scene, 0, half + 0.05, 2 * half + 0.2, 0.1);
  AddWall(&scene, 0, -half - 0.05, 2 * half + 0.2, 0.1);
  AddWall(&scene, half + 0.05, 0, 0.1, 2 * half + 0.2);
  AddWall(&scene, -half - 0.05, 0, 0.1, 2 * half + 0.2);
  std::mt19937 random(3);
  std::uniform_real_distribution<double> unit(0, 1);
  std::vector<Robot> robots;
  for (int i = 0; i < kRobots; ++i) {
    const double x = -half + 0.5 + (i % 20), y = -half + 0.5 + (i / 20);
    robots.push_back(AddRobot(&scene, Name("r", i), x + 0.3 * (unit(random) - 0.5),
                              y + 0.3 * (unit(random) - 0.5), 2 * M_PI * unit(random)));
  }
  Partitioned world(scene, partitions);
  const double r = RobotSpec{}.radius;
  DiffusionFigures out;
  std::vector<char> touching(kRobots * kRobots, 0), at_wall(kRobots, 0);
  std::vector<Vec3> last;
  for (const Robot& robot : robots) last.push_back(Position(scene, robot.body));
  double driven = 0;
  for (int step = 0; step < 600; ++step) {
    for (int i = 0; i < kRobots; ++i) {
      const Vec3 p = Position(scene, robots[i].body);
      const double yaw = Yaw(scene, robots[i].body);
      const Vec3 ahead{std::cos(yaw), std::sin(yaw), 0};
      bool blocked =
          std::max(std::abs(p.x + ahead.x * kSense), std::abs(p.y + ahead.y * kSense)) > half - r;
      for (int j = 0; j < kRobots && !blocked; ++j) {
        const Vec3 d = Position(scene, robots[j].body) - p;
        blocked = j != i && d.x * d.x + d.y * d.y < (2 * r + kSense) * (2 * r + kSense) &&
                  d.x * ahead.x + d.y * ahead.y > 0;
      }
      SetWheelSpeeds(&scene, robots[i], kSpeed, blocked ? -kSpeed : kSpeed);
    }
    world.backend->Step(&scene, kDt, kSubsteps);
    scene.UpdateWorldPoses();
    for (int i = 0; i < kRobots; ++i) {
      const Vec3 p = Position(scene, robots[i].body);
      driven += std::hypot(p.x - last[i].x, p.y - last[i].y);
      last[i] = p;
      const double wall = r - (half - std::max(std::abs(p.x), std::abs(p.y)));
      out.wall_penetration = std::max(out.wall_penetration, wall);
      const bool wall_now = wall > -0.001;
      out.wall_contacts += wall_now && !at_wall[i];
      at_wall[i] = wall_now;
      for (int j = 0; j < i; ++j) {
        const Vec3 d = last[j] - p;
        const double gap = std::hypot(d.x, d.y) - 2 * r;
        out.robot_penetration = std::max(out.robot_penetration, -gap);
        const bool now = gap < 0.001;
        out.robot_contacts += now && !touching[i * kRobots + j];
        touching[i * kRobots + j] = now;
      }
    }
  }
  out.mean_free_path = driven / std::max(1, out.robot_contacts + out.wall_contacts);
  return out;
}

TEST(Box2dPartition, DiffusionStatisticsMatchOneWorld) {
  const DiffusionFigures one = RunDiffusion(1);
  const DiffusionFigures four = RunDiffusion(4);
  const DiffusionFigures grid = RunDiffusion(25);  // 5 x 5 regions of 16 robots: corners
  std::printf(
      "diffusion 400 robots 60 s: partitions 1 / 4: mean free path %.3f / %.3f m, robot "
      "contacts %d / %d, wall contacts %d / %d, wall penetration %.2f / %.2f mm, robot overlap "
      "%.2f / %.2f mm\n",
      one.mean_free_path, four.mean_free_path, one.robot_contacts, four.robot_contacts,
      one.wall_contacts, four.wall_contacts, 1e3 * one.wall_penetration,
      1e3 * four.wall_penetration, 1e3 * one.robot_penetration, 1e3 * four.robot_penetration);
  EXPECT_GT(one.robot_contacts, 50);  // the run has collisions to compare
  EXPECT_NEAR(four.mean_free_path / one.mean_free_path, 1, 0.15);
  EXPECT_NEAR(static_cast<double>(four.robot_contacts) / one.robot_contacts, 1, 0.15);
  EXPECT_NEAR(static_cast<double>(four.wall_contacts) / one.wall_contacts, 1, 0.15);
  EXPECT_LT(four.wall_penetration, one.wall_penetration + 0.001);
  EXPECT_LT(four.robot_penetration, one.robot_penetration + 0.002);
  std::printf(
      "grid of 25: mean free path %.3f m, robot contacts %d, wall contacts %d, wall penetration "
      "%.2f mm, robot overlap %.2f mm\n",
      grid.mean_free_path, grid.robot_contacts, grid.wall_contacts, 1e3 * grid.wall_penetration,
      1e3 * grid.robot_penetration);
  EXPECT_NEAR(grid.mean_free_path / one.mean_free_path, 1, 0.15);
  EXPECT_NEAR(static_cast<double>(grid.robot_contacts) / one.robot_contacts, 1, 0.15);
  EXPECT_NEAR(static_cast<double>(grid.wall_contacts) / one.wall_contacts, 1, 0.15);
  EXPECT_LT(grid.wall_penetration, one.wall_penetration + 0.001);
  EXPECT_LT(grid.robot_penetration, one.robot_penetration + 0.002);
}

}  // namespace
}  // namespace swarmsim::box2d
