// Distributed control: explicit child scripts, threaded scripts, the
// instruction budget and error policies, the main script, messages,
// signals and packing.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "framework/error.h"
#include "framework/line_of_sight.h"
#include "framework/world.h"
#include "tests/framework/error_of.h"
#include "tests/framework/fakes.h"

namespace swarmsim {
namespace {

std::shared_ptr<const ScriptSource> Source(std::string path, std::string code) {
  return std::make_shared<const ScriptSource>(ScriptSource{std::move(path), std::move(code)});
}

// A world with null modules whose script output lands in `log`.
class ScriptWorld {
 public:
  explicit ScriptWorld(int threads = 1, WorldSettings settings = {},
                       ModuleRegistry registry = testing::NullRegistry())
      : registry_(std::move(registry)) {
    settings.physics = "null";
    settings.time_step = 0.1;
    settings.threads = threads;
    world_ = std::make_unique<World>(settings, registry_);
    world_->set_log_sink([this](std::string_view line) { log.emplace_back(line); });
  }
  World& world() { return *world_; }
  Scene& scene() { return world_->scene(); }

  // A robot: root dummy at (x, y) with heading `yaw` carrying a `body`
  // dummy with `code` attached (unless empty). Returns the body.
  ObjectId AddRobot(const std::string& name, const std::string& code, double x = 0, double y = 0,
                    double yaw = 0) {
    const ObjectId root =
        scene().AddDummy(name, {}, {{x, y, 0}, Quat::FromAxisAngle({0, 0, 1}, yaw)});
    const ObjectId body = scene().AddDummy("body", root, {});
    scene().MakeModelInstance(root, "bot", name);
    if (!code.empty()) scene().AttachScript(body, Source("scripts/robot.lua", code));
    return body;
  }
  void Steps(int n) {
    for (int i = 0; i < n; ++i) world_->Step();
  }
  std::vector<std::string> log;

