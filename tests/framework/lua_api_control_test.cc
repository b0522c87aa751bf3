// sim.* control (framework/lua_api_control.cc): explicit child scripts
// (sim.handleChildScript), threaded scripts (sim.step, sim.wait, time
// slices) and the world's main script running the phases.
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

// From a C function's callback inside the thread (table.sort's comparison):
// the thread's own, but it cannot yield there; it said "only a threaded
// script can yield", which it is.
TEST(ScriptControlTest, StepInsideACFunctionsCallbackSaysWhy) {
  ScriptWorld w;
  w.AddRobot("bot#0",
             "function sysCall_thread()\n"
             "  table.sort({3, 1, 2}, function(a, b) sim.step() return a < b end)\n"
             "end\n");
  EXPECT_CONTAINS(ErrorOf([&] { w.Steps(2); }),
                  "sim.step: not from inside a callback of a C function (table.sort's comparison");
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

// sim.wait from a coroutine of the thread: the script's line (it named the
// helpers' chunk, "sim:21").
TEST(ScriptControlTest, WaitInsideACoroutineOfTheThreadNamesTheScriptsLine) {
  ScriptWorld w;
  w.AddRobot("bot#0",
             "function sysCall_thread()\n  local co = coroutine.wrap(function()\n"
             "    sim.wait(0.5)\n  end)\n  co()\nend\n");
  const std::string error = ErrorOf([&] { w.Steps(2); });
  EXPECT_CONTAINS(error,
                  "scripts/robot.lua:3: sim.wait: call it from sysCall_thread itself, "
                  "not from a coroutine of your own");
  EXPECT_EQ(error.find("sim:"), std::string::npos) << error;
}

TEST(ScriptControlTest, WaitOutsideAThreadNamesTheCallersLine) {
  ScriptWorld w;
  w.AddRobot("bot#0", "function sysCall_actuation()\n  sim.wait(1)\nend\n");
  EXPECT_CONTAINS(ErrorOf([&] { w.Steps(1); }),
                  "bot#0: scripts/robot.lua:2: sim.wait: only a threaded script");
}

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

// A thread whose time slice runs out step after step never yields by
// itself (a loop without sim.step): it ran to the end without a word. It is
// said once, after 100 such steps; a thread that steps is not.
TEST(ScriptControlTest, AThreadThatNeverYieldsByItselfIsSaidOnce) {
  ScriptWorld w;
  w.AddRobot("bot#0",
             "function sysCall_thread()\n  sim.setThreadSwitchTiming(0.01)\n"
             "  while true do end\nend\n");
  w.AddRobot("bot#1", "function sysCall_thread()\n  while true do sim.step() end\nend\n");
  w.Steps(99);
  EXPECT_TRUE(w.log.empty()) << w.log.front();
  w.Steps(150);
  ASSERT_EQ(w.log.size(), 1u);
  EXPECT_EQ(w.log[0],
            "[bot#0] warning: scripts/robot.lua: sysCall_thread has not yielded by itself in 100 "
            "steps (its time slice ran out in each): a loop without sim.step() or sim.wait()? It "
            "goes on, using its slice every step");
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
    if (call.find("0/0") != std::string::npos) {
      EXPECT_CONTAINS(error, "(got nan)") << "not -nan";
    }
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
  // A phase outside sysCall_step stepped the world outside the run's count
  // (a 2-step run simulated 0.3 s).
  for (const char* phase : {"sim.handleDynamics()", "sim.handleSensing()",
                            "sim.handleChildScripts()", "sim.handleActuation()"}) {
    WorldSettings init;
    init.main_script = Source("main.lua", std::string("function sysCall_init()\n  ") + phase +
                                              "\nend\nfunction sysCall_step() "
                                              "sim.handleDynamics() end\n");
    ScriptWorld u(1, init);
    EXPECT_CONTAINS(ErrorOf([&] { u.Steps(1); }),
                    "main.lua:2: " + std::string(phase).substr(0, std::string(phase).find('(')) +
                        ": the phases run in the main script's sysCall_step only");
  }
}

}  // namespace
}  // namespace swarmsim
