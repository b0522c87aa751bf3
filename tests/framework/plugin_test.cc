// Plugins: the example plugin's commands called from Lua through the
// registry; clear errors for a missing file, a library that is not a
// plugin, and an ABI mismatch.
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

TEST(PluginTest, CommandsAreCalledFromLuaWithNumbersArraysAndContext) {
  ModuleRegistry registry = testing::NullRegistry();
  LoadPlugin(PluginPath("example_plugin.so"), &registry);
  ASSERT_NE(registry.FindScriptCommand("exampleSum"), nullptr);
  WorldSettings settings;
  settings.physics = "null";
  World world(settings, registry);
  std::vector<std::string> log;
  world.set_log_sink([&](std::string_view line) { log.emplace_back(line); });
  for (int r = 0; r < 2; ++r) {
    const ObjectId root = world.scene().AddDummy("bot", {}, {{1.0 + r, 2, 0}, {}});
    world.scene().MakeModelInstance(root, "bot", "bot#" + std::to_string(r));
    world.scene().AttachScript(root,
                               std::make_shared<const ScriptSource>(ScriptSource{"robot.lua", R"(
function sysCall_actuation()
  local p, robot = sim.exampleWhereAmI()
  print(sim.exampleSum(1, 2, {3, 4}), p[1], p[2], robot)
  sim.exampleSum('x')
end)"}));
  }
  world.Start();
  const std::string error = ErrorOf([&] { world.Step(); });
  EXPECT_CONTAINS(error, "bot#0: robot.lua:5: sim.exampleSum: argument 1 must be a number");
  const std::vector<std::string> expected = {"[bot#0] 10\t1.0\t2.0\t0", "[bot#1] 10\t2.0\t2.0\t1"};
  EXPECT_EQ(log, expected);
}

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

TEST(PluginTest, WholeNumberResultsArriveAsLuaIntegers) {
  ModuleRegistry registry = testing::NullRegistry();
  LoadPlugin(PluginPath("example_plugin.so"), &registry);
  std::vector<std::string> log;
  const auto world = OneBotWorld(registry, R"(
function sysCall_init()
  print(sim.exampleSum(1, 2), math.type(sim.exampleSum(1, 2)), sim.exampleSum(0.5, 1),
        sim.exampleSum(-4), 'robot' .. sim.exampleSum(3.0))
end)",
                                 &log);
  world->Start();
  EXPECT_EQ(log, std::vector<std::string>{"[bot#0] 3\tinteger\t1.5\t-4\trobot3"});
}

TEST(PluginTest, LoadErrorsNameThePathAndTheProblem) {
  ModuleRegistry registry;
  EXPECT_CONTAINS(ErrorOf([&] { LoadPlugin("/nonexistent/p.so", &registry); }),
                  "cannot load plugin '/nonexistent/p.so': ");
  EXPECT_CONTAINS(ErrorOf([&] { LoadPlugin(PluginPath("wrong_abi_plugin.so"), &registry); }),
                  "was built for plugin ABI version 7, this swarmsim has version 6");
  EXPECT_CONTAINS(ErrorOf([&] { LoadPlugin(PluginPath("old_abi_plugin.so"), &registry); }),
                  "was built for plugin ABI version 3, this swarmsim has version 6; rebuild it");
  EXPECT_CONTAINS(ErrorOf([&] { LoadPlugin("libm.so.6", &registry); }), "cannot load plugin");
  LoadPlugin(PluginPath("example_plugin.so"), &registry);
  EXPECT_CONTAINS(ErrorOf([&] { LoadPlugin(PluginPath("example_plugin.so"), &registry); }),
                  "script command 'exampleSum' is registered twice");
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
