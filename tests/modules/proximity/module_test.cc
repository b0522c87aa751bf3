// modules/proximity/module.cc: what Register adds to a registry (the
// module, the proximity_sensor type listed where it always was), the
// module a world makes (sensing in the sense phase) and the world's line
// of sight it provides when the world starts.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <string>
#include <utility>

#include "framework/line_of_sight.h"
#include "framework/object_type.h"
#include "framework/proximity_readings.h"
#include "framework/registry.h"
#include "framework/world.h"
#include "modules/builtin.h"
#include "modules/proximity/proximity.h"
#include "modules/proximity/proximity_sensor.h"

namespace swarmsim::proximity {
namespace {

ShapeData Box(double x, double y, double z) {
  ShapeData s;
  s.kind = ShapeKind::kBox;
  s.size = {x, y, z};
  return s;
}

// A world of the built-in modules (kinematic physics: nothing moves) with
// a static wall 0.2 m thick whose near face is at x = 0.9.
class ModuleWorld {
 public:
  ModuleWorld() {
    RegisterBuiltinModules(&registry_);
    WorldSettings settings;
    settings.physics = "kinematic";
    settings.threads = 1;
    world_ = std::make_unique<World>(settings, registry_);
    wall_ = world_->scene().AddShape("wall", {}, {{1, 0, 0.5}, {}}, Box(0.2, 4, 1));
  }
  World& world() { return *world_; }
  Scene& scene() { return world_->scene(); }
  ObjectId wall() const { return wall_; }

