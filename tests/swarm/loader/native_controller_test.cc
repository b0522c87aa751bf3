// Native controllers (plugin ABI 6) as a user attaches them: a models
// entry's `native_controller:` naming a controller of a plugin the world
// loads (the example plugin's `relay` and `faulty`, the diffusion plugin's
// `diffusion`). Messages between native and Lua robots, parameters, random
// draws, copies and removals at run time, failures named by robot and
// plugin, mistakes at file:line:column, and the diffusion controller moving
// the robots exactly as scripts/diffusion.lua does.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>
#include <vector>

#include "framework/error.h"
#include "framework/registry.h"
#include "framework/world.h"
#include "swarm/loader/world_loader.h"
#include "tests/framework/error_of.h"
#include "tests/swarm/loader/world_dir_test.h"

namespace swarmsim {
namespace {

// A robot with a velocity joint ./wheel; its Lua script (kept only with
// keep_scripts) drives the wheel backwards.
constexpr char kBot[] = R"(model: bot
parameters:
  greeting: {default: hi}
  noise: {default: 0}
  fail_step: {default: 2}
  fail_robot: {default: 0}
  fail_init: {default: 0}
objects:
  name: body
  type: shape
  shape: cylinder
  radius: 0.1
  height: 0.1
  script: bot.lua
  children:
    - {name: wheel, type: joint, joint: revolute, mode: velocity}
)";
constexpr char kBotLua[] = R"(
function sysCall_actuation()
  sim.setJointTargetVelocity(sim.getObject('./wheel'), -5)
  print('lua ran')
end
)";

// A robot running Lua only: it greets every robot, prints how many
// greetings it got, and in step 1 copies bot#0 and removes bot#1.
constexpr char kLuaBot[] = R"(model: luabot
objects:
  {name: body, type: shape, shape: cylinder, radius: 0.1, height: 0.1, script: luabot.lua}
)";
constexpr char kLuaBotLua[] = R"(
local step = 0
function sysCall_actuation()
  step = step + 1
  local count = 0
  while true do
    local data = sim.receiveMessage()
    if data == nil then break end
    if data == 'hi' then count = count + 1 end
  end
  print('got ' .. count)
  sim.sendGlobalMessage('hi')
  if DIRECT then sim.sendDirectMessage(sim.getObject('/bot#0'), 'hi') end
  if step == 1 and COPY then
    sim.copyModel(sim.getObject('/bot#0'))
    sim.removeModel(sim.getObject('/bot#1'))
  end
end
)";

class NativeControllerTest : public testing::WorldDirTest {
 protected:
  void SetUp() override {
    WorldDirTest::SetUp();
    Write("bot.yaml", kBot);
    Write("bot.lua", kBotLua);
    Write("luabot.yaml", kLuaBot);
  }
  LoadedWorld LoadNative(const std::string& world_text, int threads = 1,
                         std::vector<std::string>* log = nullptr) {
    LoadOptions options;
    options.threads = threads;
    options.plugin_directories = {std::filesystem::path(SWARMSIM_BINARY).parent_path() / "plugins"};
    LoadedWorld w = LoadWorld(Write("world.yaml", world_text), options, registry_);
    if (log != nullptr)
      w.world->set_log_sink([log](std::string_view line) { log->emplace_back(line); });
    else
      w.world->set_log_sink([](std::string_view) {});
    return w;
  }
  std::string LoadError(const std::string& world_text) {
    try {
      LoadNative(world_text);
    } catch (const Error& e) {
      return e.what();
    }
    return "NO ERROR";
  }
  // `count` bots running `entry_extra` (lines of their models entry), then
  // `lua_bots` Lua robots.
  static std::string WorldText(const std::string& entry_extra, int count = 4, int lua_bots = 0,
                               const std::string& simulation = "") {
    std::string text =
        "plugins: [example_plugin]\n"
        "simulation: {physics: kinematic, time_step: 0.1" +
        simulation +
        "}\n"
        "arena: {size: 10}\n"
        "models:\n"
        "  - model: bot.yaml\n"
        "    count: " +
        std::to_string(count) +
        "\n"
        "    distribute: {region: arena}\n" +
        entry_extra;
    if (lua_bots > 0)
      text += "  - {model: luabot.yaml, count: " + std::to_string(lua_bots) +
              ", distribute: {region: arena}}\n";
    return text;
  }
  static double WheelTarget(World& world, const std::string& robot) {
    const ObjectId wheel = world.scene().FindObject("/" + robot + "/wheel");
    EXPECT_FALSE(wheel.IsNull()) << robot;
    return wheel.IsNull() ? -1 : world.scene().joint(wheel).target_velocity;
  }
  static int LiveControllers(const World& world) {
    const ScriptCommand* command = world.registry().FindScriptCommand("exampleLiveControllers");
    EXPECT_NE(command, nullptr);
    SwarmsimValue result{};
    char error[64];
    command->function(nullptr, nullptr, 0, &result, 1, error, sizeof error, nullptr);
    return static_cast<int>(result.number);
  }
};

