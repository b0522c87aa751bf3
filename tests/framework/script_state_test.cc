// The errors of the Lua host (framework/script_state.cc): what a failing
// script does under on_script_error (stop the run naming the robot, or
// disable that script and go on), and what is kept of the prints before.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "framework/error.h"
#include "framework/world.h"
#include "tests/framework/error_of.h"
#include "tests/framework/fakes.h"
#include "tests/framework/script_world.h"

namespace swarmsim {
namespace {

using namespace script_test;  // script_world.h

using testing::ErrorOf;

TEST(ScriptControlTest, StopPolicyEndsTheRunWithTheFaultyRobotNamed) {
  ScriptWorld w(2);
  for (int r = 0; r < 1000; ++r)
    w.AddRobot("bot#" + std::to_string(r),
               r == 617 ? "function sysCall_actuation() error('boom') end"
                        : "function sysCall_actuation() end",
               r);
  const std::string error = ErrorOf([&] { w.Steps(1); });
  EXPECT_CONTAINS(error,
                  "bot#617: scripts/robot.lua:1: boom [in sysCall_actuation of /bot#617/body]");
}

TEST(ScriptControlTest, StopPolicyCleanupErrorKeepsEveryRobotsCleanupPrintsInRobotOrder) {
  for (int threads : {1, 2}) {
    ScriptWorld w(threads);
    for (int r = 0; r < 3; ++r)
      w.AddRobot("bot#" + std::to_string(r), R"(
        function sysCall_cleanup()
          print('cleanup ran')
          if sim.getRobotIndex() == 1 then error('boom') end
        end
      )",
                 r);
    w.Steps(1);
    EXPECT_CONTAINS(ErrorOf([&] { w.world().Stop(); }),
                    "bot#1: scripts/robot.lua:4: boom [in sysCall_cleanup of /bot#1/body]");
    const std::vector<std::string> expected = {"[bot#0] cleanup ran", "[bot#1] cleanup ran",
                                               "[bot#2] cleanup ran"};
    EXPECT_EQ(w.log, expected) << threads << " threads";
  }
}

TEST(ScriptControlTest, StopPolicyInitErrorKeepsEveryRobotsInitPrintsInRobotOrder) {
  for (int threads : {1, 3}) {
    ScriptWorld w(threads);
    for (int r = 0; r < 10; ++r)
      w.AddRobot("bot#" + std::to_string(r), R"(
        function sysCall_init()
          print('init')
          if sim.getRobotIndex() == 5 then error('boom') end
        end
      )",
                 r);
    EXPECT_CONTAINS(ErrorOf([&] { w.world().Start(); }),
                    "bot#5: scripts/robot.lua:4: boom [in sysCall_init of /bot#5/body]");
    std::vector<std::string> expected;
    for (int r = 0; r < 10; ++r) expected.push_back("[bot#" + std::to_string(r) + "] init");
    EXPECT_EQ(w.log, expected) << threads << " threads";
  }
}

TEST(ScriptControlTest, StopPolicyMainScriptErrorKeepsWhatItPrintedBefore) {
  WorldSettings settings;
  settings.main_script = Source("main.lua", R"(
    function sysCall_init() print('main init') end
    function sysCall_step()
      print('main step')
      error('boom')
    end
  )");
  ScriptWorld w(1, settings);
  w.AddRobot("bot#0", "function sysCall_init() print('init') end");
  EXPECT_CONTAINS(ErrorOf([&] { w.Steps(1); }), "main: main.lua:5: boom [in sysCall_step");
  const std::vector<std::string> expected = {"[bot#0] init", "[main] main init",
                                             "[main] main step"};
  EXPECT_EQ(w.log, expected);
  // A main script that fails in sysCall_init keeps the robots' prints too.
  WorldSettings failing_init;
  failing_init.main_script = Source("main.lua", R"(
    function sysCall_init() print('main init') error('bad init') end
    function sysCall_step() end
  )");
  ScriptWorld v(1, failing_init);
  v.AddRobot("bot#0", "function sysCall_init() print('init') end");
  EXPECT_CONTAINS(ErrorOf([&] { v.world().Start(); }), "main.lua:2: bad init");
  const std::vector<std::string> expected_init = {"[bot#0] init", "[main] main init"};
  EXPECT_EQ(v.log, expected_init);
}

TEST(ScriptControlTest, DisableScriptPolicyLogsOnceAndTheSwarmGoesOn) {
  WorldSettings settings;
  settings.on_script_error = ScriptErrorPolicy::kDisableScript;
  settings.instruction_budget = 100'000;
  ScriptWorld w(2, settings);
  for (int r = 0; r < 1000; ++r)
    w.AddRobot("bot#" + std::to_string(r),
               r == 617 ? "function sysCall_actuation()\n  while true do end\nend"
                        : "function sysCall_actuation() sim.recordMetric('alive', 1) end",
               r);
  w.Steps(3);
  ASSERT_EQ(w.log.size(), 1u);
  EXPECT_CONTAINS(w.log[0], "script disabled: bot#617: scripts/robot.lua:2:");
  EXPECT_CONTAINS(w.log[0], "[in sysCall_actuation of /bot#617/body]");
  EXPECT_EQ(w.world().TakeMetrics().size(), 3u * 999u);
}

