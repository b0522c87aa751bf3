// A plane world's part in a partitioned plane (plane_world_regions.cc): what
// a user would notice at the borders — robots crossing, pushing a crate
// across, meeting head on, walls solid in every region.

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

}  // namespace
}  // namespace swarmsim::box2d