 private:
  ModuleRegistry registry_;
  std::unique_ptr<World> world_;
};

using testing::ErrorOf;

// --- Child scripts ------------------------------------------------------------------------

TEST(ScriptControlTest, ExplicitScriptRunsOnlyWhenItsParentCallsItAndReturnsValues) {
  ScriptWorld w;
  const ObjectId body = w.AddRobot("bot#0", R"(
    function sysCall_actuation()
      print('parent before')
      local a, b = sim.handleChildScript(sim.getObject('./arm'), 3, 'x')
      print('parent got', a, b)
    end
  )");
  const ObjectId arm = w.scene().AddDummy("arm", body, {});
  const ObjectId hand = w.scene().AddDummy("hand", arm, {});
  w.scene().AttachScript(arm, Source("scripts/arm.lua", R"(
    function sysCall_actuation(n, s)
      print('arm', n, s)
      return n * 2, s .. '!'
    end
  )"),
                         /*explicit_handling=*/true);
  w.scene().AttachScript(hand, Source("scripts/hand.lua", R"(
    function sysCall_actuation() print('hand (implicit, after its parents)') end
  )"));
  w.Steps(1);
  const std::vector<std::string> expected = {"[bot#0] parent before", "[bot#0] arm\t3\tx",
                                             "[bot#0] parent got\t6\tx!",
                                             "[bot#0] hand (implicit, after its parents)"};
  EXPECT_EQ(w.log, expected);
}

TEST(ScriptControlTest, HandleChildScriptRefusesNonExplicitAndNonDescendantScripts) {
  ScriptWorld w;
  const ObjectId body = w.AddRobot("bot#0", R"(
    function sysCall_actuation() sim.handleChildScript(sim.getObject('./eye')) end
  )");
  const ObjectId eye = w.scene().AddDummy("eye", body, {});
  w.scene().AttachScript(eye, Source("scripts/eye.lua", "function sysCall_actuation() end"));
  EXPECT_CONTAINS(ErrorOf([&] { w.Steps(1); }), "is not explicit");
  ScriptWorld v;
  const ObjectId body2 = v.AddRobot("bot#0", R"(
    function sysCall_actuation() sim.handleChildScript(sim.getObject('./other')) end
  )");
  v.scene().AddDummy("other", body2, {});
  EXPECT_CONTAINS(ErrorOf([&] { v.Steps(1); }), "no script of this model");
}

// --- Threaded scripts ----------------------------------------------------------------------

TEST(ScriptControlTest, ThreadedScriptWaitsAndStepsAndGetsCleanup) {
  ScriptWorld w;
  w.AddRobot("bot#0", R"(
    function sysCall_thread()
      print('start', sim.getSimulationTime())
      sim.step()
      print('next', sim.getSimulationTime())
      sim.wait(0.3)
      print('waited', sim.getSimulationTime())
      sim.waitUntil(function() return sim.getSimulationTime() > 0.75 end)
      print('until', sim.getSimulationTime())
      while true do sim.switchThread() end
    end
    function sysCall_cleanup() print('cleanup') end
  )");
  w.Steps(10);
  w.world().Stop();
  const std::vector<std::string> expected = {"[bot#0] start\t0.0", "[bot#0] next\t0.1",
                                             "[bot#0] waited\t0.4", "[bot#0] until\t0.8",
                                             "[bot#0] cleanup"};
  EXPECT_EQ(w.log, expected);
}

TEST(ScriptControlTest, ThreadThatNeverYieldsIsSwitchedOutEachStep) {
  ScriptWorld w;
  w.AddRobot("bot#0", R"(
    n = 0
    function sysCall_thread()
      sim.setThreadSwitchTiming(1)  -- 100,000 instructions
      while true do n = n + 1 end
    end
    function sysCall_sensing() print(n > 0) end
  )");
  w.Steps(3);  // completes: the slice yields the loop
  EXPECT_EQ(w.log, (std::vector<std::string>{"[bot#0] false", "[bot#0] true", "[bot#0] true"}));
}

TEST(ScriptControlTest, ThreadSlicesAreDeterministic) {
  auto run = [](int threads) {
    ScriptWorld w(threads);
    for (int r = 0; r < 8; ++r)
      w.AddRobot("bot#" + std::to_string(r), R"(
        n = 0
        function sysCall_thread() while true do n = n + 1 end end
        function sysCall_sensing() sim.recordMetric('n', n) end
      )",
                 r);
    w.Steps(4);
    std::vector<double> values;
    for (const MetricSample& m : w.world().TakeMetrics()) values.push_back(m.value);
    return values;
  };
  const std::vector<double> one = run(1);
  EXPECT_GT(one.back(), 0);
  EXPECT_EQ(one, run(2));
}

TEST(ScriptControlTest, StepOutsideAThreadIsAnError) {
  ScriptWorld w;
  w.AddRobot("bot#0", "function sysCall_actuation() sim.step() end");
  EXPECT_CONTAINS(ErrorOf([&] { w.Steps(1); }), "only a threaded script");
}

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

TEST(ScriptControlTest, ACoroutineOfTheThreadRunsToItsEndAndReturnsItsValues) {
  ScriptWorld w;
  w.AddRobot("bot#0", R"(
    function sysCall_thread()
      local co = coroutine.create(function()
        for i = 1, 1e6 do end  -- five time slices
        return 'done'
      end)
      print(coroutine.resume(co))
      print(coroutine.status(co))
    end
  )");
  w.Steps(1);
  EXPECT_EQ(w.log, (std::vector<std::string>{"[bot#0] true\tdone", "[bot#0] dead"}));
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

TEST(ScriptControlTest, StepInsideACoroutineOfTheThreadIsAnError) {
  ScriptWorld w;
  w.AddRobot("bot#0",
             "function sysCall_thread()\n  local co = coroutine.wrap(function()\n"
             "    sim.step()\n  end)\n  co()\n  print('went on')\nend\n");
  const std::string error = ErrorOf([&] { w.Steps(2); });
  // coroutine.wrap prefixes the line of its caller.
  EXPECT_CONTAINS(error,
                  "scripts/robot.lua:3: sim.step: call it from sysCall_thread itself, "
                  "not from a coroutine of your own [in sysCall_thread of /bot#0/body]");
  EXPECT_TRUE(w.log.empty()) << w.log.front();
}

// --- Budget and error policy ---------------------------------------------------------------

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

TEST(ScriptControlTest, WaitOutsideAThreadNamesTheCallersLine) {
  ScriptWorld w;
  w.AddRobot("bot#0", "function sysCall_actuation()\n  sim.wait(1)\nend\n");
  EXPECT_CONTAINS(ErrorOf([&] { w.Steps(1); }),
                  "bot#0: scripts/robot.lua:2: sim.wait: only a threaded script");
}

// --- Memory limit --------------------------------------------------------------------------

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
      "bot#0: scripts/robot.lua: an allocation would take the scripts past 4 MiB of Lua "
      "memory");
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

// --- Main script ---------------------------------------------------------------------------

TEST(ScriptControlTest, WorldMainScriptRunsThePhases) {
  WorldSettings settings;
  settings.main_script = Source("main.lua", R"(
    function sysCall_step()
      print('main', sim.getSimulationTime())
      sim.handleSensing()
      sim.handleChildScripts('actuation')
      sim.handleChildScripts('sensing')
      sim.handleActuation()
      sim.handleDynamics()
    end
  )");
  ScriptWorld w(1, settings);
  w.AddRobot("bot#0", R"(
    function sysCall_sensing() print('sensing') end
    function sysCall_actuation() print('actuation') end
  )");
  w.Steps(2);
  const std::vector<std::string> expected = {"[main] main\t0.0",  "[bot#0] actuation",
                                             "[bot#0] sensing",   "[main] main\t0.1",
                                             "[bot#0] actuation", "[bot#0] sensing"};
  EXPECT_EQ(w.log, expected);
  EXPECT_DOUBLE_EQ(w.world().time(), 0.2);
}

// A swarm metric: the step count after physics, recorded every step.
class StepObserver : public Observer {
 public:
  void Record(const World& world, std::vector<MetricSample>* out) override {
    out->push_back({world.step_count(), world.time(), -1, "observer", 0});
  }
};

// A main script's rows: the step the world has reached where they are
// recorded, the robots' signals of the same step (not the step before), and
// metrics.csv's order: the step never goes back.
TEST(ScriptControlTest, MainScriptMetricsDescribeTheirStepAndComeInStepOrder) {
  WorldSettings settings;
  settings.main_script = Source("main.lua", R"(
    function sysCall_step()
      sim.handleSensing()
      sim.handleChildScripts()
      sim.recordMetric('pre', sim.getSignal('robot_step'))
      sim.handleActuation()
      sim.handleDynamics()
      sim.recordMetric('post', sim.getSignal('robot_step'))
    end
  )");
  ScriptWorld w(2, settings);
  w.AddRobot("bot#0", R"(
    local n = 0
    function sysCall_actuation()
      sim.recordMetric('robot', n)
      sim.setSignal('robot_step', n)
      n = n + 1
    end
  )");
  w.world().AddObserver(std::make_unique<StepObserver>());
  std::vector<std::string> rows;
  for (int i = 0; i < 3; ++i) {
    w.Steps(1);
    for (const MetricSample& m : w.world().TakeMetrics())
      rows.push_back(std::to_string(m.step) + " " + m.name + " " + std::to_string(int(m.value)));
  }
  const std::vector<std::string> expected = {
      "0 robot 0", "0 pre 0", "1 post 0", "1 observer 0",  // step 0
      "1 robot 1", "1 pre 1", "2 post 1", "2 observer 0",  // step 1
      "2 robot 2", "2 pre 2", "3 post 2", "3 observer 0"};
  EXPECT_EQ(rows, expected);
}

TEST(ScriptControlTest, HandleChildScriptsForwardsExtraArguments) {
  WorldSettings settings;
  settings.main_script = Source("main.lua", R"(
    function sysCall_step()
      sim.handleSensing()
      sim.handleChildScripts('sensing', 'gain', 2.5, true)
      sim.handleChildScripts('actuation')
      sim.handleActuation()
      sim.handleDynamics()
    end
  )");
  ScriptWorld w(2, settings);
  for (int r = 0; r < 3; ++r)
    w.AddRobot("bot#" + std::to_string(r), R"(
      function sysCall_sensing(name, value, flag) print(name, value, flag) end
      function sysCall_actuation(...) print('actuation', select('#', ...)) end
    )",
               r);
  w.Steps(1);
  const std::vector<std::string> expected = {"[bot#0] gain\t2.5\ttrue", "[bot#1] gain\t2.5\ttrue",
                                             "[bot#2] gain\t2.5\ttrue", "[bot#0] actuation\t0",
                                             "[bot#1] actuation\t0",    "[bot#2] actuation\t0"};
  EXPECT_EQ(w.log, expected);
  WorldSettings bad;
  bad.main_script =
      Source("main.lua", "function sysCall_step() sim.handleChildScripts('all', {}) end");
  ScriptWorld v(1, bad);
  EXPECT_CONTAINS(ErrorOf([&] { v.Steps(1); }),
                  "main.lua:1: sim.handleChildScripts: argument 2 must be");
}

TEST(ScriptControlTest, HandleChildScriptsListsItsPassesAndSuggestsTheNearest) {
  WorldSettings settings;
  settings.main_script =
      Source("main.lua", "function sysCall_step()\n  sim.handleChildScripts('actuate')\nend\n");
  ScriptWorld w(1, settings);
  EXPECT_CONTAINS(ErrorOf([&] { w.Steps(1); }),
                  "main.lua:2: sim.handleChildScripts: bad argument #1 (invalid option "
                  "'actuate'; expected 'sensing', 'actuation' or 'all'; did you mean "
                  "'actuation'?)");
  WorldSettings far;
  far.main_script =
      Source("main.lua", "function sysCall_step() sim.handleChildScripts('physics') end");
  ScriptWorld v(1, far);
  EXPECT_CONTAINS(ErrorOf([&] { v.Steps(1); }),
                  "bad argument #1 (invalid option 'physics'; expected 'sensing', 'actuation' or "
                  "'all')");
}

TEST(ScriptControlTest, MainScriptWithoutSysCallStepSuggestsAMisspeltOne) {
  WorldSettings settings;
  settings.main_script = Source("main.lua",
                                "function sysCall_init() end\n"
                                "function sysCall_stpe()\n  sim.handleDynamics()\nend\n");
  ScriptWorld w(1, settings);
  const std::string error = ErrorOf([&] { w.world().Start(); });
  EXPECT_CONTAINS(error, "main: main.lua: the main script must define sysCall_step()");
  EXPECT_CONTAINS(error, "main.lua:2 defines sysCall_stpe: did you mean sysCall_step?");
}

TEST(ScriptControlTest, MainScriptMustStepTheDynamicsAndChildrenCannotRunPhases) {
  WorldSettings settings;
  settings.main_script = Source("main.lua", "function sysCall_step() sim.handleSensing() end");
  ScriptWorld w(1, settings);
  EXPECT_CONTAINS(ErrorOf([&] { w.Steps(1); }), "must call sim.handleDynamics()");
  ScriptWorld v;
  v.AddRobot("bot#0", "function sysCall_actuation() sim.handleDynamics() end");
  EXPECT_CONTAINS(ErrorOf([&] { v.Steps(1); }), "only the world's main script");
}

// A main script that catches a handler's error (pcall) does not keep a
// broken world going: no phase runs after it, and the step fails with it.
TEST(ScriptControlTest, MainScriptCannotSwallowAPhaseError) {
  WorldSettings settings;
  settings.main_script = Source("main.lua",
                                "function sysCall_step()\n"
                                "  print(pcall(sim.handleChildScripts))\n"
                                "  print(pcall(sim.handleDynamics))\n"
                                "end\n");
  ScriptWorld w(1, settings);
  w.AddRobot("bot#0", "function sysCall_actuation() error('boom') end");
  EXPECT_CONTAINS(ErrorOf([&] { w.Steps(1); }), "bot#0: scripts/robot.lua:1: boom");
  ASSERT_EQ(w.log.size(), 2u);
  EXPECT_CONTAINS(w.log[1], "[main] false\t");
  EXPECT_CONTAINS(w.log[1], "stopped by an error");
  EXPECT_EQ(w.world().step_count(), 0);
}

// --- Messages ------------------------------------------------------------------------------

// A robot that sends what `send` says in step 0 and prints everything it receives.
std::string Receiver(const std::string& send) {
  return R"(
    function sysCall_actuation()
      if sim.getSimulationTime() == 0 then )" +
         send + R"( end
      while true do
        local data, sender, distance, bearing = sim.receiveMessage()
        if not data then break end
        print(data, sim.getObjectName(sim.getObjectParent(sender)),
              distance and string.format('%.2f %.2f', distance, bearing) or '-')
      end
    end
  )";
}

