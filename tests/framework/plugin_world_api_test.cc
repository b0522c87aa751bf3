// The world interface plugins see (framework/plugin_world_api.cc): what a
// plugin's commands, callbacks and controllers can ask and change, with the
// refusals that keep them to their own robot and never throw into C.
#include "framework/plugin_world_api.h"

#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "framework/world.h"
#include "tests/framework/fakes.h"

namespace swarmsim {
namespace {

// Two robots (bot#0 at x = 1, bot#1 at x = 2), each a root dummy with a
// `motor` joint, and a scene dummy `post` at (0, 3, 0).
class ApiWorld {
 public:
  ApiWorld() : registry_(testing::NullRegistry()), api(*PluginWorldApi()) {
    WorldSettings settings;
    settings.physics = "null";
    settings.time_step = 0.25;
    world_ = std::make_unique<World>(settings, registry_);
    for (int r = 0; r < 2; ++r) {
      const std::string name = "bot#" + std::to_string(r);
      roots.push_back(scene().AddDummy(name, {}, {{1.0 + r, 0, 0}, {}}));
      motors.push_back(scene().AddJoint("motor", roots.back(), {}, {}));
      scene().MakeModelInstance(roots.back(), "bot", name);
    }
    post = scene().AddDummy("post", {}, {{0, 3, 0}, {}});
  }
  Scene& scene() { return world_->scene(); }
  World& world() { return *world_; }
  void* handle() { return world_.get(); }

 private:
  ModuleRegistry registry_;
  std::unique_ptr<World> world_;

