// The environment map's voxels as obstacles of the physics backends
// (modules/dynamics/environment_obstacles.h): its voxels at the robots'
// height are walls (Box2D: projected to the plane; ODE: boxes), while the
// floor under them and an overhang above them are not. Driven through a
// World, as a run would.

#include "modules/dynamics/environment_obstacles.h"

#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <string>

#include "framework/registry.h"
#include "framework/scene.h"
#include "framework/world.h"
#include "modules/builtin.h"
#include "modules/environment/octomap_map.h"
#include "tests/shared_maps.h"

namespace swarmsim {
namespace {

// A map of 0.1 m voxels: a floor slab (z -0.1..0) under x, y in [-1, 1];
// a wall whose face is at x = 1 (x 1..1.1, y -1..1, z -0.1..0.4); an
// overhang across the path (x 0.3..0.5, z 0.2..0.4), above the robots.
std::shared_ptr<const EnvironmentMap> WallMap() {
  auto map = std::make_shared<EnvironmentMap>();
  map->source = "wall map";
  map->resolution = 0.1;
  auto voxel = [&](int i, int j, int k) {
    map->boxes.push_back(
        {{i * 0.1, j * 0.1, k * 0.1}, {(i + 1) * 0.1, (j + 1) * 0.1, (k + 1) * 0.1}});
  };
  for (int i = -10; i < 10; ++i)
    for (int j = -10; j < 10; ++j) voxel(i, j, -1);
  for (int j = -10; j < 10; ++j)
    for (int k = -1; k < 4; ++k) voxel(10, j, k);
  for (int i = 3; i < 5; ++i)
    for (int j = -10; j < 10; ++j)
      for (int k = 2; k < 4; ++k) voxel(i, j, k);
  map->lo = {-1, -1, -0.1};
  map->hi = {1.1, 1, 0.4};
  return map;
}

struct Fixture {
  ModuleRegistry registry;
  std::unique_ptr<World> world;
  explicit Fixture(const std::string& physics, int substeps) {
    RegisterBuiltinModules(&registry);
    WorldSettings s;
    s.physics = physics;
    s.time_step = 0.1;
    s.physics_substeps = substeps;
    s.threads = 1;
    world = std::make_unique<World>(s, registry);
    world->set_log_sink([](std::string_view) {});
  }
  Scene& scene() { return world->scene(); }
};

// The Box2D test robot (box2d_backend_test): a cylinder body (radius
// 0.085 m, height 0.1 m) on two velocity-driven wheels, facing +x.
ObjectId AddPlaneRobot(Scene* scene, double speed, double y = 0) {
  ShapeData body;
  body.kind = ShapeKind::kCylinder;
  body.size = {0.085, 0, 0.1};
  body.dynamic = true;
  body.mass = 1.6;
  const ObjectId root = scene->AddShape("bot", {}, {{0, y, 0.05}, {}}, body);
  scene->MakeModelInstance(root, "bot", "bot#" + std::to_string(scene->instances().size()));
  JointData motor;
  motor.settings.Edit().type = JointType::kRevolute;
  motor.settings.Edit().mode = JointMode::kVelocity;
  ShapeData wheel;
  wheel.kind = ShapeKind::kCylinder;
  wheel.size = {0.029, 0, 0.01};
  for (int side : {1, -1}) {
    motor.target_velocity = side * speed / 0.029;
    const ObjectId joint = scene->AddJoint(
        "motor", root,
        {{0, side * 0.07, 0.029 - 0.05}, Quat::FromAxisAngle({1, 0, 0}, -side * M_PI / 2)}, motor);
    scene->AddShape("wheel", joint, {}, wheel);
  }
  return root;
}

// The ODE test robot (ode_backend_test): a box chassis (front 0.15 m ahead
// of its centre) on two dynamic wheels of radius 0.05 m, facing +x.
ObjectId AddWheeledRobot(Scene* scene, double omega, double y = 0) {
  ShapeData chassis;
  chassis.kind = ShapeKind::kBox;
  chassis.size = {0.3, 0.2, 0.05};
  chassis.dynamic = true;
  chassis.mass = 2;
  const ObjectId root = scene->AddShape("chassis", {}, {{0, y, 0.05}, {}}, chassis);
  ShapeData caster;
  caster.kind = ShapeKind::kSphere;
  caster.size = {0.025, 0, 0};
  caster.friction = 0;
  scene->AddShape("caster", root, {{-0.12, 0, -0.025}, {}}, caster);
  ShapeData wheel;
  wheel.kind = ShapeKind::kCylinder;
  wheel.size = {0.05, 0, 0.02};
  wheel.dynamic = true;
  wheel.mass = 0.2;
  wheel.friction = 1.0;
  for (int side : {1, -1}) {
    JointData m;
    m.settings.Edit().type = JointType::kRevolute;
    m.settings.Edit().mode = JointMode::kVelocity;
    m.target_velocity = side * omega;
    m.settings.Edit().max_force = 5;
    const ObjectId motor = scene->AddJoint(
        "motor", root, {{0.05, side * 0.13, 0}, Quat::FromAxisAngle({1, 0, 0}, -side * M_PI / 2)},
        m);
    scene->AddShape("wheel", motor, {}, wheel);
  }
  scene->MakeModelInstance(root, "bot", "bot#" + std::to_string(scene->instances().size()));
  return root;
}

TEST(EnvironmentPhysicsTest, Box2dRobotStopsAtAMapWallAndPassesUnderTheOverhang) {
  Fixture f("box2d", 10);
  const ObjectId bot = AddPlaneRobot(&f.scene(), 0.1);
  const ObjectId beside = AddPlaneRobot(&f.scene(), 0.1, 3);  // where the map has no wall
  f.scene().set_environment(WallMap());
  f.world->Start();
  double max_x = -1;
  for (int i = 0; i < 150; ++i) {  // 15 s at 0.1 m/s: 1.5 m, were there no wall
    f.world->Step();
    max_x = std::max(max_x, f.scene().world_pose(bot).p.x);
  }
  const double contact = 1.0 - 0.085;
  EXPECT_NEAR(f.scene().world_pose(bot).p.x, contact, 3e-3);
  EXPECT_LT(max_x, contact + 3e-3);
  EXPECT_NEAR(f.scene().world_pose(beside).p.x, 1.5, 0.02);
}

TEST(EnvironmentPhysicsTest, OdeRobotStopsAtAMapWallAndPassesUnderTheOverhang) {
  Fixture f("ode", 10);
  const ObjectId bot = AddWheeledRobot(&f.scene(), 4);        // 0.2 m/s
  const ObjectId beside = AddWheeledRobot(&f.scene(), 4, 3);  // where the map has no wall
  f.scene().set_environment(WallMap());
  f.world->Start();
  double max_x = -1;
  for (int i = 0; i < 100; ++i) {  // 10 s: 2 m, were there no wall
    f.world->Step();
    max_x = std::max(max_x, f.scene().world_pose(bot).p.x);
  }
  const double contact = 1.0 - 0.15;  // the chassis' front at the wall's face
  EXPECT_NEAR(f.scene().world_pose(bot).p.x, contact, 0.01);
  EXPECT_LT(max_x, contact + 0.01);
  EXPECT_GT(f.scene().world_pose(bot).p.z, 0.04);  // on the floor, not sunk or lifted
  EXPECT_LT(f.scene().world_pose(bot).p.z, 0.06);
  EXPECT_GT(f.scene().world_pose(beside).p.x, 1.5);
}

}  // namespace
}  // namespace swarmsim