TEST_F(NativeControllerTest, NativeAndLuaRobotsExchangeMessagesTheStepAfter) {
  Write("luabot.lua", kLuaBotLua);
  std::vector<std::string> log;
  LoadedWorld w = LoadNative(WorldText("    native_controller: relay\n", 4, 1), 1, &log);
  World& world = *w.world;
  world.Start();
  world.Step();
  // Nothing was sent before step 1: nothing received.
  for (int r = 0; r < 4; ++r) EXPECT_EQ(WheelTarget(world, "bot#" + std::to_string(r)), 0);
  world.Step();
  // Each native robot got the 3 others' greetings and the Lua robot's; the
  // Lua robot the 4 native ones'. The bots' own Lua script is gone.
  for (int r = 0; r < 4; ++r) EXPECT_EQ(WheelTarget(world, "bot#" + std::to_string(r)), 4);
  const std::vector<std::string> expected = {"[luabot#4] got 0", "[luabot#4] got 4"};
  EXPECT_EQ(log, expected);
}

TEST_F(NativeControllerTest, ALuaScriptSendsADirectMessageToANativeRobot) {
  Write("luabot.lua", std::string("DIRECT = true\n") + kLuaBotLua);
  LoadedWorld w = LoadNative(WorldText("    native_controller: relay\n", 4, 1), 1, nullptr);
  World& world = *w.world;
  world.Start();
  world.Step();
  world.Step();
  // bot#0 got the Lua robot's direct greeting on top of the 4 global ones.
  EXPECT_EQ(WheelTarget(world, "bot#0"), 5);
  for (int r = 1; r < 4; ++r) EXPECT_EQ(WheelTarget(world, "bot#" + std::to_string(r)), 4);
}

TEST_F(NativeControllerTest, KeptScriptsRunFirstAndTheControllerAfterThem) {
  std::vector<std::string> log;
  LoadedWorld w = LoadNative(
      WorldText("    native_controller: {name: relay, keep_scripts: true}\n", 2), 1, &log);
  w.world->Start();
  w.world->Step();
  w.world->Step();
  EXPECT_EQ(log.size(), 4u);                     // the Lua script of both robots, twice
  EXPECT_EQ(WheelTarget(*w.world, "bot#0"), 1);  // the controller's write is the last
}

TEST_F(NativeControllerTest, WithAMainScriptControllersRunInTheActuationPassOnly) {
  Write("main.lua", R"(
function sysCall_step()
  sim.handleSensing()
  sim.handleChildScripts('sensing')
  sim.handleChildScripts('actuation')
  sim.handleActuation()
  sim.handleDynamics()
end
)");
  LoadedWorld w =
      LoadNative(WorldText("    native_controller: relay\n", 4, 0, ", main_script: main.lua"));
  w.world->Start();
  w.world->Step();
  w.world->Step();
  // Once a step: 3 greetings (twice would send 6, and the second pass would find none).
  for (int r = 0; r < 4; ++r) EXPECT_EQ(WheelTarget(*w.world, "bot#" + std::to_string(r)), 3);
}

TEST_F(NativeControllerTest, ParametersReachTheController) {
  // Greetings of another text than the receivers' are not counted.
  LoadedWorld w =
      LoadNative(WorldText("    native_controller: relay\n"
                           "    instances: [{index: 0, parameters: {greeting: yo}}]\n",
                           3));
  w.world->Start();
  w.world->Step();
  w.world->Step();
  EXPECT_EQ(WheelTarget(*w.world, "bot#0"), 0);  // "yo" hears only "hi"
  EXPECT_EQ(WheelTarget(*w.world, "bot#1"), 1);
  EXPECT_EQ(WheelTarget(*w.world, "bot#2"), 1);
}

TEST_F(NativeControllerTest, RandomDrawsAndMessagesDoNotDependOnTheThreadCount) {
  const std::string text =
      WorldText("    native_controller: relay\n    parameters: {noise: 0.5}\n", 40, 0, ", seed: 3");
  std::vector<uint64_t> hashes;
  std::vector<double> targets;
  for (int threads : {1, 2, 4}) {
    LoadedWorld w = LoadNative(text, threads);
    for (int s = 0; s < 20; ++s) w.world->Step();
    hashes.push_back(w.world->StateHash());
    targets.push_back(WheelTarget(*w.world, "bot#7"));
  }
  EXPECT_EQ(hashes[0], hashes[1]);
  EXPECT_EQ(hashes[0], hashes[2]);
  EXPECT_EQ(targets[0], targets[2]);
  // 39 greetings plus a draw in [0, 0.5).
  EXPECT_GE(targets[0], 39);
  EXPECT_LT(targets[0], 39.5);
  EXPECT_NE(targets[0], 39);
}

