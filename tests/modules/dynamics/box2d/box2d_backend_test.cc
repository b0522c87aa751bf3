// The Box2D backend as registered (box2d_backend.cc), driven directly (no
// World): its name, repeatable runs, rebuilds, its bare loop. What the plane
// world does is in plane_world_test.cc and plane_world_build_test.cc.

#include "modules/dynamics/box2d/box2d_backend.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "framework/dynamics_backend.h"
#include "framework/scene.h"
#include "framework/state_hash.h"
#include "tests/modules/dynamics/box2d/box2d_scene.h"

namespace swarmsim::box2d {
namespace {

using namespace box2d::scene_kit;  // NOLINT: the scene helpers

std::unique_ptr<DynamicsBackend> Build(const Scene& scene, const Options& options = {}) {
  auto backend = MakeBackend(options);
  backend->Build(scene, {});
  return backend;
}

TEST(Box2dBackend, RegistersAsBox2d) {
  EXPECT_EQ(ModuleInfo().name, "box2d");
  EXPECT_EQ(ModuleInfo().kind, "dynamics");
}

ObjectId AddPassiveCylinder(Scene* scene, double x, double y, double mass, double friction) {
  ShapeData puck;
  puck.kind = ShapeKind::kCylinder;
  puck.size = {0.085, 0, 0.1};
  puck.dynamic = true;
  puck.mass = mass;
  puck.friction = friction;
  return scene->AddShape("puck", {}, {{x, y, 0.05}, {}}, puck);
}

struct RunResult {
  std::vector<Pose> poses;
  uint64_t hash = 0;
};

RunResult RunBusyScene() {
  Scene scene;
  AddFloor(&scene);
  AddWall(&scene, 1.05, 0, 0.1, 4);
  AddWall(&scene, -1.05, 0, 0.1, 4);
  std::vector<Robot> robots;
  for (int i = 0; i < 6; ++i) {
    std::string name = "r";  // (not "r" + ...: GCC 12 -Wrestrict false positive)
    name += std::to_string(i);
    robots.push_back(AddRobot(&scene, name, -0.6 + 0.25 * i, 0.1 * (i % 2), 0.7 * i));
  }
  AddPassiveCylinder(&scene, 0, 0.5, 0.5, 0.5);
  auto backend = Build(scene);
  for (size_t i = 0; i < robots.size(); ++i)
    SetWheelSpeeds(&scene, robots[i], 0.1 + 0.02 * i, 0.15 - 0.01 * i);
  Simulate(backend.get(), &scene, 10.0);
  RunResult out;
  for (uint32_t s = 0; s < scene.slot_count(); ++s) out.poses.push_back(scene.world_pose_at(s));
  StateHasher hasher;
  backend->HashState(&hasher);
  out.hash = hasher.Digest();
  return out;
}

TEST(Box2dBackend, IdenticalRunsAreBitIdentical) {
  const RunResult a = RunBusyScene();
  const RunResult b = RunBusyScene();
  ASSERT_EQ(a.poses.size(), b.poses.size());
  EXPECT_EQ(std::memcmp(a.poses.data(), b.poses.data(), a.poses.size() * sizeof(Pose)), 0);
  EXPECT_EQ(a.hash, b.hash);
}

TEST(Box2dBackend, RebuildsWhenRobotsAreAdded) {
  Scene scene;
  Robot a = AddRobot(&scene, "a", 0, 0, 0);
  auto backend = Build(scene);
  SetWheelSpeeds(&scene, a, 0.05, 0.05);
  Simulate(backend.get(), &scene, 1.0);
  Robot b = AddRobot(&scene, "b", 0, 1, 0);
  SetWheelSpeeds(&scene, b, 0.05, 0.05);
  Simulate(backend.get(), &scene, 1.0);
  EXPECT_EQ(backend->body_count(), 2);
  EXPECT_NEAR(Position(scene, a.body).x, 0.1, 2e-3);
  EXPECT_NEAR(Position(scene, b.body).x, 0.05, 2e-3);
}

TEST(Box2dBackend, BareLoopTimesStepping) {
  Scene scene;
  Robot robot = AddRobot(&scene, "r", 0, 0, 0);
  SetWheelSpeeds(&scene, robot, 0.05, 0.05);
  const Pose before = scene.world_pose(robot.body);
  EXPECT_GE(TimeBareLoop(scene, kDt, kSubsteps, 5), 0.0);
  EXPECT_EQ(scene.world_pose(robot.body), before);  // no write-back
}

}  // namespace
}  // namespace swarmsim::box2d