TEST(ScriptControlTest, DisableScriptPolicyCoversCleanupErrors) {
  WorldSettings settings;
  settings.on_script_error = ScriptErrorPolicy::kDisableScript;
  ScriptWorld w(2, settings);
  for (int r = 0; r < 3; ++r)
    w.AddRobot("bot#" + std::to_string(r),
               r == 1 ? "function sysCall_cleanup()\n  error('bye')\nend"
                      : "function sysCall_cleanup() print('cleanup') end",
               r);
  w.Steps(1);
  EXPECT_EQ(ErrorOf([&] { w.world().Stop(); }), "");
  ASSERT_EQ(w.log.size(), 3u);
  EXPECT_EQ(w.log[0], "[bot#0] cleanup");
  EXPECT_EQ(w.log[1],
            "error, script disabled: bot#1: scripts/robot.lua:2: bye [in sysCall_cleanup of "
            "/bot#1/body]");
  EXPECT_EQ(w.log[2], "[bot#2] cleanup");
  ASSERT_EQ(w.world().disabled_scripts().size(), 1u);
  EXPECT_CONTAINS(w.world().disabled_scripts()[0], "bot#1: scripts/robot.lua:2: bye");
}

TEST(ScriptControlTest, DisableScriptPolicyWithoutABudgetLetsTheRobotsOtherScriptsGoOn) {
  // With instruction_budget 0, the spent memory limit of one script failed
  // every later script of its robot ("not enough memory").
  WorldSettings settings;
  settings.on_script_error = ScriptErrorPolicy::kDisableScript;
  settings.instruction_budget = 0;
  settings.script_memory_limit = 4 << 20;
  ScriptWorld w(1, settings);
  const ObjectId body = w.AddRobot("bot#0",
                                   "function sysCall_actuation()\n  local t = {}\n"
                                   "  while true do t[#t + 1] = string.rep('x', 10000) .. #t end\n"
                                   "end\n");
  const ObjectId arm = w.scene().AddDummy("arm", body, {});
  w.scene().AttachScript(
      arm, Source("scripts/arm.lua", "function sysCall_actuation() print('arm') end"));
  w.Steps(3);
  ASSERT_EQ(w.log.size(), 4u);
  EXPECT_CONTAINS(w.log[0], "script disabled: bot#0: scripts/robot.lua:3: the scripts hold more");
  EXPECT_EQ(w.log[1], "[bot#0] arm");
  EXPECT_EQ(w.log[3], "[bot#0] arm");
}

TEST(ScriptControlTest, DisableScriptPolicyCoversMainChunkErrors) {
  auto world_with_a_failing_body = [](ScriptErrorPolicy policy) {
    WorldSettings settings;
    settings.on_script_error = policy;
    auto w = std::make_unique<ScriptWorld>(2, settings);
    for (int r = 0; r < 3; ++r)
      w->AddRobot("bot#" + std::to_string(r),
                  std::string(r == 1 ? "local x = 1\nerror('boom')\n" : "") +
                      "function sysCall_init() print('init') end\n"
                      "function sysCall_actuation() sim.recordMetric('alive', 1) end\n"
                      "function sysCall_cleanup() print('cleanup') end\n",
                  r);
    return w;
  };
  auto w = world_with_a_failing_body(ScriptErrorPolicy::kDisableScript);
  w->Steps(2);
  w->world().Stop();
  const std::vector<std::string> expected = {
      "[bot#0] init",
      "error, script disabled: bot#1: scripts/robot.lua:2: boom [in the main chunk of "
      "/bot#1/body]",
      "[bot#2] init", "[bot#0] cleanup", "[bot#2] cleanup"};
  EXPECT_EQ(w->log, expected);
  EXPECT_EQ(w->world().TakeMetrics().size(), 4u);
  ASSERT_EQ(w->world().disabled_scripts().size(), 1u);
  EXPECT_CONTAINS(w->world().disabled_scripts()[0], "bot#1: scripts/robot.lua:2: boom");
  // Under stop the run ends, as before.
  auto v = world_with_a_failing_body(ScriptErrorPolicy::kStop);
  EXPECT_CONTAINS(ErrorOf([&] { v->world().Start(); }),
                  "bot#1: scripts/robot.lua:2: boom [in the main chunk of /bot#1/body]");
}

TEST(ScriptControlTest, CallbackThatIsNotAFunctionIsAnErrorAtLoad) {
  const std::pair<std::string, std::string> cases[] = {
      {"sysCall_actuation = 5", "sysCall_actuation must be a function (got number)"},
      {"sysCall_init = 'x'", "sysCall_init must be a function (got string)"},
      {"function sysCall_init() sysCall_sensing = {} end",
       "sysCall_sensing must be a function (got table)"},
      {"sysCall_thread = true", "sysCall_thread must be a function (got boolean)"},
  };
  for (const auto& [code, message] : cases) {
    ScriptWorld w;
    w.AddRobot("bot#0", code);
    EXPECT_CONTAINS(ErrorOf([&] { w.world().Start(); }), "bot#0: scripts/robot.lua: " + message +
                                                             " [in loading the script of "
                                                             "/bot#0/body]");
  }
  // Under disable_script, that script is disabled like one whose sysCall_init fails.
  WorldSettings settings;
  settings.on_script_error = ScriptErrorPolicy::kDisableScript;
  ScriptWorld w(1, settings);
  w.AddRobot("bot#0", "sysCall_actuation = 5\nfunction sysCall_sensing() print('sensing') end");
  w.Steps(1);
  ASSERT_EQ(w.log.size(), 1u);
  EXPECT_CONTAINS(w.log[0], "script disabled: bot#0: scripts/robot.lua: sysCall_actuation must");
}

}  // namespace
}  // namespace swarmsim
