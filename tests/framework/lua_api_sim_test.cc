// sim.* simulation (framework/lua_api_sim.cc): print, metrics, per-robot
// random streams and parameters (robot, then world, then default).
#include <gtest/gtest.h>

#include <memory>
#include <string>
#include <vector>

#include "framework/error.h"
#include "framework/world.h"
#include "tests/framework/error_of.h"
#include "tests/framework/fakes.h"
#include "tests/framework/script_world.h"

namespace swarmsim {
namespace {

using script_test::ScriptWorld;
using script_test::Source;

using testing::ErrorOf;

TEST(ScriptHostTest, PrintWritesOnePrefixedTabSeparatedLine) {
  ScriptWorld w;
  w.AddWheeledRobot(
      "bot#0",
      R"(print('a', 1, 2.5, nil, true, setmetatable({}, {__tostring = function() return 'obj' end})))");
  w.world().Start();
  EXPECT_EQ(w.log, std::vector<std::string>{"[bot#0] a\t1\t2.5\tnil\ttrue\tobj"});
}

// A printed text's lines each get the robot's prefix (a "\n[bot#7] ..." read
// as another robot's line, a "\nerror: ..." as the run's), and the controls
// a terminal acts on are escaped (ESC recoloured or cleared the console, CR
// overwrote the line); tabs and UTF-8 stay. Script errors are escaped alike.
TEST(ScriptHostTest, PrintedLinesCannotPassForAnotherRobotsOrDriveTheTerminal) {
  ScriptWorld w;
  w.AddWheeledRobot("bot#0",
                    "print('a\\n[bot#7] forged\\nerror: forged', '\\27[2J\\r\\0x\\127\\194\\155', "
                    "'\\tcaf\\195\\169')");
  w.world().Start();
  EXPECT_EQ(w.log, std::vector<std::string>{"[bot#0] a\n[bot#0] [bot#7] forged\n[bot#0] error: "
                                            "forged\t\\x1b[2J\\r\\0x\\x7f\\u009b\t\tcaf\xc3\xa9"});
  ScriptWorld e;
  e.AddWheeledRobot("bot#0", "function sysCall_actuation() error('\\27]0;title\\7 x') end");
  e.world().Start();
  const std::string error = ErrorOf([&] { e.world().Step(); });
  EXPECT_NE(error.find("\\x1b]0;title\\x07 x"), std::string::npos) << error;
  EXPECT_EQ(error.find('\x1b'), std::string::npos) << error;
  // The step's print cap counts the text as written: 200,000 newlines are
  // 1.8 MB with their prefixes, past the 1 MiB a robot may print a step.
  ScriptWorld many;
  many.AddWheeledRobot("bot#0",
                       "function sysCall_actuation() print(string.rep('\\n', 200000)) end");
  many.world().Start();
  EXPECT_NE(ErrorOf([&] { many.world().Step(); }).find("printed more than 1 MiB in this step"),
            std::string::npos);
}

TEST(ScriptHostTest, RecordedMetricsReachTheWorld) {
  ScriptWorld w;
  w.AddWheeledRobot("bot#0", "function sysCall_actuation() sim.recordMetric('speed', 1.5) end");
  w.AddWheeledRobot("bot#1", "function sysCall_actuation() sim.recordMetric('speed', 2.5) end");
  w.world().Start();
  w.world().Step();
  w.world().Step();
  const std::vector<MetricSample> metrics = w.world().TakeMetrics();
  ASSERT_EQ(metrics.size(), 4u);
  EXPECT_EQ(metrics[0].step, 0);
  EXPECT_EQ(metrics[0].instance, 0);
  EXPECT_EQ(metrics[0].name, "speed");
  EXPECT_EQ(metrics[0].value, 1.5);
  EXPECT_EQ(metrics[1].instance, 1);
  EXPECT_EQ(metrics[1].value, 2.5);
  EXPECT_EQ(metrics[3].step, 1);
  EXPECT_DOUBLE_EQ(metrics[3].time, 0.1);
  EXPECT_EQ(metrics[3].instance, 1);
}

TEST(ScriptHostTest, RandomNumbersArePerRobotAndReproducible) {
  auto run = [](uint64_t seed) {
    ScriptWorld w(2, seed);
    for (int r = 0; r < 3; ++r)
      w.AddWheeledRobot("bot#" + std::to_string(r), R"(
        function sysCall_actuation()
          sim.recordMetric('sim', sim.random())
          sim.recordMetric('lua', math.random())
        end
      )");
    w.world().Start();
    w.world().Step();
    w.world().Step();
    std::vector<double> values;
    for (const MetricSample& m : w.world().TakeMetrics()) values.push_back(m.value);
    return values;
  };
  const std::vector<double> a = run(7), b = run(7), c = run(8);
  ASSERT_EQ(a.size(), 12u);
  EXPECT_EQ(a, b);
  EXPECT_NE(a, c);
  // Robots draw different numbers (step 0: robot 0, 1, 2; sim then lua).
  EXPECT_NE(a[0], a[2]);
  EXPECT_NE(a[2], a[4]);
  EXPECT_NE(a[1], a[3]);
  for (double v : a) {
    EXPECT_GE(v, 0.0);
    EXPECT_LT(v, 1.0);
  }
}

TEST(ScriptHostTest, ParametersComeFromTheRobotThenTheWorldThenTheDefault) {
  ScriptWorld w;
  const std::string code = R"(
    function sysCall_init()
      print(sim.getParam('speed'), sim.getParam('name'), sim.getParam('fast'),
            sim.getParam('missing', 3), sim.getParam('missing', nil))
    end
  )";
  w.AddWheeledRobot("bot#0", code);
  w.AddWheeledRobot("bot#1", code);
  w.world().parameters()["speed"] = 0.5;
  w.world().parameters()["name"] = std::string("world");
  w.world().parameters()["fast"] = false;
  auto own = std::make_shared<ParameterSet>();
  (*own)["speed"] = 2.0;
  (*own)["fast"] = true;
  w.world().SetInstanceParameters(1, own);
  w.world().Start();
  const std::vector<std::string> expected = {"[bot#0] 0.5\tworld\tfalse\t3\tnil",
                                             "[bot#1] 2\tworld\ttrue\t3\tnil"};
  EXPECT_EQ(w.log, expected);
}

// Integral numbers (parameters, signals, sim.handleChildScripts arguments)
// reach scripts as Lua integers, so '/st#' .. (i % robots) reads '/st#3'.
TEST(ScriptHostTest, IntegralParametersAndSignalsAreLuaIntegers) {
  ScriptWorld w;
  w.AddWheeledRobot("bot#0", R"(
    function sysCall_init()
      local robots = sim.getParam('robots')
      print('/st#' .. (13 % robots), math.type(robots), math.type(sim.getParam('speed')),
            math.type(sim.getParam('exact')), math.type(sim.getParam('inexact')),
            math.type(sim.getParam('negative')), sim.getParam('negative'))
    end
    function sysCall_actuation()
      if sim.getSimulationTime() == 0 then
        sim.setSignal('count', 4.0)
        sim.setSignal('half', 0.5)
      else
        print('/st#' .. sim.getSignal('count'), sim.getSignal('half'))
      end
    end
  )");
  w.world().parameters()["robots"] = 10.0;
  w.world().parameters()["speed"] = 0.5;
  w.world().parameters()["exact"] = 9007199254740992.0;     // 2^53
  w.world().parameters()["inexact"] = 18014398509481984.0;  // 2^54: a float
  w.world().parameters()["negative"] = -3.0;
  w.world().Start();
  w.world().Step();
  w.world().Step();
  const std::vector<std::string> expected = {
      "[bot#0] /st#3\tinteger\tfloat\tinteger\tfloat\tinteger\t-3", "[bot#0] /st#4\t0.5"};
  EXPECT_EQ(w.log, expected);
}

}  // namespace
}  // namespace swarmsim
