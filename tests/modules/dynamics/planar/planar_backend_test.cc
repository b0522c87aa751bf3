// The planar contact backend as registered (planar_backend.cc), driven
// directly (no World): its name and bodies, the same result for any thread
// count.

#include "modules/dynamics/planar/planar_backend.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "framework/dynamics_backend.h"
#include "framework/scene.h"
#include "framework/scheduler.h"
#include "framework/state_hash.h"
#include "tests/modules/dynamics/plane_robot.h"

namespace swarmsim::planar {
namespace {

using plane_test::AddFloor;
using plane_test::AddRobot;
using plane_test::AddWall;
using plane_test::Robot;
using plane_test::SetWheelSpeeds;

constexpr double kDt = 0.01;   // s, one physics substep
constexpr int kSubsteps = 10;  // substeps per control step (0.1 s)

std::unique_ptr<DynamicsBackend> Build(const Scene& scene, TaskScheduler* scheduler = nullptr) {
  auto backend = MakeBackend();
  DynamicsSettings settings;
  settings.scheduler = scheduler;
  backend->Build(scene, settings);
  return backend;
}

TEST(PlanarBackend, RegistersAsPlanarWithOneBodyPerDynamicShape) {
  EXPECT_EQ(ModuleInfo().name, "planar");
  EXPECT_EQ(ModuleInfo().kind, "dynamics");
  Scene scene;
  AddFloor(&scene);
  AddRobot(&scene, "a", 0, 0, 0);
  AddRobot(&scene, "b", 1, 0, 0);
  AddWall(&scene, 3, 0, 0.1, 2);
  EXPECT_EQ(Build(scene)->body_count(), 2);  // not the wheels, the wall or the floor
}

// A crowd in a walled arena, wheel speeds changing every step: the hash after
// 100 steps.
uint64_t CrowdHash(int threads) {
  Scene scene;
  const int side = 24;  // 576 robots, 0.3 m apart in a 7.2 m arena
  const double half = side * 0.15;
  AddWall(&scene, -half - 0.05, 0, 0.1, 2 * half + 0.2);
  AddWall(&scene, half + 0.05, 0, 0.1, 2 * half + 0.2);
  AddWall(&scene, 0, -half - 0.05, 2 * half + 0.2, 0.1);
  AddWall(&scene, 0, half + 0.05, 2 * half + 0.2, 0.1);
  std::vector<Robot> robots;
  for (int i = 0; i < side * side; ++i)
    robots.push_back(AddRobot(&scene, std::string("r") += std::to_string(i),
                              -half + 0.15 + 0.3 * (i % side), -half + 0.15 + 0.3 * (i / side),
                              i * 0.7));
  TaskScheduler scheduler(threads);
  auto backend = Build(scene, &scheduler);
  uint32_t state = 12345;
  const auto draw = [&] {  // a fixed LCG: same commands for every thread count
    state = state * 1664525u + 1013904223u;
    return static_cast<double>(state >> 8) / (1 << 24);
  };
  for (int step = 0; step < 100; ++step) {
    for (const Robot& robot : robots) SetWheelSpeeds(&scene, robot, draw() * 0.3, draw() * 0.3);
    backend->Step(&scene, kDt, kSubsteps);
    scene.UpdateWorldPoses();
  }
  StateHasher hasher;
  backend->HashState(&hasher);
  for (const Robot& robot : robots) hasher.AddValue(scene.world_pose(robot.body));
  return hasher.Digest();
}

TEST(PlanarBackend, SameHashForOneTwoAndFourThreads) {
  const uint64_t one = CrowdHash(1);
  EXPECT_EQ(CrowdHash(2), one);
  EXPECT_EQ(CrowdHash(4), one);
}

}  // namespace
}  // namespace swarmsim::planar
