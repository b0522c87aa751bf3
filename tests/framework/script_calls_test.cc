// The script calls in progress (framework/script_calls.cc, read through
// ScriptCallsInProgress): what a watchdog prints for a run stuck in one
// call, "robot: file, in callback of /object", innermost script first, and
// nothing once the call has returned.
#include <gtest/gtest.h>

#include <memory>
#include <string>
#include <vector>

#include "framework/registry.h"
#include "framework/script_host.h"
#include "framework/world.h"
#include "tests/framework/fakes.h"

namespace swarmsim {
namespace {

using Lines = std::vector<std::string>;

// sim.calls(): records ScriptCallsInProgress() as seen from inside a script.
int RecordCalls(const SwarmsimCallContext*, const SwarmsimValue*, int, SwarmsimValue*, int, char*,
                size_t, void* user_data) {
  static_cast<std::vector<Lines>*>(user_data)->push_back(ScriptCallsInProgress());
  return 0;
}

std::shared_ptr<const ScriptSource> Source(std::string path, std::string code) {
  return std::make_shared<const ScriptSource>(ScriptSource{std::move(path), std::move(code)});
}

TEST(ScriptCallsTest, ACallInProgressNamesRobotFileCallbackAndObject) {
  std::vector<Lines> seen;
  ModuleRegistry registry = testing::NullRegistry();
  registry.RegisterScriptCommand({"", "test", "1", ""}, {"calls", "", RecordCalls, &seen});
  WorldSettings settings;
  settings.physics = "null";
  settings.threads = 1;
  World world(settings, registry);
  Scene& scene = world.scene();
  const ObjectId root = scene.AddDummy("bot#0", {}, {});
  const ObjectId body = scene.AddDummy("body", root, {});
  const ObjectId arm = scene.AddDummy("arm", body, {});
  scene.MakeModelInstance(root, "bot", "bot#0");
  scene.AttachScript(body, Source("scripts/robot.lua", R"(
    function sysCall_init() sim.calls() end
    function sysCall_actuation()
      sim.handleChildScript(sim.getObject('./arm'))
      sim.calls()
    end
  )"));
  scene.AttachScript(arm, Source("scripts/arm.lua", "function sysCall_actuation() sim.calls() end"),
                     /*explicit_handling=*/true);
  EXPECT_TRUE(ScriptCallsInProgress().empty());
  world.Step();
  // Outside the step, no call is in progress.
  EXPECT_TRUE(ScriptCallsInProgress().empty());
  const std::vector<Lines> expected = {
      {"bot#0: scripts/robot.lua, in sysCall_init of /bot#0/body"},
      {"bot#0: scripts/arm.lua, in sysCall_actuation of /bot#0/body/arm"},
      {"bot#0: scripts/robot.lua, in sysCall_actuation of /bot#0/body"},  // back in the caller
  };
  EXPECT_EQ(seen, expected);
}

// A scene script (outside any robot) is named by the scene.
TEST(ScriptCallsTest, SceneScriptsAreNamedAsTheScene) {
  std::vector<Lines> seen;
  ModuleRegistry registry = testing::NullRegistry();
  registry.RegisterScriptCommand({"", "test", "1", ""}, {"calls", "", RecordCalls, &seen});
  WorldSettings settings;
  settings.physics = "null";
  settings.threads = 1;
  World world(settings, registry);
  const ObjectId floor = world.scene().AddDummy("floor", {}, {});
  world.scene().AttachScript(
      floor, Source("scripts/floor.lua", "function sysCall_sensing() sim.calls() end"));
  world.Step();
  ASSERT_EQ(seen.size(), 1u);
  EXPECT_EQ(seen[0], Lines{"scene: scripts/floor.lua, in sysCall_sensing of /floor"});
}

}  // namespace
}  // namespace swarmsim
