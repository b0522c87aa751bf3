// The Lua host's count hooks (framework/script_hooks.cc): the instruction
// budget of callbacks, the time slice of threads and the memory limit of
// states, none of which a script can catch with pcall.
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

TEST(ScriptControlTest, ThreadThatNeverYieldsGetsExactlyItsSliceEveryStep) {
  ScriptWorld w;
  w.AddRobot("bot#0", R"(
    n = 0
    function sysCall_thread()
      sim.setThreadSwitchTiming(1)  -- 100,000 instructions: 25,000 turns of the loop
      while true do n = n + 1 end
    end
    function sysCall_sensing() sim.recordMetric('n', n) end
  )");
  w.Steps(6);
  const std::vector<MetricSample> metrics = w.world().TakeMetrics();
  ASSERT_EQ(metrics.size(), 6u);
  EXPECT_EQ(metrics[0].value, 0);
  for (size_t step = 1; step < metrics.size(); ++step)
    EXPECT_NEAR(metrics[step].value - metrics[step - 1].value, 25'000, 2) << "step " << step - 1;
}

TEST(ScriptControlTest, EndlessCoroutineOfTheThreadBecomesABudgetError) {
  WorldSettings settings;
  settings.instruction_budget = 1'000'000;
  ScriptWorld w(1, settings);
  w.AddRobot("bot#0",
             "function sysCall_thread()\n  local co = coroutine.wrap(function()\n"
             "    while true do end\n  end)\n  while true do co() end\nend\n");
  const std::string error = ErrorOf([&] { w.Steps(1); });
  EXPECT_CONTAINS(error, "bot#0: scripts/robot.lua:3: ");
  EXPECT_CONTAINS(error, "more than 1000000 Lua instructions");
  EXPECT_CONTAINS(error, "[in sysCall_thread of /bot#0/body]");
}

TEST(ScriptControlTest, EndlessLoopBecomesAnErrorNamingRobotScriptAndLine) {
  WorldSettings settings;
  settings.instruction_budget = 1'000'000;
  ScriptWorld w(1, settings);
  w.AddRobot("bot#0", "function sysCall_actuation()\n  while true do end\nend\n");
  const std::string error = ErrorOf([&] { w.Steps(1); });
  EXPECT_CONTAINS(error, "bot#0: scripts/robot.lua:2: ");
  EXPECT_CONTAINS(error, "more than 1000000 Lua instructions");
  EXPECT_CONTAINS(error, "[in sysCall_actuation of /bot#0/body]");
}

TEST(ScriptControlTest, PcallCannotCatchTheBudgetError) {
  auto error_of = [](const std::string& code) {
    WorldSettings settings;
    settings.instruction_budget = 100'000;
    ScriptWorld w(1, settings);
    w.AddRobot("bot#0", code);
    const std::string error = ErrorOf([&] { w.Steps(2); });
    EXPECT_TRUE(w.log.empty()) << w.log.front();
    return error;
  };
  for (const std::string code : {
           // In a loop: the callback would never return.
           "function sysCall_actuation()\n  while true do\n"
           "    pcall(function() while true do end end)\n  end\nend\n",
           // Once: the run would go on as if nothing happened.
           "function sysCall_actuation()\n  local ok = pcall(function()\n"
           "    while true do end\n  end)\n  print('went on', ok)\nend\n",
           // In a message handler that loops too.
           "function sysCall_actuation()\n  while true do\n"
           "    xpcall(function() while true do end end, function() while true do end end)\n"
           "  end\nend\n",
           // In a coroutine of the callback: each new one would get a fresh count.
           "function sysCall_actuation()\n  while true do\n"
           "    pcall(coroutine.wrap(function() while true do end end))\n  end\nend\n",
       }) {
    const std::string error = error_of(code);
    EXPECT_CONTAINS(error, "bot#0: scripts/robot.lua:3: ");
    EXPECT_CONTAINS(error, "more than 100000 Lua instructions");
    EXPECT_CONTAINS(error, "[in sysCall_actuation of /bot#0/body]");
  }
}

TEST(ScriptControlTest, ExplicitScriptsRunOnTheirCallersBudget) {
  WorldSettings settings;
  settings.instruction_budget = 100'000;
  ScriptWorld w(1, settings);
  const ObjectId body =
      w.AddRobot("bot#0",
                 "function sysCall_actuation()\n  local arm = sim.getObject('./arm')\n"
                 "  while true do sim.handleChildScript(arm) end\nend\n");
  const ObjectId arm = w.scene().AddDummy("arm", body, {});
  w.scene().AttachScript(arm, Source("scripts/arm.lua", "function sysCall_actuation() end"),
                         /*explicit_handling=*/true);
  const std::string error = ErrorOf([&] { w.Steps(1); });
  EXPECT_CONTAINS(error, "more than 100000 Lua instructions");
  EXPECT_CONTAINS(error, "[in sysCall_actuation of /bot#0/body]");
}

TEST(ScriptControlTest, PcallCannotCatchTheBudgetErrorOfAThread) {
  WorldSettings settings;
  settings.instruction_budget = 1'000'000;
  ScriptWorld w(1, settings);
  // A comparator cannot yield: the budget applies there.
  w.AddRobot("bot#0",
             "function sysCall_thread()\n  while true do\n"
             "    pcall(table.sort, {3, 2, 1}, function() while true do end end)\n"
             "  end\nend\n");
  const std::string error = ErrorOf([&] { w.Steps(3); });
  EXPECT_CONTAINS(error, "bot#0: scripts/robot.lua:3: ");
  EXPECT_CONTAINS(error, "more than 1000000 Lua instructions");
  EXPECT_CONTAINS(error, "[in sysCall_thread of /bot#0/body]");
}

TEST(ScriptControlTest, RunawayMemoryBecomesAnErrorNamingRobotScriptAndLine) {
  WorldSettings settings;
  settings.script_memory_limit = 4 << 20;
  ScriptWorld w(1, settings);
  w.AddRobot("bot#0",
             "local t = {}\nfunction sysCall_actuation()\n  while true do\n"
             "    t[#t + 1] = string.rep('x', 10000) .. #t\n  end\nend\n");
  const std::string error = ErrorOf([&] { w.Steps(1); });
  EXPECT_CONTAINS(error, "bot#0: scripts/robot.lua:4: the scripts hold more than 4 MiB");
  EXPECT_CONTAINS(error, "simulation.script_memory_mb");
  EXPECT_CONTAINS(error, "[in sysCall_actuation of /bot#0/body]");
}

TEST(ScriptControlTest, PcallCannotCatchTheMemoryLimit) {
  WorldSettings settings;
  settings.script_memory_limit = 4 << 20;
  ScriptWorld w(1, settings);
  // A pcall loop would retry for ever, an xpcall handler that loops would
  // never return: the limit must end the callback either way.
  w.AddRobot(
      "bot#0",
      "local t = {}\n"
      "local function grow() while true do t[#t + 1] = string.rep('x', 10000) .. #t end end\n"
      "function sysCall_actuation()\n"
      "  while true do pcall(grow) end\n"
      "end\n");
  w.AddRobot(
      "bot#1",
      "local t = {}\n"
      "local function grow() while true do t[#t + 1] = string.rep('x', 10000) .. #t end end\n"
      "function sysCall_actuation()\n"
      "  xpcall(grow, function() while true do end end)\n"
      "end\n",
      1);
  const std::string error = ErrorOf([&] { w.Steps(1); });
  EXPECT_CONTAINS(error, "bot#0: scripts/robot.lua:2: the scripts hold more than 4 MiB");
}

TEST(ScriptControlTest, RunawayMemoryInAThreadIsCaughtToo) {
  WorldSettings settings;
  settings.script_memory_limit = 4 << 20;
  ScriptWorld w(1, settings);
  w.AddRobot("bot#0",
             "function sysCall_thread()\n  local t = {}\n"
             "  while true do t[#t + 1] = {1, 2, 3} end\nend\n");
  const std::string error = ErrorOf([&] { w.Steps(2); });
  EXPECT_CONTAINS(error, "bot#0: scripts/robot.lua:3: the scripts hold more than 4 MiB");
  EXPECT_CONTAINS(error, "[in sysCall_thread of /bot#0/body]");
}

TEST(ScriptControlTest, OneAllocationPastTheLimitIsRefused) {
  WorldSettings settings;
  settings.script_memory_limit = 4 << 20;
  ScriptWorld w(1, settings);
  w.AddRobot("bot#0", "function sysCall_actuation() local s = string.rep('x', 1e8) end");
  EXPECT_CONTAINS(
      ErrorOf([&] { w.Steps(1); }),
      "bot#0: scripts/robot.lua:1: an allocation of 95 MiB would take the scripts past 4 MiB "
      "of Lua memory");
}

// A refusal Lua recovers from is no error: its emergency collection frees
// the last step's string and its retry fits. Each step below holds 12 MiB
// (24 MiB while string.rep copies its buffer) under a 16 MiB limit (with
// its 16 MiB of slack for a moment), with the last step's 12 MiB of
// garbage: the second step failed ("an allocation of 12 MiB would take the
// scripts past 16 MiB") though the docs say garbage is collected first.
// One that cannot fit still fails, and pcall cannot catch it.
TEST(ScriptControlTest, AnAllocationThatFitsOnceGarbageIsCollectedIsGranted) {
  WorldSettings settings;
  settings.script_memory_limit = 16 << 20;
  // A local: the last step's string is garbage (a global would hold it
  // while string.rep builds the next, and it could not be freed).
  const std::string keep = "  local keep = string.rep('x', 12 * 1024 * 1024)\n";
  ScriptWorld fits(1, settings);
  fits.AddRobot(
      "bot#0", "function sysCall_actuation()\n" + keep + "  sim.recordMetric('len', #keep)\nend\n");
  fits.Steps(4);
  EXPECT_EQ(fits.world().TakeMetrics().size(), 4u);
  ScriptWorld w(1, settings);
  w.AddRobot("bot#0", "function sysCall_actuation()\n" + keep +
                          "  pcall(string.rep, 'y', 40 * 1024 * 1024)\n"
                          "  sim.recordMetric('len', #keep)\nend\n");
  EXPECT_CONTAINS(ErrorOf([&] { w.Steps(1); }),
                  "an allocation of 40 MiB would take the scripts past 16 MiB");
}

// Under disable_script, a refused allocation disables its script only: the
// robot's next script is not failed by the refusal already reported (with no
// instruction budget, nothing else replaces the hook the refusal armed).
TEST(ScriptControlTest, ARefusedAllocationDoesNotFailTheNextScript) {
  WorldSettings settings;
  settings.script_memory_limit = 4 << 20;
  settings.instruction_budget = 0;
  settings.on_script_error = ScriptErrorPolicy::kDisableScript;
  ScriptWorld w(1, settings);
  const ObjectId body =
      w.AddRobot("bot#0", "function sysCall_actuation() local s = string.rep('x', 1e8) end");
  w.scene().AttachScript(
      w.scene().AddDummy("eye", body, {}),
      Source("scripts/eye.lua", "function sysCall_actuation() sim.recordMetric('alive', 1) end"));
  w.Steps(3);
  ASSERT_EQ(w.world().disabled_scripts().size(), 1u);
  EXPECT_CONTAINS(w.world().disabled_scripts()[0], "of /bot#0/body]");
  EXPECT_EQ(w.world().TakeMetrics().size(), 3u);
}

// Each refused allocation costs Lua a full collection and a retry; a pcall
// loop around one would go on until the step timeout. The first refusal
// fails the callback instead, with the line, and pcall cannot catch it.
TEST(ScriptControlTest, APcallLoopAroundARefusedAllocationEndsAtOnce) {
  WorldSettings settings;
  settings.script_memory_limit = 4 << 20;
  settings.instruction_budget = 1000000;  // without the rule: a budget error instead
  ScriptWorld w(1, settings);
  w.AddRobot("bot#0",
             "function sysCall_actuation()\n"
             "  local n = 0\n"
             "  while true do pcall(string.rep, 'x', 1e9); n = n + 1 end\n"
             "end\n");
  const std::string error = ErrorOf([&] { w.Steps(1); });
  EXPECT_CONTAINS(error,
                  "bot#0: scripts/robot.lua:3: an allocation of 953 MiB would take the "
                  "scripts past 4 MiB of Lua memory");
  EXPECT_CONTAINS(error, "[in sysCall_actuation of /bot#0/body]");
  // The next step's callbacks are not failed by the refusal that was reported.
}

TEST(ScriptControlTest, GarbageAboveTheLimitIsCollectedNotAnError) {
  WorldSettings settings;
  settings.script_memory_limit = 2 << 20;
  ScriptWorld w(1, settings);
  // ~20 MB of short-lived strings a step, never more than ~100 KB alive.
  w.AddRobot("bot#0", R"(
    function sysCall_actuation()
      for i = 1, 200 do local s = string.rep('y', 100000) .. i end
      sim.recordMetric('done', 1)
    end)");
  w.Steps(5);
  EXPECT_EQ(w.world().TakeMetrics().size(), 5u);
  EXPECT_LT(w.world().script_memory_bytes(), size_t{2} << 20);
}

TEST(ScriptControlTest, ThreadSliceIsCappedAtTheInstructionBudget) {
  // 100,000 instructions are 25,000 turns of the loop.
  auto turns_per_step = [](const std::string& timing, const std::string& init = "") {
    WorldSettings settings;
    settings.instruction_budget = 100'000;
    ScriptWorld w(1, settings);
    w.AddRobot("bot#0", R"(
      n = 0
      function sysCall_init() )" +
                            init + R"( end
      function sysCall_thread()
        )" + timing + R"(
        while true do n = n + 1 end
      end
      function sysCall_sensing() sim.recordMetric('n', n) end
    )");
    w.Steps(4);
    const std::vector<MetricSample> metrics = w.world().TakeMetrics();
    return metrics.back().value - metrics[metrics.size() - 2].value;
  };
  EXPECT_NEAR(turns_per_step("sim.setThreadSwitchTiming(10)"), 25'000, 2);  // 1,000,000 asked
  EXPECT_NEAR(turns_per_step("sim.setThreadSwitchTiming(1e300)"), 25'000, 2);
  EXPECT_NEAR(turns_per_step(""), 25'000, 2);  // the default, 200,000
  EXPECT_NEAR(turns_per_step("sim.setThreadSwitchTiming(0.5)"), 12'500, 2);
  EXPECT_NEAR(turns_per_step("", "sim.setThreadSwitchTiming(0.5)"), 12'500,
              2);  // before the thread
}

}  // namespace
}  // namespace swarmsim