TEST(ScriptControlTest, MessageScopesReachExactlyTheirReceiversAtTheNextStep) {
  ScriptWorld w;
  const ObjectId a = w.AddRobot("a", Receiver("sim.sendGlobalMessage('g')"), 0, 0);
  // b's body script sends local + direct; its eye script receives.
  const ObjectId b = w.AddRobot("b", Receiver(R"(
      sim.sendLocalMessage('l')
      sim.sendDirectMessage(sim.getObject('/a/body'), 'd'))"),
                                1, 0, M_PI / 2);
  const ObjectId eye = w.scene().AddDummy("eye", b, {});
  w.scene().AttachScript(eye, Source("scripts/eye.lua", Receiver("")));
  w.AddRobot("c", Receiver("sim.sendRangeMessage('r', 1.5)"), 0, 1);
  (void)a;
  w.Steps(1);
  EXPECT_TRUE(w.log.empty());  // nothing delivered in the step it was sent
  w.Steps(1);
  // Sender-handle order (a's body, b's body, c's body); b faces +y, so a
  // (at -x from b) is at bearing +pi/2 in b's frame.
  const std::vector<std::string> expected = {
      "[a] d\tb\t1.00 0.00", "[a] r\tc\t1.00 1.57", "[b] g\ta\t1.00 1.57", "[b] r\tc\t1.41 0.79",
      "[b] g\ta\t1.00 1.57", "[b] l\tb\t0.00 0.00", "[b] r\tc\t1.41 0.79", "[c] g\ta\t1.00 -1.57"};
  EXPECT_EQ(w.log, expected);
  // Sent once, delivered once: the following steps, with no messages at all,
  // deliver nothing (the inboxes of the last round are emptied).
  w.log.clear();
  w.Steps(2);
  EXPECT_TRUE(w.log.empty()) << w.log.front();
}

