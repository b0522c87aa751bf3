// The force_sensor type's hooks (force_sensor_type.cc) through a Scene: a
// copy starts unbroken with its settings, thresholds scale as forces (x s^3)
// and torques (x s^4), and the type is a module's, registered after the
// built-in ones.
#include <gtest/gtest.h>

#include <string>

#include "framework/error.h"
#include "framework/object_type.h"
#include "framework/registry.h"
#include "framework/scene.h"
#include "modules/builtin.h"
#include "modules/force_sensor/force_sensor.h"

namespace swarmsim {
namespace {

ObjectType Register(Scene* scene) { return scene->RegisterType(force_sensor::Descriptor()); }

TEST(ForceSensorTypeTest, ACopyStartsUnbrokenWithItsSettings) {
  Scene scene;
  const ObjectType type = Register(&scene);
  const ObjectId root = scene.AddDummy("bot", {}, {});
  ForceSensorData sensor;
  sensor.force_threshold = 5;
  sensor.broken = true;
  sensor.violations = 3;
  scene.AddObject(type, "cell", root, {}, &sensor);
  const ObjectId copy = scene.DuplicateSubtree(root, {});
  const ForceSensorData& copied = force_sensor::Row(scene, scene.FindObject("./cell", copy));
  EXPECT_EQ(copied.force_threshold, 5);
  EXPECT_FALSE(copied.broken);
  EXPECT_EQ(copied.violations, 0);
  scene.ScaleSubtree(copy, 2);
  EXPECT_EQ(force_sensor::Row(scene, scene.FindObject("./cell", copy)).force_threshold, 40);
  EXPECT_EQ(force_sensor::Row(scene, scene.FindObject("./cell", root)).force_threshold, 5);
}

TEST(ForceSensorTypeTest, ThresholdsScaleAsForcesAndTorques) {
  Scene scene;
  const ObjectType type = Register(&scene);
  const ObjectId root = scene.AddDummy("bot", {}, {});
  ForceSensorData force;
  force.force_threshold = 10;
  force.torque_threshold = 1;
  const ObjectId link = scene.AddObject(type, "link", root, {}, &force);
  scene.ScaleSubtree(root, 2);
  EXPECT_DOUBLE_EQ(force_sensor::Row(scene, link).force_threshold, 80);
  EXPECT_DOUBLE_EQ(force_sensor::Row(scene, link).torque_threshold, 16);
  EXPECT_DOUBLE_EQ(scene.size_factor(link), 2);
}

TEST(ForceSensorTypeTest, ARowOfAnotherTypeIsAnError) {
  Scene scene;
  Register(&scene);
  const ObjectId dummy = scene.AddDummy("bot", {}, {});
  EXPECT_THROW(force_sensor::Row(scene, dummy), Error);
}

// The built-in registry has it (`swarmsim modules` lists it), not as a
// built-in type.
TEST(ForceSensorTypeTest, RegisteredByTheModule) {
  ModuleRegistry registry;
  RegisterBuiltinModules(&registry);
  bool found = false;
  for (const ObjectTypeDescriptor* type : registry.object_types())
    found |= std::string(type->name) == kForceSensorTypeName;
  EXPECT_TRUE(found);
  for (const ObjectTypeDescriptor* type : CoreObjectTypes())
    EXPECT_NE(std::string(type->name), kForceSensorTypeName);
}

}  // namespace
}  // namespace swarmsim