 private:
  ModuleRegistry registry_;
  std::unique_ptr<World> world_;
  ObjectId wall_;
};

TEST(ProximityModuleTest, RegistersAsProximity) {
  const auto info = ModuleInfo();
  EXPECT_EQ(info.kind, "proximity");
  EXPECT_EQ(info.name, "proximity");
  EXPECT_FALSE(info.version.empty());
  EXPECT_FALSE(info.description.empty());
  EXPECT_NE(MakeBackend(), nullptr);
}

// The module for every world, and the type: listed (and hashed) right
// after `joint`, where it was when it was a built-in type, so the golden
// hashes and the loader's type lists stay.
TEST(ProximityModuleTest, RegisterAddsTheModuleAndTheTypeAfterJoint) {
  ModuleRegistry registry;
  Register(&registry);
  const ModuleDescriptor* module = registry.FindModule("proximity");
  ASSERT_NE(module, nullptr);
  EXPECT_EQ(module->info.kind, "proximity");
  EXPECT_TRUE(module->every_world);
  EXPECT_EQ(module->order, 100);
  ASSERT_EQ(registry.object_types().size(), 1u);
  EXPECT_EQ(registry.object_types()[0], &SensorTypeDescriptor());
  EXPECT_STREQ(SensorTypeDescriptor().name, "proximity_sensor");

  ModuleWorld w;  // every built-in module
  ObjectType sensor, joint;
  ASSERT_TRUE(FindSensorType(w.scene(), &sensor));
  ASSERT_TRUE(w.scene().FindType("joint", &joint));
  const auto order = w.scene().listing_order();
  size_t at = 0;
  while (at < order.size() && order[at] != joint) ++at;
  ASSERT_LT(at + 1, order.size());
  EXPECT_EQ(order[at + 1], sensor);
}

TEST(ProximityModuleTest, ProvidesTheWorldsLineOfSightWhenTheWorldStarts) {
  ModuleWorld w;
  EXPECT_EQ(w.world().line_of_sight(), nullptr);
  w.world().Start();
  const LineOfSight* line_of_sight = w.world().line_of_sight();
  ASSERT_NE(line_of_sight, nullptr);
  EXPECT_TRUE(line_of_sight->SegmentBlocked({0, 0, 0.5}, {2, 0, 0.5}));     // through the wall
  EXPECT_FALSE(line_of_sight->SegmentBlocked({0, 0, 0.5}, {0.8, 0, 0.5}));  // short of it
  EXPECT_FALSE(line_of_sight->SegmentBlocked({0, 0, 0.5}, {0, 2, 0.5}));    // along it
  EXPECT_FALSE(line_of_sight->SegmentBlocked({2, 3, 0.5}, {0, 3, 0.5}));    // past its end
}

TEST(ProximityModuleTest, SensesInTheWorldsStep) {
  ModuleWorld w;
  ProximitySensorData ray;
  ray.settings.Edit().range = 5;
  // Its +z along the world's +x.
  const Pose X_WS{{0, 0, 0.5}, Quat::FromAxisAngle({0, 1, 0}, M_PI / 2)};
  const ObjectId eye = AddSensor(&w.scene(), "eye", {}, X_WS, ray);
  w.world().Step();
  const ProximitySensorData& reading = Sensor(w.scene(), eye);
  EXPECT_TRUE(reading.detected);
  EXPECT_NEAR(reading.distance, 0.9, 1e-9);
  EXPECT_EQ(reading.detected_object, w.wall());
}

// The wall moved by a script (as sim.setObjectPose), a path or a joint, or
// removed, or rescaled: a robot's sensor and the line of sight find it
// where it is now, from the next sense phase on, as often as it moves.
TEST(ProximityModuleTest, SensesAStaticShapeWhereAScriptOrAPathMovedIt) {
  ModuleWorld w;
  Scene& scene = w.scene();
  ProximitySensorData ray;
  ray.settings.Edit().range = 5;
  const ObjectId bot = scene.AddDummy("bot", {}, {});
  const ObjectId eye =
      AddSensor(&scene, "eye", bot, {{0, 0, 0.5}, Quat::FromAxisAngle({0, 1, 0}, M_PI / 2)}, ray);
  scene.MakeModelInstance(bot, "bot", "bot#0");
  w.world().Step();
  EXPECT_NEAR(Sensor(scene, eye).distance, 0.9, 1e-9);
  const LineOfSight& sight = *w.world().line_of_sight();
  for (double x : {2.5, 1.7, 3.1}) {  // near face at x - 0.1
    scene.SetWorldPose(w.wall(), {{x, 0, 0.5}, {}});
    w.world().Step();
    EXPECT_TRUE(Sensor(scene, eye).detected);
    EXPECT_NEAR(Sensor(scene, eye).distance, x - 0.1, 1e-9);
    EXPECT_EQ(Sensor(scene, eye).detected_object, w.wall());
    EXPECT_FALSE(sight.SegmentBlocked({0, 0, 0.5}, {x - 0.2, 0, 0.5})) << "short of it now";
    EXPECT_TRUE(sight.SegmentBlocked({0, 0, 0.5}, {x + 0.2, 0, 0.5})) << "through it now";
  }
  // Another static shape added by a script, then scaled: indexed as it is.
  const ObjectId post = scene.AddShape("post", {}, {{0.6, 0, 0.5}, {}}, Box(0.2, 0.2, 1));
  w.world().Step();
  EXPECT_NEAR(Sensor(scene, eye).distance, 0.5, 1e-9);
  EXPECT_EQ(Sensor(scene, eye).detected_object, post);
  scene.ScaleSubtree(post, 2);
  w.world().Step();
  EXPECT_NEAR(Sensor(scene, eye).distance, 0.4, 1e-9);
  scene.RemoveSubtree(post);
  w.world().Step();
  EXPECT_NEAR(Sensor(scene, eye).distance, 3.0, 1e-9) << "the moved wall again";
}

// What a native controller reads (World::proximity_readings(), the
// plugins' read_proximity_sensor): each sensor's row as the sense phase
// left it, also after a write through MutableSensor, a snapshot restored or
// a sensor added since (what any cache of the readings behind Read() must
// keep right: never a stale copy, never one too short for a new slot).
TEST(ProximityModuleTest, ReadingsReadAsTheRowsAfterEveryChange) {
  ModuleWorld w;
  Scene& scene = w.scene();
  ProximitySensorData ray;
  ray.settings.Edit().range = 5;
  const Quat along_x = Quat::FromAxisAngle({0, 1, 0}, M_PI / 2);
  const Quat along_minus_x = Quat::FromAxisAngle({0, 1, 0}, -M_PI / 2);
  // A robot: a dummy with one sensor towards the wall, one away from it.
  const ObjectId bot = scene.AddDummy("bot", {}, {{0.5, 0, 0}, {}});
  const ObjectId front = AddSensor(&scene, "front", bot, {{0, 0, 0.5}, along_x}, ray);
  const ObjectId back = AddSensor(&scene, "back", bot, {{0, 0, 0.5}, along_minus_x}, ray);
  scene.MakeModelInstance(bot, "bot", "bot#0");
  // A sensor of no robot.
  const ObjectId eye = AddSensor(&scene, "eye", {}, {{0, 0, 0.5}, along_x}, ray);
  const ProximityReadings* readings = nullptr;
  // Read() as 1 / 0 / -1, and the distance read.
  const auto read = [&](ObjectId id) {
    double d = -7;
    const int r = readings->Read(scene, id, &d);
    return std::pair(r, r == 1 ? d : -7.0);
  };
  // Every sensor reads as its row.
  const auto as_rows = [&](const char* when) {
    for (const ObjectId id : {front, back, eye}) {
      const ProximitySensorData& row = Sensor(scene, id);
      EXPECT_EQ(read(id), std::pair(row.detected ? 1 : 0, row.detected ? row.distance : -7.0))
          << scene.PathOf(id) << " " << when;
    }
  };
  w.world().Step();
  readings = w.world().proximity_readings();
  ASSERT_NE(readings, nullptr);
  EXPECT_EQ(read(front).first, 1);
  EXPECT_NEAR(read(front).second, 0.4, 1e-9);
  EXPECT_EQ(read(back), std::pair(0, -7.0));
  EXPECT_NEAR(read(eye).second, 0.9, 1e-9);
  as_rows("after a step");
  // Not sensors, or gone: -1.
  EXPECT_EQ(read(bot).first, -1);
  EXPECT_EQ(read(w.wall()).first, -1);
  EXPECT_EQ(read(ObjectId{}).first, -1);
  EXPECT_EQ(read(ObjectId::FromInteger(1'000'000)).first, -1);

  // A test writes a reading: read as written until the next sense phase.
  MutableSensor(&scene, eye).distance = 0.25;
  EXPECT_EQ(read(eye), std::pair(1, 0.25));
  w.world().Step();
  EXPECT_NEAR(read(eye).second, 0.9, 1e-9);

  // A snapshot restored: its readings, not those of the steps since.
  const std::string saved = w.world().SaveState();
  scene.SetWorldPose(bot, {{0.7, 0, 0}, {}});
  w.world().Step();
  EXPECT_NEAR(read(front).second, 0.2, 1e-9);
  w.world().RestoreState(saved);
  EXPECT_NEAR(read(front).second, 0.4, 1e-9);
  as_rows("after a snapshot restored");

  // A sensor added after the sense phase: its row (nothing yet), not "no
  // such sensor" (its slot is past the packed copy).
  const ObjectId late = AddSensor(&scene, "late", {}, {{0, 0, 0.5}, along_x}, ray);
  EXPECT_EQ(read(late), std::pair(0, -7.0));
  w.world().Step();
  EXPECT_NEAR(read(late).second, 0.9, 1e-9);
  as_rows("after a sensor was added");
  // One removed: -1.
  scene.RemoveSubtree(eye);
  EXPECT_EQ(read(eye).first, -1);
  w.world().Step();
  EXPECT_EQ(read(eye).first, -1);
  EXPECT_NEAR(read(late).second, 0.9, 1e-9);
}

// The lookups of proximity_sensor.h, as the recorder, Python and plugins use them.
TEST(ProximityModuleTest, LookupsFindSensorsAndRefuseOtherObjects) {
  ModuleWorld w;
  const ObjectId eye = AddSensor(&w.scene(), "eye", {}, {}, {});
  EXPECT_NE(FindSensor(w.scene(), eye), nullptr);
  EXPECT_TRUE(IsSensorAt(w.scene(), eye.index()));
  EXPECT_EQ(FindSensor(w.scene(), w.wall()), nullptr);
  EXPECT_EQ(FindSensor(w.scene(), ObjectId{}), nullptr);
  EXPECT_EQ(Sensors(w.scene()).rows.size(), 1u);
  try {
    Sensor(w.scene(), w.wall());
    ADD_FAILURE() << "no error for a shape";
  } catch (const std::exception& e) {
    EXPECT_STREQ(e.what(), "object 'wall' is a shape, not a proximity_sensor");
  }
  // A Scene made without a World gets the type with its first sensor.
  Scene bare;
  EXPECT_EQ(Sensors(bare).rows.size(), 0u);
  const ObjectId s = AddSensor(&bare, "s", {}, {}, {});
  EXPECT_NE(FindSensor(bare, s), nullptr);
}

}  // namespace
}  // namespace swarmsim::proximity
