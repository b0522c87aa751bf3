// The proximity_sensor type's rows: settings shared by the copies of one
// model entry (copy on write), readings per copy, through world files as a
// user writes them.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "framework/registry.h"
#include "framework/world.h"
#include "modules/builtin.h"
#include "modules/proximity/proximity_sensor.h"
#include "swarm/loader/world_loader.h"

namespace swarmsim {
namespace {

namespace fs = std::filesystem;

// Two entries of one model: three robots spread far from everything
// (range 0.5, but the second copy's own range 0.4) and one more facing a
// wall 0.3 m ahead (range 0.25 for its ray, from its entry's parameter).
class ProximitySensorTypeTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("swarmsim_prox_type_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    std::ofstream(dir_ / "bot.yaml")
        << "model: bot\n"
           "parameters: {range: {default: 0.5}}\n"
           "objects:\n"
           "  name: body\n"
           "  type: dummy\n"
           "  children:\n"
           "    - {name: ahead, type: proximity_sensor, range: $range,\n"
           "       position: [0, 0, 0.1], orientation_deg: [0, 90, 0]}\n"
           "    - {name: cone, type: proximity_sensor, range: $range,\n"
           "       volume: cone, angle_deg: 20,\n"
           "       position: [0, 0, 0.1], orientation_deg: [0, 90, 0]}\n";
    std::ofstream(dir_ / "world.yaml")
        << "simulation: {physics: kinematic, time_step: 0.1}\n"
           "obstacles:\n"
           "  - {name: wall, shape: box, size: [0.1, 20, 1], position: [0.35, 0, 0.5]}\n"
           "models:\n"
           "  - {model: bot.yaml, count: 3, distribute: {region: {min: [-10, -2], max: [-6, 2]}},\n"
           "     instances: [{index: 1, parameters: {range: 0.4}}]}\n"
           "  - {model: bot.yaml, position: [0, 0], parameters: {range: 0.35}}\n";
    RegisterBuiltinModules(&registry_);
    loaded_ = LoadWorld(dir_ / "world.yaml", LoadOptions{}, registry_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  Scene& scene() { return loaded_.world->scene(); }
  const ProximitySensorData& Row(int robot, const char* name) {
    return proximity::Sensor(scene(), scene().FindObject(name, scene().instance(robot).root));
  }

  fs::path dir_;
  ModuleRegistry registry_;
  LoadedWorld loaded_;
};

TEST_F(ProximitySensorTypeTest, CopiesOfOneModelEntryShareTheirSettings) {
  ASSERT_EQ(scene().instances().size(), 4u);
  for (const char* name : {"./ahead", "./cone"}) {
    SCOPED_TRACE(name);
    EXPECT_TRUE(Row(2, name).settings.SameAs(Row(0, name).settings));
    EXPECT_DOUBLE_EQ(Row(0, name).range(), 0.5);
    // A copy with its own values has its own settings.
    EXPECT_FALSE(Row(1, name).settings.SameAs(Row(0, name).settings));
    EXPECT_DOUBLE_EQ(Row(1, name).range(), 0.4);
    // Another entry: its own settings.
    EXPECT_FALSE(Row(3, name).settings.SameAs(Row(0, name).settings));
    EXPECT_DOUBLE_EQ(Row(3, name).range(), 0.35);
  }
  // Two sensors of one model are two settings.
  EXPECT_FALSE(Row(0, "./ahead").settings.SameAs(Row(0, "./cone").settings));
  EXPECT_EQ(Row(0, "./cone").volume(), ProximityVolume::kCone);
  EXPECT_EQ(Row(0, "./ahead").volume(), ProximityVolume::kRay);
}

TEST_F(ProximitySensorTypeTest, ReadingsArePerCopy) {
  loaded_.world->Start();
  loaded_.world->Step();
  // Only the last robot is within reach of the wall (0.3 m ahead).
  EXPECT_TRUE(Row(3, "./ahead").detected);
  EXPECT_NEAR(Row(3, "./ahead").distance, 0.3, 1e-9);
  EXPECT_TRUE(Row(3, "./cone").detected);
  EXPECT_NEAR(Row(3, "./cone").point.z, 0.3, 1e-9);
  for (int robot : {0, 1, 2}) {
    EXPECT_FALSE(Row(robot, "./ahead").detected) << robot;
    EXPECT_FALSE(Row(robot, "./cone").detected) << robot;
  }
  // Sensing wrote state only: the copies still share their settings.
  EXPECT_TRUE(Row(2, "./cone").settings.SameAs(Row(0, "./cone").settings));
}

TEST_F(ProximitySensorTypeTest, ScalingOneCopyChangesOnlyThatCopy) {
  scene().ScaleSubtree(scene().instance(2).root, 2);
  EXPECT_DOUBLE_EQ(Row(2, "./ahead").range(), 1.0);
  EXPECT_DOUBLE_EQ(Row(2, "./cone").range(), 1.0);
  EXPECT_FALSE(Row(2, "./ahead").settings.SameAs(Row(0, "./ahead").settings));
  // The others keep theirs.
  EXPECT_DOUBLE_EQ(Row(0, "./ahead").range(), 0.5);
  EXPECT_DOUBLE_EQ(Row(0, "./cone").range(), 0.5);
  // The scaled copy keeps its other settings (a cone of 20 degrees).
  EXPECT_DOUBLE_EQ(Row(2, "./cone").settings->angle, Row(0, "./cone").settings->angle);
}

TEST_F(ProximitySensorTypeTest, ARunTimeCopySharesItsSourcesSettings) {
  const ObjectId copy = scene().DuplicateSubtree(scene().instance(3).root, {});
  const ObjectId ahead = scene().FindObject("./ahead", copy);
  EXPECT_TRUE(proximity::Sensor(scene(), ahead).settings.SameAs(Row(3, "./ahead").settings));
  EXPECT_DOUBLE_EQ(proximity::Sensor(scene(), ahead).range(), 0.35);
}

}  // namespace
}  // namespace swarmsim
