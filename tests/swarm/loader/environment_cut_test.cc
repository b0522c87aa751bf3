// A map replaced while the world runs (what a mill's cut does,
// Scene::set_environment): proximity sensors see the new map from the next
// step on (the collision module's index follows the same version:
// modules/collision/geometry.cc).
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "framework/environment.h"
#include "framework/registry.h"
#include "framework/world.h"
#include "modules/builtin.h"
#include "modules/proximity/proximity_sensor.h"

namespace swarmsim {
namespace {

std::shared_ptr<const EnvironmentMap> Wall(double x) {
  auto map = std::make_shared<EnvironmentMap>();
  map->source = "test";
  map->resolution = 0.1;
  map->boxes.push_back({{x, -0.5, 0}, {x + 0.1, 0.5, 0.5}});
  map->lo = map->boxes[0].lo;
  map->hi = map->boxes[0].hi;
  return map;
}

TEST(EnvironmentCutTest, SensorsAndDistancesFollowAReplacedMap) {
  ModuleRegistry registry;
  RegisterBuiltinModules(&registry);
  WorldSettings settings;
  settings.physics = "kinematic";
  settings.time_step = 0.1;
  World world(settings, registry);
  world.set_log_sink([](std::string_view) {});
  Scene& scene = world.scene();
  scene.set_environment(Wall(1.0));
  ShapeData body;
  body.kind = ShapeKind::kBox;
  body.size = {0.2, 0.2, 0.2};
  const ObjectId root = scene.AddShape("bot#0", {}, {{0, 0, 0.2}, {}}, body);
  ProximitySensorData ray;
  ray.settings.Edit().range = 3;
  const ObjectId eye = proximity::AddSensor(
      &scene, "eye", root, {{0, 0, 0}, Quat::FromAxisAngle({0, 1, 0}, M_PI / 2)}, ray);
  scene.MakeModelInstance(root, "bot", "bot#0");
  world.Start();
  world.Step();
  EXPECT_TRUE(proximity::Sensor(scene, eye).detected);
  EXPECT_NEAR(proximity::Sensor(scene, eye).distance, 1.0, 1e-9);
  scene.set_environment(Wall(2.0));  // the wall moved back by a cut
  world.Step();
  EXPECT_NEAR(proximity::Sensor(scene, eye).distance, 2.0, 1e-9);
  scene.set_environment(std::make_shared<EnvironmentMap>());  // all cut away
  world.Step();
  EXPECT_FALSE(proximity::Sensor(scene, eye).detected);
  world.Stop();
}

}  // namespace
}  // namespace swarmsim