 public:
  const SwarmsimWorldApi& api;
  std::vector<ObjectId> roots, motors;
  ObjectId post;
};

TEST(PluginWorldApiTest, TimeStepsRobotsAndPositions) {
  ApiWorld w;
  EXPECT_EQ(w.api.time(w.handle()), 0);
  EXPECT_EQ(w.api.robot_count(w.handle()), 2);
  w.world().Step();
  w.world().Step();
  EXPECT_EQ(w.api.step_count(w.handle()), 2);
  EXPECT_DOUBLE_EQ(w.api.time(w.handle()), 0.5);
  double p[3] = {};
  ASSERT_EQ(w.api.object_position(w.handle(), w.roots[1].ToInteger(), p), 1);
  EXPECT_EQ(p[0], 2);
  ASSERT_EQ(w.api.object_position(w.handle(), w.post.ToInteger(), p), 1);
  EXPECT_EQ(p[1], 3);
  EXPECT_EQ(w.api.robot_root(w.handle(), 1), w.roots[1].ToInteger());
  EXPECT_EQ(w.api.robot_root(w.handle(), 2), 0);
  EXPECT_EQ(w.api.robot_root(w.handle(), -1), 0);
  EXPECT_EQ(w.api.robot_of(w.handle(), w.motors[1].ToInteger()), 1);
  EXPECT_EQ(w.api.robot_of(w.handle(), w.post.ToInteger()), -1);
  // A stale handle answers "none", never a crash.
  const int64_t stale = w.post.ToInteger();
  w.scene().RemoveSubtree(w.post);
  EXPECT_EQ(w.api.object_position(w.handle(), stale, p), 0);
  EXPECT_EQ(w.api.robot_of(w.handle(), stale), -1);
}

TEST(PluginWorldApiTest, FindObjectUsesTheScriptsPathSyntax) {
  ApiWorld w;
  int64_t found = 0;
  ASSERT_EQ(w.api.find_object(w.handle(), 0, "/bot#1/motor", &found), 1);
  EXPECT_EQ(found, w.motors[1].ToInteger());
  ASSERT_EQ(w.api.find_object(w.handle(), w.roots[0].ToInteger(), "./motor", &found), 1);
  EXPECT_EQ(found, w.motors[0].ToInteger());
  ASSERT_EQ(w.api.find_object(w.handle(), w.motors[1].ToInteger(), ":", &found), 1);
  EXPECT_EQ(found, w.roots[1].ToInteger());
  found = 7;
  EXPECT_EQ(w.api.find_object(w.handle(), 0, "/bot#1/wheel", &found), 0);
  EXPECT_EQ(w.api.find_object(w.handle(), 0, "motor", &found), 0);    // malformed: no throw
  EXPECT_EQ(w.api.find_object(w.handle(), 0, "./motor", &found), 0);  // relative to nothing
  EXPECT_EQ(w.api.find_object(w.handle(), 0, nullptr, &found), 0);
  EXPECT_EQ(found, 7);
}

TEST(PluginWorldApiTest, ARobotDrivesOnlyItsOwnJoints) {
  ApiWorld w;
  const int64_t motor0 = w.motors[0].ToInteger();
  EXPECT_EQ(w.api.set_joint_target_velocity(w.handle(), 0, motor0, 1.5), 1);
  EXPECT_EQ(w.scene().joint(w.motors[0]).target_velocity, 1.5);
  EXPECT_EQ(w.api.set_joint_target_velocity(w.handle(), 1, motor0, 9), 0);
  EXPECT_EQ(w.api.set_joint_target_velocity(w.handle(), 0, w.roots[0].ToInteger(), 9), 0);
  EXPECT_EQ(w.scene().joint(w.motors[0]).target_velocity, 1.5);
  EXPECT_EQ(w.api.set_joint_target_position(w.handle(), 0, motor0, 0.25), 1);
  EXPECT_EQ(w.scene().joint(w.motors[0]).target_position, 0.25);
  EXPECT_EQ(w.api.set_joint_target_position(w.handle(), 0, motor0, NAN), 0);
  EXPECT_EQ(w.api.set_joint_target_position(w.handle(), 1, motor0, 1), 0);
  EXPECT_EQ(w.scene().joint(w.motors[0]).target_position, 0.25);
  w.scene().mutable_joint(w.motors[1]).position = 0.75;
  w.scene().mutable_joint(w.motors[1]).velocity = -2;
  double q = 0, v = 0;
  ASSERT_EQ(w.api.joint_state(w.handle(), w.motors[1].ToInteger(), &q, &v), 1);
  EXPECT_EQ(q, 0.75);
  EXPECT_EQ(v, -2);
  EXPECT_EQ(w.api.joint_state(w.handle(), w.roots[1].ToInteger(), &q, &v), 0);
}

TEST(PluginWorldApiTest, ObjectsOfATypeInHandleOrder) {
  ApiWorld w;
  int64_t out[8] = {};
  ASSERT_EQ(w.api.objects_of_type(w.handle(), "joint", out, 8), 2);
  EXPECT_EQ(out[0], w.motors[0].ToInteger());
  EXPECT_EQ(out[1], w.motors[1].ToInteger());
  EXPECT_EQ(w.api.objects_of_type(w.handle(), "dummy", out, 1), 3);  // more than fit
  EXPECT_EQ(out[0], w.roots[0].ToInteger());
  EXPECT_EQ(w.api.objects_of_type(w.handle(), "beacon", out, 8), -1);
  EXPECT_EQ(w.api.objects_of_type(w.handle(), nullptr, out, 8), -1);
  // Not a plugin type's object: no values.
  double values[4];
  EXPECT_EQ(w.api.object_values(w.handle(), w.roots[0].ToInteger(), values, 4), -1);
}

TEST(PluginWorldApiTest, ParametersAsScriptsSeeThem) {
  ApiWorld w;
  w.world().parameters()["speed"] = 0.5;
  w.world().parameters()["enabled"] = true;
  w.world().parameters()["mode"] = std::string("wander");
  SwarmsimValue value{};
  ASSERT_EQ(w.api.parameter(w.handle(), 0, "speed", &value), 1);
  EXPECT_EQ(value.type, kSwarmsimNumber);
  EXPECT_EQ(value.number, 0.5);
  ASSERT_EQ(w.api.parameter(w.handle(), 1, "enabled", &value), 1);
  EXPECT_EQ(value.number, 1);
  ASSERT_EQ(w.api.parameter(w.handle(), -1, "mode", &value), 1);
  EXPECT_EQ(value.type, kSwarmsimString);
  EXPECT_EQ(std::string(value.text, value.size), "wander");
  EXPECT_EQ(w.api.parameter(w.handle(), 0, "gain", &value), 0);
  double number = 0;
  ASSERT_EQ(w.api.number_parameter(w.handle(), 0, "speed", &number), 1);
  EXPECT_EQ(number, 0.5);
  EXPECT_EQ(w.api.number_parameter(w.handle(), 0, "mode", &number), 0);
}

// Metrics come only from the record phase; elsewhere the call is refused.
TEST(PluginWorldApiTest, MetricsOnlyFromTheRecordPhase) {
  ApiWorld w;
  EXPECT_EQ(w.api.record_metric(w.handle(), -1, "coverage", 1), -1);
  EXPECT_TRUE(w.world().TakeMetrics().empty());
}

}  // namespace
}  // namespace swarmsim