TEST_F(NativeControllerTest, CopiesRunTheirSourcesControllerAndRemovalsCleanUp) {
  Write("luabot.lua", std::string("COPY = true\n") + kLuaBotLua);
  const int before = LiveControllers(*LoadNative(WorldText("")).world);
  {
    LoadedWorld w = LoadNative(WorldText("    native_controller: relay\n", 3, 1));
    World& world = *w.world;
    world.Start();
    EXPECT_EQ(LiveControllers(world) - before, 3);
    world.Step();  // luabot#3 copies bot#0 (as bot#4) and removes bot#1
    EXPECT_EQ(LiveControllers(world) - before, 3);
    EXPECT_TRUE(world.scene().FindObject("/bot#1").IsNull());
    world.Step();
    world.Step();
    // bot#4 greets and hears: bot#0, bot#2 and the Lua robot.
    EXPECT_EQ(WheelTarget(world, "bot#4"), 3);
    EXPECT_EQ(WheelTarget(world, "bot#0"), 3);
  }
  EXPECT_EQ(LiveControllers(*LoadNative(WorldText("")).world), before);  // Stop cleaned up
}

TEST_F(NativeControllerTest, AFailingStepStopsTheRunNamingTheLowestRobotAndThePlugin) {
  for (int threads : {1, 2}) {
    LoadedWorld w = LoadNative(
        WorldText("    native_controller: faulty\n    parameters: {fail_robot: 1}\n", 6), threads);
    w.world->Start();
    w.world->Step();
    w.world->Step();
    const std::string error = testing::ErrorOf([&] { w.world->Step(); });
    EXPECT_CONTAINS(error, "bot#1: native controller 'faulty' (");
    EXPECT_CONTAINS(error, "example_plugin.so), in step: broke at step 2");
    EXPECT_CONTAINS(testing::ErrorOf([&] { w.world->Step(); }), "cannot be stepped again");
  }
}

TEST_F(NativeControllerTest, AFailingInitStopsTheStart) {
  LoadedWorld w =
      LoadNative(WorldText("    native_controller: faulty\n    parameters: {fail_init: 1}\n", 2));
  const std::string error = testing::ErrorOf([&] { w.world->Start(); });
  EXPECT_CONTAINS(error, "bot#0: native controller 'faulty' (");
  EXPECT_CONTAINS(error, "in init: cannot start robot 0");
}

TEST_F(NativeControllerTest, UnderDisableScriptAFailingControllerStopsAlone) {
  LoadedWorld w =
      LoadNative(WorldText("    native_controller: faulty\n    parameters: {fail_robot: 2}\n", 4, 0,
                           ", on_script_error: disable_script"));
  for (int s = 0; s < 5; ++s) w.world->Step();
  const std::vector<std::string>& disabled = w.world->disabled_scripts();
  ASSERT_EQ(disabled.size(), 2u);  // bot#2 and bot#3, once each
  EXPECT_CONTAINS(disabled[0], "bot#2: native controller 'faulty'");
  EXPECT_CONTAINS(disabled[1], "bot#3: native controller 'faulty'");
}

TEST_F(NativeControllerTest, MistakesAreNamedAtTheirKey) {
  // An unknown name lists the registered ones.
  std::string error = LoadError(WorldText("    native_controller: relya\n"));
  EXPECT_CONTAINS(error, "world.yaml:8:24: 'native_controller': no controller 'relya'");
  EXPECT_CONTAINS(error, "registered: relay, faulty");
  EXPECT_CONTAINS(error, "did you mean 'relay'?");
  // Without the plugin: no controller at all.
  std::string text = WorldText("    native_controller: relay\n");
  text.erase(0, text.find('\n') + 1);
  EXPECT_CONTAINS(LoadError(text),
                  "no plugin of the world's 'plugins:' registers one: list the "
                  "plugin that has it there, as 'plugins: [diffusion_controller]'");
  // A key of the map form that does not exist.
  EXPECT_CONTAINS(LoadError(WorldText("    native_controller: {name: relay, keep: true}\n")),
                  "world.yaml:8:");
  // Python and native on one entry.
  Write("c.py", "def control(robots):\n  pass\n");
  EXPECT_CONTAINS(
      LoadError(WorldText("    native_controller: relay\n    python_controller: c.py\n")),
      "either a 'python_controller' or a 'native_controller'");
}

// worlds/diffusion_native.yaml is worlds/diffusion.yaml with the controller
// in C: the same arithmetic in the same order, so the same state.
TEST_F(NativeControllerTest, TheDiffusionControllerMovesRobotsExactlyAsTheLuaOne) {
  const std::filesystem::path worlds = std::filesystem::path(SWARMSIM_SOURCE_DIR) / "worlds";
  for (int threads : {1, 2}) {
    std::vector<uint64_t> hashes;
    for (const char* file : {"diffusion.yaml", "diffusion_native.yaml"}) {
      LoadOptions options;
      options.threads = threads;
      options.seed = 5;
      options.overrides = {{"robots", "150"}};
      options.plugin_directories = {std::filesystem::path(SWARMSIM_BINARY).parent_path() /
                                    "plugins"};
      LoadedWorld w = LoadWorld(worlds / file, options, registry_);
      w.world->set_log_sink([](std::string_view) {});
      for (int s = 0; s < 150; ++s) w.world->Step();
      hashes.push_back(w.world->StateHash());
    }
    EXPECT_EQ(hashes[0], hashes[1]) << threads << " threads";
  }
}

}  // namespace
}  // namespace swarmsim
