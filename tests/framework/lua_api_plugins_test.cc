// Plugin script commands as sim.* functions (framework/lua_api_plugins.cc):
// the example plugin's commands called from Lua with numbers, arrays and
// the calling robot's context; whole numbers come back as Lua integers.
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

}  // namespace
}  // namespace swarmsim
