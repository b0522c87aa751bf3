#include "framework/world.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "framework/error.h"
#include "tests/framework/fakes.h"

namespace swarmsim {
namespace {

// Moves every dynamic shape along +x at 1 m/s; can be told to explode.
class ConveyorDynamics : public DynamicsBackend {
 public:
  explicit ConveyorDynamics(bool explode_at_step2) : explode_(explode_at_step2) {}
  void Build(const Scene&, const DynamicsSettings&) override {}
  void Step(Scene* scene, double dt, int substeps) override {
    ++steps_;
    for (size_t r = 0; r < scene->shapes().size(); ++r) {
      if (!scene->shapes()[r].dynamic) continue;
      const uint32_t slot = scene->shape_owners()[r];
      Pose X = scene->world_pose_at(slot);
      X.p.x += dt * substeps;
      if (explode_ && steps_ == 2) X.p.y = std::numeric_limits<double>::quiet_NaN();
      scene->SetSimulatedState(slot, X, {1, 0, 0}, {});
    }
  }
  int body_count() const override { return 0; }

 private:
  bool explode_;
  int steps_ = 0;
};

ModuleRegistry MakeRegistry() {
  ModuleRegistry r = testing::NullRegistry();
  r.RegisterDynamics({"", "conveyor", "1", ""}, {},
                     [] { return std::make_unique<ConveyorDynamics>(false); });
  r.RegisterDynamics({"", "explode", "1", ""}, {},
                     [] { return std::make_unique<ConveyorDynamics>(true); });
  return r;
}

class CountRobots : public Observer {
 public:
  void Record(const World& world, std::vector<MetricSample>* out) override {
    out->push_back({world.step_count(), world.time(), -1, "robots", double(world.robot_count())});
  }
};

TEST(WorldTest, StepsPhysicsAndChildrenFollow) {
  const ModuleRegistry registry = MakeRegistry();
  WorldSettings settings;
  settings.physics = "conveyor";
  settings.time_step = 0.1;
  settings.physics_substeps = 4;
  World world(settings, registry);
  ShapeData body;
  body.dynamic = true;
  const ObjectId root = world.scene().AddShape("body", {}, {}, body);
  const ObjectId sensor = world.scene().AddDummy("eye", root, {{0.1, 0, 0}, {}});
  world.scene().MakeModelInstance(root, "bot", "bot#0");
  world.AddObserver(std::make_unique<CountRobots>());
  world.Start();
  for (int i = 0; i < 10; ++i) world.Step();
  EXPECT_EQ(world.step_count(), 10);
  EXPECT_NEAR(world.time(), 1.0, 1e-12);
  EXPECT_NEAR(world.scene().world_pose(root).p.x, 1.0, 1e-12);
  EXPECT_NEAR(world.scene().world_pose(sensor).p.x, 1.1, 1e-12);
  const auto metrics = world.TakeMetrics();
  ASSERT_EQ(metrics.size(), 10u);
  EXPECT_EQ(metrics.back().step, 10);
  EXPECT_EQ(metrics.back().value, 1.0);
  EXPECT_TRUE(world.TakeMetrics().empty());
}

TEST(WorldTest, JointsMoveTowardTheirTargets) {
  const ModuleRegistry registry = MakeRegistry();
  WorldSettings settings;
  settings.physics = "null";
  settings.time_step = 0.1;
  World world(settings, registry);
  JointData v;
  v.settings.Edit().mode = JointMode::kVelocity;
  v.target_velocity = 2.0;
  JointData p;
  p.settings.Edit().mode = JointMode::kPosition;
  p.target_position = 1.0;
  p.settings.Edit().max_velocity = 1.0;
  const ObjectId jv = world.scene().AddJoint("v", {}, {}, v);
  const ObjectId jp = world.scene().AddJoint("p", {}, {}, p);
  world.Start();
  for (int i = 0; i < 5; ++i) world.Step();
  EXPECT_NEAR(world.scene().joint(jv).position, 1.0, 1e-12);
  EXPECT_NEAR(world.scene().joint(jp).position, 0.5, 1e-12);  // rate-limited
  for (int i = 0; i < 10; ++i) world.Step();
  EXPECT_NEAR(world.scene().joint(jp).position, 1.0, 1e-12);  // and stops at the target
}

TEST(WorldTest, NonFinitePhysicsIsAnErrorNamingTheObject) {
  const ModuleRegistry registry = MakeRegistry();
  WorldSettings settings;
  settings.physics = "explode";
  World world(settings, registry);
  ShapeData body;
  body.dynamic = true;
  const ObjectId root = world.scene().AddShape("body", {}, {}, body);
  world.scene().MakeModelInstance(root, "bot", "bot#0");
  world.Start();
  world.Step();
  try {
    world.Step();
    FAIL() << "NaN accepted";
  } catch (const Error& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("non-finite"), std::string::npos) << msg;
    EXPECT_NE(msg.find("/body"), std::string::npos) << msg;
    EXPECT_NE(msg.find("step 2"), std::string::npos) << msg;
  }
  EXPECT_THROW(world.Step(), Error);  // no stepping on after a failure
}

TEST(WorldTest, JointRunningToInfinityIsAnErrorNamingTheJoint) {
  const ModuleRegistry registry = MakeRegistry();
  WorldSettings settings;
  settings.physics = "null";
  settings.time_step = 0.1;
  World world(settings, registry);
  JointData v;
  v.settings.Edit().mode = JointMode::kVelocity;
  v.target_velocity = 1e308;  // finite, but its position overflows after ~18 steps
  world.scene().AddJoint("wheel", {}, {}, v);
  world.Start();
  int steps = 0;
  try {
    for (; steps < 100; ++steps) world.Step();
    FAIL() << "an infinite joint position was accepted";
  } catch (const Error& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("non-finite joint position"), std::string::npos) << msg;
    EXPECT_NE(msg.find("'/wheel'"), std::string::npos) << msg;
  }
  EXPECT_GT(steps, 10);
}

TEST(WorldTest, UnknownBackendAndBadSettingsAreErrors) {
  const ModuleRegistry registry = MakeRegistry();
  WorldSettings settings;
  settings.physics = "bullet";
  try {
    World world(settings, registry);
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("available: null, conveyor, explode"), std::string::npos)
        << e.what();
  }
  settings.physics = "null";
  settings.time_step = 0;
  EXPECT_THROW(World(settings, registry), Error);
}

}  // namespace
}  // namespace swarmsim
