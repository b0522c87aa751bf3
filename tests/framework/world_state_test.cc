// World::SaveState / RestoreState (framework/world_state.h) on worlds built
// in code: restore + k steps equals the uninterrupted run; bytes of another
// world, truncated or mutated bytes are errors that leave the world as it
// was; what cannot be saved is refused by name. The dynamics backends
// themselves: tests/swarm/loader/world_state_loader_test.cc.
#include "framework/world_state.h"

#include <gtest/gtest.h>

#include <memory>
#include <string>

#include "framework/error.h"
#include "framework/world.h"
#include "tests/framework/fakes.h"

namespace swarmsim {
namespace {

// Moves every dynamic shape along +x by its joint's speed; keeps nothing.
class SlideDynamics : public DynamicsBackend {
 public:
  void Build(const Scene&, const DynamicsSettings&) override {}
  void Step(Scene* scene, double dt, int substeps) override {
    const double speed = scene->joints().empty() ? 1 : scene->joints()[0].target_velocity;
    for (size_t r = 0; r < scene->shapes().size(); ++r) {
      if (!scene->shapes()[r].dynamic) continue;
      const uint32_t slot = scene->shape_owners()[r];
      Pose X = scene->world_pose_at(slot);
      X.p.x += speed * dt * substeps;
      scene->SetSimulatedState(slot, X, {speed, 0, 0}, {});
    }
  }
  int body_count() const override { return 0; }
};

// A metric keeping a running count (state outside the scene), saved or not.
class Counter : public Observer {
 public:
  explicit Counter(bool saves) : saves_(saves) {}
  void Record(const World& world, std::vector<MetricSample>* out) override {
    out->push_back({world.step_count(), world.time(), -1, "count", double(++count_)});
  }
  bool SaveState(const World&, StateWriter* out) const override {
    if (saves_) out->Put(count_);
    return saves_;
  }
  void LoadState(StateReader* in, World*) override { count_ = in->Get<int64_t>(); }

 private:
  bool saves_;
  int64_t count_ = 0;
};

ModuleRegistry Registry() {
  ModuleRegistry r = testing::NullRegistry();
  r.RegisterDynamics({"", "slide", "1", ""}, {}, [] { return std::make_unique<SlideDynamics>(); });
  return r;
}

const ModuleRegistry& TheRegistry() {
  static const ModuleRegistry registry = Registry();
  return registry;
}

// `robots` robots (a dynamic body and a joint each); the metric saves its
// state unless told not to.
std::unique_ptr<World> MakeWorld(int robots, bool metric_saves = true) {
  WorldSettings settings;
  settings.physics = "slide";
  settings.file = "";
  auto world = std::make_unique<World>(settings, TheRegistry());
  for (int i = 0; i < robots; ++i) {
    ShapeData body;
    body.dynamic = true;
    Scene& scene = world->scene();
    const ObjectId root = scene.AddShape("body", {}, {{0, double(i), 0}, {}}, body);
    JointData joint;
    scene.AddJoint("wheel", root, {}, joint);
    scene.MakeModelInstance(root, "bot", "bot#" + std::to_string(i));
  }
  world->AddObserver(std::make_unique<Counter>(metric_saves));
  world->Start();
  return world;
}

// Changes a joint's target (what a Python controller does between steps).
void Drive(World* world) {
  world->scene().joints()[0].target_velocity = 0.5 + 0.1 * double(world->step_count() % 3);
}

void StepDriven(World* world, int steps) {
  for (int i = 0; i < steps; ++i) {
    Drive(world);
    world->Step();
  }
}

TEST(WorldStateTest, RestorePlusStepsEqualsTheUninterruptedRun) {
  auto original = MakeWorld(2);
  StepDriven(original.get(), 3);
  const std::string bytes = original->SaveState();
  StepDriven(original.get(), 4);
  const uint64_t expected = original->StateHash();
  const auto metrics = original->TakeMetrics();

  auto restored = MakeWorld(2);
  restored->RestoreState(bytes);
  EXPECT_EQ(restored->step_count(), 3);
  StepDriven(restored.get(), 4);
  EXPECT_EQ(restored->StateHash(), expected);
  // The metric's running count came back too (7 at step 7, not 4).
  const auto again = restored->TakeMetrics();
  ASSERT_FALSE(again.empty());
  EXPECT_EQ(again.back().value, 7);
  EXPECT_EQ(again.back().value, metrics.back().value);
  // Restoring into the original takes it back as well.
  original->RestoreState(bytes);
  StepDriven(original.get(), 4);
  EXPECT_EQ(original->StateHash(), expected);
}

TEST(WorldStateTest, TruncatedOrMutatedBytesAreErrorsThatChangeNothing) {
  auto source = MakeWorld(2);
  StepDriven(source.get(), 2);
  const std::string bytes = source->SaveState();
  auto world = MakeWorld(2);
  StepDriven(world.get(), 5);
  const uint64_t before = world->StateHash();
  int errors = 0, tries = 0;
  for (size_t size = 0; size < bytes.size(); size += 1 + size / 7) {
    ++tries;
    try {
      world->RestoreState(std::string_view(bytes).substr(0, size));
    } catch (const Error& e) {
      ++errors;
      EXPECT_NE(std::string(e.what()).find("snapshot"), std::string::npos) << e.what();
    }
  }
  for (size_t at = 0; at < bytes.size(); at += 1 + at / 5) {
    std::string mutated = bytes;
    mutated[at] = static_cast<char>(mutated[at] ^ (1 << (at % 8)));
    ++tries;
    try {
      world->RestoreState(mutated);
    } catch (const Error&) {
      ++errors;
    }
  }
  EXPECT_EQ(errors, tries);
  EXPECT_EQ(world->StateHash(), before);
  StepDriven(world.get(), 1);  // still steps
  EXPECT_EQ(world->step_count(), 6);
}

TEST(WorldStateTest, AnotherWorldIsAnErrorNamingTheDifference) {
  auto two = MakeWorld(2);
  const std::string bytes = two->SaveState();
  auto three = MakeWorld(3);
  try {
    three->RestoreState(bytes);
    FAIL() << "restored 2 robots into 3";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("2 robots"), std::string::npos) << e.what();
  }
  EXPECT_THROW(three->RestoreState("not a snapshot at all"), Error);
}

TEST(WorldStateTest, RefusesScriptsAndModulesWithoutSaveHooks) {
  auto scripted = MakeWorld(2);
  scripted->scene().AttachScript(
      scripted->scene().instance(1).root,
      std::make_shared<const ScriptSource>(ScriptSource{"scripts/bot.lua", "x = 1"}));
  try {
    scripted->SaveState();
    FAIL() << "saved a world with a Lua script";
  } catch (const Error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("robot 'bot#1'"), std::string::npos) << what;
    EXPECT_NE(what.find("scripts/bot.lua"), std::string::npos) << what;
  }
  auto unsaved = MakeWorld(1, /*metric_saves=*/false);
  try {
    unsaved->SaveState();
    FAIL() << "saved a module that cannot save its state";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("cannot save its state"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace swarmsim
