// The scripts' side of modules/graphs (lua_api_graphs.cc):
// sim.setGraphStreamValue, sim.addGraphStream, sim.getGraphStreamValues,
// who may set what, and their errors.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "modules/graphs/module.h"
#include "modules/graphs/rows.h"
#include "tests/modules/module_world.h"

namespace swarmsim::graphs {
namespace {

using testing::ModuleWorld;

constexpr double kStep = 0.125;

// A robot "bot" with a graph "g" of a script stream "speed" and its root's
// x; a scene graph "scene_g" of a script stream "count"; `code` runs on
// the robot.
struct GraphScripts {
  ModuleWorld w{"kinematic", 1, kStep};
  ObjectId bot, graph, scene_graph;
  explicit GraphScripts(const std::string& code) {
    bot = w.Robot("bot", {{2, 0, 0}, {}});
    GraphRow row;
    ParseStream("script speed", &row.streams);
    ParseStream("position : x", &row.streams);
    graph = w.Add("graph", "g", bot, {}, &row);
    GraphRow scene_row;
    ParseStream("script count", &scene_row.streams);
    scene_graph = w.Add("graph", "scene_g", {}, {}, &scene_row);
    w.Script(bot, code);
  }
  std::string Log() const {
    std::string all;
    for (const std::string& line : w.log()) all += line + "\n";
    return all;
  }
  const Series& SeriesOf(ObjectId id) {
    return *dynamic_cast<const GraphModule*>(w.world().find_module(kModuleName))->Find(id);
  }
};

TEST(LuaApiGraphsTest, AScriptsValueIsRecordedAtTheNextSampleOnly) {
  GraphScripts s(R"(
    local step = 0
    function sysCall_actuation()
      step = step + 1
      local g = sim.getObject('./g')
      if step == 1 then sim.setGraphStreamValue(g, 'speed', 0.5) end
      if step == 3 then sim.setGraphStreamValue(g, sim.addGraphStream(g, 'speed'), 2.5) end
    end
  )");
  ASSERT_EQ(s.w.Run(3), "");
  const Series& series = s.SeriesOf(s.graph);
  ASSERT_EQ(series.count, 4u);
  EXPECT_TRUE(std::isnan(series.sample(0)[1]));
  EXPECT_DOUBLE_EQ(series.sample(1)[1], 0.5);
  EXPECT_TRUE(std::isnan(series.sample(2)[1]));  // not set again: nan
  EXPECT_DOUBLE_EQ(series.sample(3)[1], 2.5);
}

TEST(LuaApiGraphsTest, ScriptsReadTheSamplesOfAnyStream) {
  GraphScripts s(R"(
    function sysCall_sensing()
      local g = sim.getObject('./g')
      local times, xs = sim.getGraphStreamValues(g, 'position : x')
      local last_times, last = sim.getGraphStreamValues(g, 2, 1)
      print(string.format('n=%d last t=%g x=%g count1=%d', #times, times[#times], xs[#xs],
                          #last_times))
    end
  )");
  ASSERT_EQ(s.w.Run(3), "");
  // In step 3's sense phase: the samples of the start, steps 1 and 2.
  EXPECT_CONTAINS(s.Log(), "n=3 last t=0.25 x=2 count1=1");
}

std::string ErrorOfLine(const std::string& line) {
  GraphScripts s("function sysCall_init()\n" + line + "\nend\n");
  return s.w.Run(1);
}

TEST(LuaApiGraphsTest, MistakesAreErrorsNamingTheGraphAndItsStreams) {
  EXPECT_CONTAINS(ErrorOfLine("sim.setGraphStreamValue(sim.getObject('/bot'), 'speed', 1)"),
                  "object /bot is not a graph");
  EXPECT_CONTAINS(ErrorOfLine("sim.setGraphStreamValue(sim.getObject('./g'), 'sped', 1)"),
                  "graph /bot/g has no stream 'sped'; its script streams: 'speed'");
  EXPECT_CONTAINS(ErrorOfLine("sim.setGraphStreamValue(sim.getObject('./g'), 'position : x', 1)"),
                  "stream 'position : x' of graph /bot/g is not a script stream");
  EXPECT_CONTAINS(ErrorOfLine("sim.setGraphStreamValue(sim.getObject('./g'), 2, 1)"),
                  "graph /bot/g has no script stream with id 2 (it has 2 streams)");
  EXPECT_CONTAINS(ErrorOfLine("sim.getGraphStreamValues(sim.getObject('./g'), 'nope')"),
                  "its streams: 'speed', 'position : x'");
  EXPECT_CONTAINS(ErrorOfLine("sim.getGraphStreamValues(sim.getObject('./g'), 1, -1)"),
                  "bad argument #3 (a count >= 0 expected, got -1)");
  EXPECT_CONTAINS(ErrorOfLine("sim.setGraphStreamValue(sim.getObject('/scene_g'), 'count', 1)"),
                  "a robot's script may set only its own graphs' streams ('/scene_g' belongs to "
                  "another robot or to the scene)");
}

}  // namespace
}  // namespace swarmsim::graphs