TEST(ScriptControlTest, RangeMessagesHonourRangeAndLineOfSight) {
  // A module that provides the world's line of sight (framework/line_of_sight.h,
  // as the proximity module does) in which the segment crossing x = 0.5 is blocked.
  class Wall final : public Module, public LineOfSight {
   public:
    void Start(World* world) override { world->set_line_of_sight(this); }
    bool SegmentBlocked(const Vec3& a, const Vec3& b) const override {
      return (a.x - 0.5) * (b.x - 0.5) < 0;
    }
  };
  ModuleRegistry walled;
  walled.RegisterDynamics({"", "null", "1", ""},
                          [] { return std::make_unique<testing::NullDynamics>(); });
  walled.RegisterModule(
      {{"sensor", "wall", "1", ""},
       PhaseBit(ModulePhase::kSense),
       100,
       /*every_world=*/true,
       [](World*, const void*) -> std::unique_ptr<Module> { return std::make_unique<Wall>(); }});
  ScriptWorld w(1, {}, std::move(walled));
  w.AddRobot("s", Receiver("sim.sendRangeMessage('open', 2); sim.sendRangeMessage('los', 2, true)"),
             0, 0);
  w.AddRobot("near", Receiver(""), 0, 1.9);
  w.AddRobot("behind", Receiver(""), 1, 0);
  w.AddRobot("far", Receiver(""), 0, -2.1);
  w.Steps(2);
  const std::vector<std::string> expected = {
      "[near] open\ts\t1.90 -1.57", "[near] los\ts\t1.90 -1.57", "[behind] open\ts\t1.00 3.14"};
  EXPECT_EQ(w.log, expected);
}

// Distance and bearing arrive in full double precision: a receiver 1.9 m
// along +y from the sender (both facing +x) gets exactly 1.9 and -pi/2.
TEST(ScriptControlTest, RangeMessageDistanceAndBearingAreExact) {
  ScriptWorld w;
  w.AddRobot("s", "function sysCall_actuation() sim.sendRangeMessage('x', 2) end", 0, 0);
  w.AddRobot("r", R"(
    function sysCall_actuation()
      local data, sender, distance, bearing = sim.receiveMessage()
      if data then print(distance == 1.9, bearing == -math.pi / 2, distance) end
    end)",
             0, 1.9);
  w.Steps(2);
  EXPECT_EQ(w.log, std::vector<std::string>{"[r] true\ttrue\t1.9"});
}

