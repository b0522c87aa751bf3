// The Box2D backend with the plane cut into regions (physics_partitions):
// what a user would notice at the borders (robots crossing, pushing,
// meeting, walls), determinism for any thread count, and what a partitioned
// diffusion run trades against one world.
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
#include "modules/dynamics/box2d/plane_partition.h"
#include "tests/modules/box2d_scene.h"

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

// Rows of robots 0.5 m apart, each row driving along x (alternately +x and
// -x) 3 m through strips about 1 m wide: every robot crosses borders. None
// is lost or duplicated, none jumps, each arrives where it would alone.
TEST(Box2dPartition, RobotsCrossBordersAndKeepMoving) {
  Scene scene;
  AddFloor(&scene);
  std::vector<Robot> robots;
  for (int row = 0; row < 6; ++row)
    for (int i = 0; i < 3; ++i)
      robots.push_back(AddRobot(&scene, Name("r", row * 3 + i), -2 + 2.0 * i + 0.1 * row,
                                -1.5 + 0.5 * row, row % 2 ? M_PI : 0));
  Partitioned world(scene, 4);
  const double v = 0.3;
  for (const Robot& robot : robots) SetWheelSpeeds(&scene, robot, v, v);
  std::vector<Vec3> start, last;
  for (const Robot& robot : robots) start.push_back(Position(scene, robot.body));
  last = start;
  double largest_jump = 0;
  Simulate(world.backend.get(), &scene, 10.0, [&] {
    EXPECT_EQ(world.backend->body_count(), static_cast<int>(robots.size()));
    for (size_t i = 0; i < robots.size(); ++i) {
      const Vec3 p = Position(scene, robots[i].body);
      largest_jump = std::max(largest_jump, std::hypot(p.x - last[i].x, p.y - last[i].y));
      last[i] = p;
    }
  });
  EXPECT_LE(largest_jump, v * kDt * kSubsteps * 1.05);  // never more than a step's drive
  for (size_t i = 0; i < robots.size(); ++i) {
    const double heading = i / 3 % 2 ? -1 : 1;
    EXPECT_NEAR((last[i].x - start[i].x) * heading, v * 10, 0.03 * v * 10) << i;
    EXPECT_NEAR(last[i].y, start[i].y, 1e-3) << i;
  }
}

// Two robots driving at each other meet on the border between the two
// regions (halfway between them): each stops the other, neither passes,
// as in one world.
TEST(Box2dPartition, RobotsMeetingHeadOnOnABorderStopEachOther) {
  const auto meet = [](int partitions) {
    Scene scene;
    AddFloor(&scene);
    const Robot a = AddRobot(&scene, "a", -0.5, 0, 0);
    const Robot b = AddRobot(&scene, "b", 0.5, 0, M_PI);
    Partitioned world(scene, partitions);
    SetWheelSpeeds(&scene, a, 0.1, 0.1);
    SetWheelSpeeds(&scene, b, 0.1, 0.1);
    Simulate(world.backend.get(), &scene, 8.0);
    return std::pair{Position(scene, a.body).x, Position(scene, b.body).x};
  };
  const auto [a2, b2] = meet(2);
  const auto [a1, b1] = meet(1);
  const double contact = 2 * RobotSpec{}.radius;
  EXPECT_LT(a2, b2);                     // not through each other
  EXPECT_NEAR(b2 - a2, contact, 0.002);  // touching, not overlapping
  EXPECT_NEAR(a2 + b2, 0, 0.01);         // they meet on the border
  EXPECT_NEAR(a2, a1, 0.01);             // as in one world
  EXPECT_NEAR(b2, b1, 0.01);
}

// A robot pushes a crate from its own region into the next one: the crate
// moves on in the next region and ends where one world puts it.
TEST(Box2dPartition, RobotPushesACrateAcrossABorder) {
  const auto push = [](int partitions) {
    Scene scene;
    AddFloor(&scene);
    const Robot pusher = AddRobot(&scene, "pusher", -1, 0, 0);
    const ObjectId crate = AddCrate(&scene, -0.75, 0, 0.15, 0.3);
    // Idle robots far off the pushing line set the border at about x = 0.4.
    AddRobot(&scene, "idle0", 1.5, 2, 0);
    AddRobot(&scene, "idle1", 2, 2, 0);
    Partitioned world(scene, partitions);
    SetWheelSpeeds(&scene, pusher, 0.1, 0.1);
    Simulate(world.backend.get(), &scene, 15.0);
    return std::pair{Position(scene, pusher.body), Position(scene, crate)};
  };
  const auto [robot2, crate2] = push(2);
  const auto [robot1, crate1] = push(1);
  EXPECT_GT(crate2.x, 0.6);  // pushed well past the border
  EXPECT_LT(robot2.x, crate2.x);
  EXPECT_NEAR(crate2.x, crate1.x, 0.02);
  EXPECT_NEAR(crate2.y, crate1.y, 0.02);
  EXPECT_NEAR(robot2.x, robot1.x, 0.02);
}

// A wall along x crosses every region; robots in each region drive into it
// and none gets through, and the wall is solid where it starts and ends.
TEST(Box2dPartition, AWallSpanningEveryRegionIsSolidInEach) {
  Scene scene;
  AddFloor(&scene);
  AddWall(&scene, 0, 0, 10, 0.1);
  std::vector<Robot> robots;
  for (int i = 0; i < 10; ++i)
    robots.push_back(AddRobot(&scene, Name("r", i), -4.5 + i, -0.5, M_PI / 2 + 0.2 * (i % 3)));
  Partitioned world(scene, 5);
  for (const Robot& robot : robots) SetWheelSpeeds(&scene, robot, 0.3, 0.3);
  double deepest = -1;
  Simulate(world.backend.get(), &scene, 5.0, [&] {
    for (const Robot& robot : robots)
      deepest = std::max(deepest, Position(scene, robot.body).y + robot.spec.radius + 0.05);
  });
  EXPECT_LT(deepest, 0.002);  // at most the solver's slop into the wall face
  for (const Robot& robot : robots) EXPECT_GT(Position(scene, robot.body).y, -0.2);  // reached it
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
    PartitionedPlaneWorld probe(Options{}, {.partitions = partitions});
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

// More regions than bodies: one region per body, none empty.
TEST(Box2dPartition, MorePartitionsThanBodiesIsOneRegionPerBody) {
  Scene scene;
  AddRobot(&scene, "a", 0, 0, 0);
  AddRobot(&scene, "b", 1, 0, 0);
  PartitionedPlaneWorld world(Options{}, {.partitions = 64});
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
}

}  // namespace
}  // namespace swarmsim::box2d
