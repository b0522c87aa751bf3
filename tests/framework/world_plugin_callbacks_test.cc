// Plugin phase callbacks (framework/world_plugin_callbacks.cc): the example
// plugin's callbacks run at their points of each step.
#include <gtest/gtest.h>

#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "framework/error.h"
#include "framework/plugin_loader.h"
#include "framework/world.h"
#include "tests/framework/error_of.h"
#include "tests/framework/fakes.h"

namespace swarmsim {
namespace {

std::string PluginPath(const std::string& name) {
  return (std::filesystem::path(SWARMSIM_BINARY).parent_path() / "plugins" / name).string();
}

using testing::ErrorOf;

// A world without physics of one robot, bot#0 (a dummy), running `code` as
// robot.lua; its prints go to *log.
std::unique_ptr<World> OneBotWorld(const ModuleRegistry& registry, const char* code,
                                   std::vector<std::string>* log) {
  WorldSettings settings;
  settings.physics = "null";
  auto world = std::make_unique<World>(settings, registry);
  world->set_log_sink([log](std::string_view line) { log->emplace_back(line); });
  const ObjectId root = world->scene().AddDummy("bot", {}, {});
  world->scene().MakeModelInstance(root, "bot", "bot#0");
  world->scene().AttachScript(
      root, std::make_shared<const ScriptSource>(ScriptSource{"robot.lua", code}));
  return world;
}

TEST(PluginTest, PhaseCallbacksRunAtTheirPointsOfTheStep) {
  ModuleRegistry registry = testing::NullRegistry();
  LoadPlugin(PluginPath("example_plugin.so"), &registry);
  EXPECT_EQ(registry.phase_callbacks().size(), 7u);  // Steer + 5 counters + beacon coverage
  std::vector<std::string> log;
  const auto world = OneBotWorld(registry, R"(
function sysCall_actuation()
  print(table.concat(sim.examplePhaseCounts(), ' '))
end)",
                                 &log);
  for (int i = 0; i < 3; ++i) world->Step();
  // In step k (from 0) the script runs after sense and before-control of
  // step k, after control, physics and record of steps 0..k-1.
  const std::vector<std::string> expected = {
      "[bot#0] 1.0 1.0 0.0 0.0 0.0", "[bot#0] 2.0 2.0 1.0 1.0 1.0", "[bot#0] 3.0 3.0 2.0 2.0 2.0"};
  EXPECT_EQ(log, expected);
  // A robot without motors cannot use robotMoveAndAvoidObstacles.
  const auto other = OneBotWorld(registry, "sim.robotMoveAndAvoidObstacles(1)", &log);
  EXPECT_CONTAINS(ErrorOf([&] { other->Start(); }),
                  "sim.robotMoveAndAvoidObstacles: the robot has no :/leftMotor and :/rightMotor");
}

}  // namespace
}  // namespace swarmsim
