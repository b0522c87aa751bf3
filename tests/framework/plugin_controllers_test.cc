// Native controllers (framework/plugin_controllers.cc): a plugin's C
// controller runs init, one step per robot per step with that robot's
// context, and cleanup; a failure names the robot, the controller and its
// plugin, and stops the run or (disable_script) that robot's controller.
#include "framework/plugin_controllers.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <memory>
#include <mutex>
#include <stdexcept>
#include <string>
#include <vector>

#include "framework/error.h"
#include "framework/registry.h"
#include "framework/world.h"
#include "tests/framework/error_of.h"
#include "tests/framework/fakes.h"

namespace swarmsim {
namespace {

using testing::ErrorOf;

// What the test controller does: it logs every call as "<what> <robot>" and
// fails its step at `fail_step` for robot `fail_robot` (-1: never) in the
// way `failure` says.
struct Script {
  std::mutex mutex;
  std::vector<std::string> calls;
  int fail_robot = -1;
  int64_t fail_step = 0;
  enum { kMessage, kSilent, kThrow } failure = kMessage;
  void Log(const std::string& what, int robot) {
    std::lock_guard<std::mutex> lock(mutex);
    calls.push_back(what + " " + std::to_string(robot));
  }
};

int Init(const SwarmsimCallContext* c, void** state, char*, size_t, void* user_data) {
  static_cast<Script*>(user_data)->Log("init", c->robot);
  *state = new int(c->robot);
  return 0;
}

int Step(const SwarmsimCallContext* c, void* state, char* error, size_t error_size,
         void* user_data) {
  auto& script = *static_cast<Script*>(user_data);
  const int64_t step = c->api->step_count(c->world);
  script.Log("step" + std::to_string(step) + " state", *static_cast<int*>(state));
  if (c->robot != script.fail_robot || step != script.fail_step) return 0;
  switch (script.failure) {
    case Script::kMessage:
      std::snprintf(error, error_size, "lost at step %lld", static_cast<long long>(step));
      return -1;
    case Script::kSilent: return -1;
    case Script::kThrow: throw std::runtime_error("vector::at");
  }
  return 0;
}

void Cleanup(const SwarmsimCallContext* c, void* state, void* user_data) {
  static_cast<Script*>(user_data)->Log("cleanup", c->robot);
  delete static_cast<int*>(state);
}

class ControllerWorld {
 public:
  explicit ControllerWorld(Script* script, int robots, WorldSettings settings = {})
      : registry_(testing::NullRegistry()),
        type_{"counter", "logs its calls", "plugins/test.so", Init, Step, Cleanup, script} {
    settings.physics = "null";
    settings.threads = 1;  // calls in robot order
    world_ = std::make_unique<World>(settings, registry_);
    world_->set_log_sink([this](std::string_view line) { log.emplace_back(line); });
    for (int r = 0; r < robots; ++r) {
      const std::string name = "bot#" + std::to_string(r);
      world_->scene().MakeModelInstance(world_->scene().AddDummy(name, {}, {}), "bot", name);
      world_->SetNativeController(r, &type_, /*in_place_of_scripts=*/false);
    }
  }
  World& world() { return *world_; }
  std::vector<std::string> log;

 private:
  ModuleRegistry registry_;
  PluginControllerType type_;
  std::unique_ptr<World> world_;
};

TEST(PluginControllersTest, InitStepsAndCleanupRunPerRobotInOrder) {
  Script script;
  ControllerWorld w(&script, 2);
  w.world().Start();
  w.world().Step();
  w.world().Step();
  w.world().Stop();
  const std::vector<std::string> expected = {"init 0",        "init 1",        "step0 state 0",
                                             "step0 state 1", "step1 state 0", "step1 state 1",
                                             "cleanup 0",     "cleanup 1"};
  EXPECT_EQ(script.calls, expected);
  ASSERT_NE(w.world().plugin_controllers(), nullptr);
  EXPECT_EQ(w.world().plugin_controllers()->type_of(1)->name, "counter");
  EXPECT_EQ(w.world().plugin_controllers()->type_of(2), nullptr);
}

TEST(PluginControllersTest, AFailingStepStopsTheRunNamingRobotControllerAndPlugin) {
  Script script;
  script.fail_robot = 1;
  script.fail_step = 1;
  ControllerWorld w(&script, 3);
  w.world().Step();
  EXPECT_EQ(ErrorOf([&] { w.world().Step(); }),
            "bot#1: native controller 'counter' (plugins/test.so), in step: lost at step 1");
}

TEST(PluginControllersTest, SilentAndThrowingFailuresStillSayWhatHappened) {
  Script silent;
  silent.fail_robot = 0;
  silent.failure = Script::kSilent;
  ControllerWorld a(&silent, 1);
  EXPECT_EQ(ErrorOf([&] { a.world().Step(); }),
            "bot#0: native controller 'counter' (plugins/test.so), in step: failed without a "
            "message");
  Script thrower;
  thrower.fail_robot = 0;
  thrower.failure = Script::kThrow;
  ControllerWorld b(&thrower, 1);
  EXPECT_EQ(ErrorOf([&] { b.world().Step(); }),
            "bot#0: native controller 'counter' (plugins/test.so), in step: a C++ exception "
            "left the plugin: vector::at");
}

// Under disable_script the failing robot's controller is cleaned up at once
// and stops; the others go on.
TEST(PluginControllersTest, DisableScriptStopsOnlyTheFailingController) {
  Script script;
  script.fail_robot = 0;
  script.fail_step = 0;
  WorldSettings settings;
  settings.on_script_error = ScriptErrorPolicy::kDisableScript;
  ControllerWorld w(&script, 2, settings);
  w.world().Step();
  w.world().Step();
  w.world().Stop();
  const std::vector<std::string> expected = {"init 0",    "init 1",        "step0 state 0",
                                             "cleanup 0", "step0 state 1", "step1 state 1",
                                             "cleanup 1"};
  EXPECT_EQ(script.calls, expected);
  ASSERT_EQ(w.log.size(), 1u);
  EXPECT_EQ(w.log[0],
            "error, native controller disabled: bot#0: native controller 'counter' "
            "(plugins/test.so), in step: lost at step 0");
}

TEST(PluginControllersTest, AControllerNameIsRegisteredOnce) {
  ModuleRegistry registry;
  registry.RegisterController({"", "p", "1", "relays"}, {"relay", "", "p.so", nullptr, Step});
  EXPECT_EQ(ErrorOf([&] {
              registry.RegisterController({"", "q", "1", ""}, {"relay", "", "q.so", nullptr, Step});
            }),
            "native controller 'relay' is registered twice");
  EXPECT_EQ(registry.ControllerNames(), std::vector<std::string>{"relay"});
  EXPECT_EQ(registry.FindController("relay")->plugin, "p.so");
  EXPECT_EQ(registry.modules().at(0).kind, "controller");
}

}  // namespace
}  // namespace swarmsim