TEST(ScriptControlTest, RangeMessagingIsTheSameAtAnyThreadCount) {
  auto run = [](int threads) {
    ScriptWorld w(threads);
    for (int r = 0; r < 300; ++r)
      w.AddRobot("bot#" + std::to_string(r), R"(
        function sysCall_actuation()
          local sum = 0
          while true do
            local data, sender, d, b = sim.receiveMessage()
            if not data then break end
            sum = sum * 1.0001 + sim.unpackFloats(data)[1] + d + b
          end
          sim.recordMetric('sum', sum)
          sim.sendRangeMessage(sim.packFloats({sim.random()}), 0.5)
        end
      )",
                 (r % 20) * 0.3, (r / 20) * 0.3);
    w.Steps(3);
    std::vector<double> v;
    for (const MetricSample& m : w.world().TakeMetrics()) v.push_back(m.value);
    return v;
  };
  const std::vector<double> one = run(1);
  EXPECT_EQ(one, run(2));
  EXPECT_EQ(one, run(4));
}

// --- Signals and packing -------------------------------------------------------------------

TEST(ScriptControlTest, SignalsAreVisibleFromTheNextStepAndTheLastRobotWins) {
  ScriptWorld w(2);
  for (int r = 0; r < 40; ++r)
    w.AddRobot("bot#" + std::to_string(r), R"(
      function sysCall_actuation()
        if sim.getRobotIndex() == 0 then print(sim.getSignal('who'), sim.getSignal('flag')) end
        sim.setSignal('who', sim.getRobotIndex())
        if sim.getSimulationTime() > 0.05 then sim.clearSignal('flag') else sim.setSignal('flag', true) end
      end
    )",
               r);
  w.Steps(3);
  EXPECT_EQ(w.log,
            (std::vector<std::string>{"[bot#0] nil\tnil", "[bot#0] 39\ttrue", "[bot#0] 39\tnil"}));
}

