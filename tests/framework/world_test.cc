#include "framework/world.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <new>
#include <string>
#include <vector>

#include "framework/error.h"
#include "tests/framework/fakes.h"

namespace swarmsim {
namespace {

// Moves every dynamic shape along +x at 1 m/s; can be told to explode.
class ConveyorDynamics : public DynamicsBackend {
 public:
  // explode_some: at step 2 only every 1,000th body from the 778th gets a
  // NaN velocity, and every body from the 5,000th a NaN pose.
  explicit ConveyorDynamics(bool explode_at_step2, bool explode_some = false)
      : explode_(explode_at_step2), some_(explode_some) {}
  void Build(const Scene&, const DynamicsSettings&) override {}
  void Step(Scene* scene, double dt, int substeps) override {
    ++steps_;
    for (size_t r = 0; r < scene->shapes().size(); ++r) {
      if (!scene->shapes()[r].dynamic) continue;
      const uint32_t slot = scene->shape_owners()[r];
      Pose X = scene->world_pose_at(slot);
      X.p.x += dt * substeps;
      if (explode_ && steps_ == 2) X.p.y = std::numeric_limits<double>::quiet_NaN();
      Vec3 v{1, 0, 0};
      if (some_ && steps_ == 2) {
        if (r % 1000 == 777) v.z = std::numeric_limits<double>::infinity();
        if (r >= 5000) X.q.w = std::numeric_limits<double>::quiet_NaN();
      }
      scene->SetSimulatedState(slot, X, v, {});
    }
  }
  int body_count() const override { return 0; }

 private:
  bool explode_, some_;
  int steps_ = 0;
};

ModuleRegistry MakeRegistry() {
  ModuleRegistry r = testing::NullRegistry();
  r.RegisterDynamics({"", "conveyor", "1", ""}, {},
                     [] { return std::make_unique<ConveyorDynamics>(false); });
  r.RegisterDynamics({"", "explode", "1", ""}, {},
                     [] { return std::make_unique<ConveyorDynamics>(true); });
  r.RegisterDynamics({"", "explode_some", "1", ""}, {},
                     [] { return std::make_unique<ConveyorDynamics>(false, true); });
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

// A physics engine that runs out of memory part-way through its build
// (Box2D's partitions under `ulimit -v`): what it holds is half built.
class HalfBuiltDynamics : public DynamicsBackend {
 public:
  HalfBuiltDynamics(bool fail, int* hashed) : fail_(fail), hashed_(hashed) {}
  void Build(const Scene&, const DynamicsSettings&) override {
    if (fail_) throw std::bad_alloc();
  }
  void Step(Scene*, double, int) override {}
  int body_count() const override { return 0; }
  void HashState(StateHasher*) const override { ++*hashed_; }

 private:
  bool fail_;
  int* hashed_;
};

// The run that failed to start still prints a state hash and ends cleanly:
// the hash leaves the half-built physics alone (reading it crashed), and
// the world cannot be started or stepped again.
TEST(WorldTest, AWorldWhoseStartFailedLeavesItsHalfBuiltPartsAlone) {
  int hashed = 0;
  ModuleRegistry registry = MakeRegistry();
  for (const bool fail : {false, true})
    registry.RegisterDynamics({"", fail ? "half" : "whole", "1", ""}, {}, [fail, &hashed] {
      return std::make_unique<HalfBuiltDynamics>(fail, &hashed);
    });
  WorldSettings settings;
  // Built whole, the engine is hashed.
  settings.physics = "whole";
  World whole(settings, registry);
  whole.Start();
  whole.StateHash();
  EXPECT_EQ(hashed, 1);
  hashed = 0;
  settings.physics = "half";
  World world(settings, registry);
  const ObjectId root = world.scene().AddDummy("bot", {}, {});
  world.scene().MakeModelInstance(root, "bot", "bot#0");
  EXPECT_THROW(world.Start(), std::bad_alloc);
  const uint64_t hash = world.StateHash();
  EXPECT_EQ(hashed, 0);
  EXPECT_EQ(world.StateHash(), hash);
  EXPECT_THROW(world.Start(), Error);
  try {
    world.Step();
    ADD_FAILURE() << "a world that failed to start stepped";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("the world failed to start"), std::string::npos)
        << e.what();
  }
}

// The start names its stages for the progress line: the scripts' stage
// speaks of Lua states only in a world that has scripts.
TEST(WorldTest, TheStartNamesTheScriptsStageByWhatTheWorldHas) {
  for (const bool scripted : {false, true}) {
    const ModuleRegistry registry = MakeRegistry();
    WorldSettings settings;
    settings.physics = "null";
    World world(settings, registry);
    const ObjectId root = world.scene().AddDummy("bot", {}, {});
    world.scene().MakeModelInstance(root, "bot", "bot#0");
    if (scripted)
      world.scene().AttachScript(root, std::make_shared<const ScriptSource>(
                                           ScriptSource{"bot.lua", "function sysCall_init() end"}));
    std::vector<std::string> stages;
    world.set_start_progress([&](const std::string& stage) { stages.push_back(stage); });
    world.Start();
    const std::string expected = scripted ? "scripts (Lua states, sysCall_init)" : "scripts (none)";
    EXPECT_NE(std::find(stages.begin(), stages.end(), expected), stages.end()) << scripted;
  }
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

// A body that physics moves past the 1e6 m a world may use has blown up:
// an error naming it, not a run that ends "ok" with bodies at 1e96 m.
TEST(WorldTest, ABodyPhysicsMovesOutOfTheWorldIsAnError) {
  const ModuleRegistry registry = MakeRegistry();
  WorldSettings settings;
  settings.physics = "conveyor";  // +x at 1 m/s
  settings.time_step = 0.1;
  World world(settings, registry);
  ShapeData body;
  body.dynamic = true;
  world.scene().AddShape("near", {}, {{999'999.85, 0, 0}, {}}, body);
  world.Start();
  world.Step();  // 999,999.95: still in
  try {
    world.Step();
    FAIL() << "a body at 1,000,000.05 m accepted";
  } catch (const Error& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("physics moved '/near' to (1000000.05, 0, 0) m at step 2, beyond the 1e6 m"),
              std::string::npos)
        << msg;
    EXPECT_NE(msg.find("smaller time_step"), std::string::npos) << msg;
  }
}

// Many bodies checked on every thread: the error names the first bad one
// (by row) and what is wrong with it, the same for any thread count.
TEST(WorldTest, NonFinitePhysicsNamesTheFirstBadBodyForAnyThreadCount) {
  const ModuleRegistry registry = MakeRegistry();
  for (const int threads : {1, 2}) {
    WorldSettings settings;
    settings.physics = "explode_some";
    settings.threads = threads;
    World world(settings, registry);
    ShapeData body;
    body.dynamic = true;
    for (int i = 0; i < 20000; ++i)
      world.scene().AddShape("body" + std::to_string(i), {}, {{double(i), 0, 0}, {}}, body);
    world.Start();
    world.Step();
    try {
      world.Step();
      FAIL() << "NaN accepted, threads " << threads;
    } catch (const Error& e) {
      const std::string msg = e.what();
      EXPECT_NE(msg.find("non-finite velocity for '/body777' at step 2"), std::string::npos)
          << threads << ": " << msg;
    }
  }
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