TEST(ScriptControlTest, PackAndUnpackRoundTrip) {
  ScriptWorld w;
  w.AddRobot("bot#0", R"(
    local f = sim.unpackFloats(sim.packFloats({1.5, -2}))
    local d = sim.unpackDoubles(sim.packDoubles({0.1}))
    local i = sim.unpackInt32s(sim.packInt32s({-7, 2147483647}))
    local t = sim.unpackTable(sim.packTable({1, 'two', x = {y = true}, [3] = 0.25}))
    print(#sim.packFloats({1, 2, 3}), f[1], f[2], d[1], i[1], i[2], t[1], t[2], t.x.y, t[3])
    print(pcall(sim.unpackTable, 'garbage'))
  )");
  w.world().Start();
  ASSERT_EQ(w.log.size(), 2u);
  EXPECT_EQ(w.log[0], "[bot#0] 12\t1.5\t-2.0\t0.1\t-7\t2147483647\t1\ttwo\ttrue\t0.25");
  EXPECT_CONTAINS(w.log[1], "not a packed table");
}

// Nested tables take Lua stack space per level: packing one used to write
// past the stack and corrupt the heap. Deep tables and cycles are Lua errors
// naming sim.packTable, which pcall catches; 32 levels still pack.
TEST(ScriptControlTest, PackTableOfDeepOrCyclicTablesIsACleanError) {
  ScriptWorld w;
  w.AddRobot("bot#0", R"(
    local function chain(n)
      local root = {}
      local t = root
      for i = 2, n do t.k = {i = i}; t = t.k end
      return root
    end
    function sysCall_actuation()
      local d = chain(21)
      for i = 1, 50 do sim.sendGlobalMessage(sim.packTable(d)) end
      for i = 1, 50 do
        local ok, e = pcall(sim.packTable, chain(33 + i))
        assert(not ok and e:find('nested more than 32 levels'), e)
      end
      local cycle = {}
      cycle.self = {up = cycle}
      local ok, e = pcall(sim.packTable, cycle)
      print(ok, e)
      local t = sim.unpackTable(sim.packTable(chain(32)))
      local depth = 1
      while t.k do t = t.k; depth = depth + 1 end
      print(depth, t.i)
      -- A table as a key takes its stack slots too.
      local keyed = {}
      local t = keyed
      for i = 1, 31 do local k = {}; t[k] = true; t = k end
      print(#sim.packTable(keyed) > 0, pcall(sim.packTable, {[chain(32)] = 1}))
    end
  )");
  w.Steps(2);
  ASSERT_EQ(w.log.size(), 6u);
  EXPECT_CONTAINS(
      w.log[0],
      "[bot#0] false\tsim.packTable: the table is nested more than 32 levels deep (or has "
      "a cycle)");
  EXPECT_EQ(w.log[1], "[bot#0] 32\t32");
  EXPECT_CONTAINS(
      w.log[2], "[bot#0] true\tfalse\tsim.packTable: the table is nested more than 32 levels deep");
}

// A packed string nested deeper than packTable makes is refused, not unpacked.
TEST(ScriptControlTest, UnpackTableRefusesStringsNestedTooDeeply) {
  ScriptWorld w;
  w.AddRobot("bot#0", R"(
    local function nested(n)  -- n tables, each {[1] = <the next>}
      local s = string.pack('<c1I4', 't', 0)
      for i = 2, n do s = string.pack('<c1I4c1i8', 't', 1, 'i', 1) .. s end
      return s
    end
    local t = sim.unpackTable(nested(32))
    local depth = 1
    while t[1] do t = t[1]; depth = depth + 1 end
    print(depth, pcall(sim.unpackTable, nested(33)))
    print(pcall(sim.unpackTable, nested(1000)))
  )");
  w.world().Start();
  ASSERT_EQ(w.log.size(), 2u);
  EXPECT_CONTAINS(w.log[0],
                  "[bot#0] 32\tfalse\tsim.unpackTable: the packed table is nested more than 32 "
                  "levels deep");
  EXPECT_CONTAINS(w.log[1], "nested more than 32 levels deep");
}

TEST(ScriptControlTest, StringSignalsKeepEveryByte) {
  ScriptWorld w;
  w.AddRobot("bot#0", R"(
    function sysCall_actuation()
      local v = sim.getSignal('blob')
      if v then print(#v, v == 'a\0b\0' .. sim.packInt32s({7})) end
      sim.setSignal('blob', 'a\0b\0' .. sim.packInt32s({7}))
    end
  )");
  w.Steps(2);
  EXPECT_EQ(w.log, (std::vector<std::string>{"[bot#0] 8\ttrue"}));
}

// A message is charged to its sender's memory account, with its Lua memory
// (simulation.script_memory_mb), from the step it is sent until the next
// step's messages are delivered: 20 robots sending 100 MiB each per step
// used to exhaust the host's memory. Here the robot holds ~1 MiB of Lua
// memory: two 1 MiB messages fit its 4 MiB in a step; the next step, while
// they are delivered, none does; the step after, two again.
TEST(ScriptControlTest, MessagesAreChargedToTheSendersMemoryUntilDelivered) {
  WorldSettings settings;
  settings.script_memory_limit = 4 << 20;
  ScriptWorld w(1, settings);
  w.AddRobot("bot#0", R"(
    function sysCall_actuation()
      local n = 0
      while sim.receiveMessage() do n = n + 1 end
      local m = string.rep('x', 1 << 20)
      local sent, ok, e = 0, true, nil
      while ok and sent < 10 do
        ok, e = pcall(sim.sendRangeMessage, m, 5)
        if ok then sent = sent + 1 end
      end
      print(n, sent, e)
      ok, e = pcall(sim.sendGlobalMessage, m)  -- the same count for every scope
      print(ok, e)
    end
  )");
  w.AddRobot("bot#1", "", 1, 0);
  const ObjectId listener = w.scene().FindObject("/bot#1/body");
  w.scene().AttachScript(listener, Source("scripts/listener.lua", R"(
    function sysCall_actuation()
      local n = 0
      while sim.receiveMessage() do n = n + 1 end
      if n > 0 then print('received', n) end
    end
  )"));
  w.Steps(3);
  const std::string limit =
      "the message would take the scripts past 4 MiB (1 MiB of Lua memory and 2 MiB of data the "
      "sim.* calls keep for them: signals, custom data, messages, prints, metrics; "
      "simulation.script_memory_mb; raise it if the data is real)";
  ASSERT_EQ(w.log.size(), 7u);
  EXPECT_EQ(w.log[0], "[bot#0] 0\t2\tsim.sendRangeMessage: " + limit);
  EXPECT_EQ(w.log[1], "[bot#0] false\tsim.sendGlobalMessage: " + limit);
  EXPECT_EQ(w.log[2], "[bot#0] 0\t0\tsim.sendRangeMessage: " + limit);
  EXPECT_EQ(w.log[4], "[bot#1] received\t2");
  EXPECT_EQ(w.log[5], "[bot#0] 0\t2\tsim.sendRangeMessage: " + limit);
  // 0: no limit.
  settings.script_memory_limit = 0;
  ScriptWorld u(1, settings);
  u.AddRobot("bot#0", R"(
    function sysCall_actuation()
      local m = string.rep('x', 1 << 20)
      for i = 1, 20 do sim.sendGlobalMessage(m) end
    end
  )");
  EXPECT_EQ(ErrorOf([&] { u.Steps(2); }), "");
}

TEST(ScriptControlTest, CustomDataIsSeenNextStepAndCopiedWithTheModel) {
  ScriptWorld w(2);
  // Robot 0 writes a block on its own body and on robot 1's; robot 1 reads both.
  const ObjectId body0 = w.AddRobot("bot#0", R"(
    function sysCall_actuation()
      local t = sim.getSimulationTime()
      sim.writeCustomDataBlock(sim.getObject('.'), 'mood', t < 0.05 and 'calm' or nil)
      sim.writeCustomDataBlock(sim.getObject('/bot#1/body'), 'note', sim.packFloats({t}))
    end
  )");
  w.AddRobot("bot#1", R"(
    function sysCall_actuation()
      local note = sim.readCustomDataBlock(sim.getObject('.'), 'note')
      print(sim.readCustomDataBlock(sim.getObject('/bot#0/body'), 'mood'),
            note and sim.unpackFloats(note)[1])
    end
  )",
             1);
  w.Steps(3);
  EXPECT_EQ(w.log, (std::vector<std::string>{"[bot#1] nil	nil", "[bot#1] calm	0.0",
                                             "[bot#1] nil	0.10000000149012"}));
  // A copy of the model carries the block with it; the original keeps its own.
  w.scene().WriteCustomData(body0, "serial", "A-17");
  const ObjectId root0 = w.scene().parent(body0);
  const ObjectId copy = w.scene().DuplicateSubtree(root0, {});
  const ObjectId copy_body = w.scene().FindObject("./body", copy);
  ASSERT_NE(w.scene().ReadCustomData(copy_body, "serial"), nullptr);
  EXPECT_EQ(*w.scene().ReadCustomData(copy_body, "serial"), "A-17");
  w.scene().WriteCustomData(copy_body, "serial", "");
  EXPECT_EQ(w.scene().ReadCustomData(copy_body, "serial"), nullptr);
  EXPECT_EQ(*w.scene().ReadCustomData(body0, "serial"), "A-17");
}

TEST(ScriptControlTest, StateHashCoversWhatScriptsLeaveForTheNextStep) {
  // Identical worlds except for what a script leaves pending at the end of a
  // step: a signal, an undelivered message, a custom data block. Each changes
  // the future, so each must change the hash.
  auto hash_after = [](const std::string& action) {
    ScriptWorld w;
    w.AddRobot("bot#0", "function sysCall_actuation() " + action + " end");
    w.Steps(2);
    return w.world().StateHash();
  };
  const uint64_t nothing = hash_after("");
  EXPECT_EQ(hash_after(""), nothing);
  EXPECT_NE(hash_after("sim.setSignal('s', 1)"), nothing);
  EXPECT_NE(hash_after("sim.sendGlobalMessage('hi')"), nothing);
  EXPECT_NE(hash_after("sim.writeCustomDataBlock(sim.getObject('.'), 't', 'x')"), nothing);
}

// --- Rough edges (QA) ----------------------------------------------------------------------

// A main script passing `extra` (Lua expressions) to every child callback of a
// pass, then stepping the rest of the phases.
WorldSettings MainPassing(const std::string& pass, const std::string& extra) {
  WorldSettings settings;
  settings.main_script = Source("main.lua", R"(
    function sysCall_step()
      local t = {}
      for i = 1, )" + extra + R"( do t[i] = i end
      sim.handleSensing()
      sim.handleChildScripts(')" + pass + R"(', table.unpack(t))
      sim.handleActuation()
      sim.handleDynamics()
    end
  )");
  return settings;
}

TEST(ScriptControlTest, HandleChildScriptsPassesManyArgumentsToEveryRobot) {
  // 45 arguments overflowed each robot's Lua stack (a segfault); 5,000 need it grown.
  for (const std::string count : {"45", "5000"}) {
    ScriptWorld w(2, MainPassing("actuation", count));
    for (int r = 0; r < 2; ++r)
      w.AddRobot("bot#" + std::to_string(r), R"(
        function sysCall_actuation(...) print(select('#', ...), (select(select('#', ...), ...))) end
        function sysCall_thread() while true do sim.step() end end
      )",
                 r);
    w.AddRobot("bot#2", "", 2);
    w.Steps(2);
    const std::vector<std::string> expected = {
        "[bot#0] " + count + "\t" + count, "[bot#1] " + count + "\t" + count,
        "[bot#0] " + count + "\t" + count, "[bot#1] " + count + "\t" + count};
    EXPECT_EQ(w.log, expected);
  }
}

TEST(ScriptControlTest, HandleChildScriptPassesAndReturnsManyValues) {
  ScriptWorld w;
  const ObjectId body = w.AddRobot("bot#0", R"(
    function sysCall_actuation()
      local t = {}
      for i = 1, 5000 do t[i] = i end
      local arm = sim.getObject('./arm')
      print(select('#', sim.handleChildScript(arm, table.unpack(t))))
      print(select('#', sim.handleChildScript(arm)))
    end
  )");
  const ObjectId arm = w.scene().AddDummy("arm", body, {});
  w.scene().AttachScript(arm, Source("scripts/arm.lua", R"(
    function sysCall_actuation(...)
      if select('#', ...) > 0 then return ... end
      local t = {}
      for i = 1, 10000 do t[i] = i end
      return table.unpack(t)
    end
  )"),
                         /*explicit_handling=*/true);
  w.Steps(1);
  EXPECT_EQ(w.log, (std::vector<std::string>{"[bot#0] 5000", "[bot#0] 10000"}));
}

TEST(ScriptControlTest, ThreadSwitchTimingMustBeFiniteAndPositive) {
  for (const std::string ms : {"1/0", "-1/0", "0/0", "-1", "0", "'x'"}) {
    ScriptWorld w;
    w.AddRobot("bot#0", "function sysCall_thread()\n  sim.setThreadSwitchTiming(" + ms +
                            ")\n  while true do end\nend\n");
    const std::string error = ErrorOf([&] { w.Steps(1); });
    EXPECT_CONTAINS(error, "bot#0: scripts/robot.lua:2: sim.setThreadSwitchTiming: ") << ms;
  }
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

TEST(ScriptControlTest, WaitAndWaitUntilRejectNaNInfiniteAndNegativeTimes) {
  for (const std::string call :
       {"sim.wait(0/0)", "sim.wait(1/0)", "sim.wait(-1)", "sim.waitUntil(f, 0/0)",
        "sim.waitUntil(f, 1/0)", "sim.waitUntil(f, -0.5)", "sim.waitUntil(f, 'x')"}) {
    ScriptWorld w;
    w.AddRobot("bot#0", "local function f() return false end\nfunction sysCall_thread()\n  " +
                            call + "\n  print('went on')\nend\n");
    const std::string error = ErrorOf([&] { w.Steps(3); });
    const std::string name = call.substr(0, call.find('('));
    EXPECT_CONTAINS(error, "bot#0: scripts/robot.lua:3: " + name + ": ") << call;
    EXPECT_TRUE(w.log.empty()) << call << ": " << w.log.front();
  }
  ScriptWorld w;  // zero and nil stay fine
  w.AddRobot("bot#0", R"(
    function sysCall_thread()
      sim.wait(0)
      print(sim.waitUntil(function() return true end, 0), sim.waitUntil(function() return true end))
    end
  )");
  w.Steps(1);
  EXPECT_EQ(w.log, (std::vector<std::string>{"[bot#0] true\ttrue"}));
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

TEST(ScriptControlTest, UnknownSysCallNamesAreWarnedOncePerScriptFile) {
  ScriptWorld w(2);
  for (int r = 0; r < 1000; ++r)
    w.AddRobot("bot#" + std::to_string(r), R"(
      function sysCall_actuate() end
      function sysCall_beforeSimulation() end
      function sysCall_step() end
      sysCall_frobnicate = 3
      function sysCall_actuation() end
    )",
               r);
  w.world().Start();
  w.Steps(1);
  const std::vector<std::string> expected = {
      "warning: scripts/robot.lua:2: defines sysCall_actuate, which swarmsim never calls (did you "
      "mean sysCall_actuation?)",
      "warning: scripts/robot.lua:3: defines sysCall_beforeSimulation, which swarmsim never calls "
      "(it is CoppeliaSim's; put its code in sysCall_init)",
      "warning: scripts/robot.lua:4: defines sysCall_step, which swarmsim never calls (only the "
      "world's main script, simulation.main_script, has a sysCall_step)",
      "warning: scripts/robot.lua defines sysCall_frobnicate, which swarmsim never calls "
      "(it calls sysCall_init, sysCall_sensing, sysCall_actuation, sysCall_cleanup and "
      "sysCall_thread)"};
  EXPECT_EQ(w.log, expected);
}

TEST(ScriptControlTest, UnknownSysCallNamesOfOneFileAreWarnedInLineOrder) {
  ScriptWorld w;
  w.AddRobot("bot#0",
             "function sysCall_beforeSimulation() end\n"
             "function sysCall_Init() end\n"
             "function sysCall_b() end function sysCall_a() end\n"
             "sysCall_zzz = 1\n");
  w.world().Start();
  ASSERT_EQ(w.log.size(), 5u);
  EXPECT_CONTAINS(w.log[0], "robot.lua:1: defines sysCall_beforeSimulation,");
  EXPECT_CONTAINS(w.log[1], "robot.lua:2: defines sysCall_Init,");
  EXPECT_CONTAINS(w.log[2], "robot.lua:3: defines sysCall_a,");  // same line: by name
  EXPECT_CONTAINS(w.log[3], "robot.lua:3: defines sysCall_b,");
  EXPECT_CONTAINS(w.log[4], "robot.lua defines sysCall_zzz,");  // no line: last
}

TEST(ScriptControlTest, ThreadsResumeAtMostOncePerStep) {
  for (const std::string passes : {"'actuation', 'actuation'", "'all', 'actuation'"}) {
    WorldSettings settings;
    settings.main_script = Source("main.lua", R"(
      function sysCall_step()
        sim.handleSensing()
        for _, pass in ipairs({)" + passes + R"(}) do sim.handleChildScripts(pass) end
        sim.handleActuation()
        sim.handleDynamics()
      end
    )");
    ScriptWorld w(1, settings);
    w.AddRobot("bot#0", R"(
      function sysCall_actuation() print('actuation', sim.getSimulationTime()) end
      function sysCall_thread()
        while true do print('thread', sim.getSimulationTime()) sim.step() end
      end
    )");
    w.Steps(2);
    const std::vector<std::string> expected = {"[bot#0] actuation\t0.0", "[bot#0] thread\t0.0",
                                               "[bot#0] actuation\t0.0", "[bot#0] actuation\t0.1",
                                               "[bot#0] thread\t0.1",    "[bot#0] actuation\t0.1"};
    EXPECT_EQ(w.log, expected) << passes;
  }
}

TEST(ScriptControlTest, MainScriptPhaseMistakesNameTheMainScript) {
  WorldSettings twice;
  twice.main_script = Source("main.lua",
                             "function sysCall_step()\n  sim.handleDynamics()\n"
                             "  sim.handleDynamics()\nend\n");
  ScriptWorld w(1, twice);
  EXPECT_CONTAINS(ErrorOf([&] { w.Steps(1); }),
                  "main: main.lua:3: sim.handleDynamics: may run only once per step");
  WorldSettings never;
  never.main_script = Source("main.lua", "function sysCall_step() sim.handleSensing() end");
  ScriptWorld v(1, never);
  EXPECT_CONTAINS(ErrorOf([&] { v.Steps(1); }),
                  "main: main.lua: sysCall_step must call sim.handleDynamics() once per step");
}

}  // namespace
}  // namespace swarmsim
