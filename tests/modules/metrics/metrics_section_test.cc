// The metrics module's world-file section `metrics:` (metrics_section.cc),
// read through the loader: each entry adds its metric module, recording
// every N steps, and its mistakes name file:line:column.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "tests/swarm/loader/world_dir_test.h"

namespace swarmsim {
namespace {

class MetricsSectionTest : public testing::WorldDirTest {
 protected:
  // The loader's message for `world_text`, or "(no error)".
  std::string ErrorOfWorld(const std::string& world_text) {
    try {
      Load(world_text);
    } catch (const Error& e) {
      return e.what();
    }
    return "(no error)";
  }
  void WriteBot() {
    Write("bot.yaml",
          "model: bot\nobjects:\n  type: shape\n  shape: box\n  size: [0.1, 0.1, 0.1]\n");
  }
};

void ExpectHas(const std::string& message, const std::vector<std::string>& fragments) {
  for (const std::string& fragment : fragments)
    EXPECT_NE(message.find(fragment), std::string::npos)
        << "expected '" << fragment << "' in: " << message;
}

TEST_F(MetricsSectionTest, MetricsEntriesAddTheirModulesEveryNSteps) {
  WriteBot();
  LoadedWorld w = Load(
      "simulation: {physics: kinematic, time_step: 0.1}\narena: {size: 2}\n"
      "models: [{model: bot.yaml, position: [-0.5, 0]}, {model: bot.yaml, position: [0.5, 0]}]\n"
      "metrics: [{name: covered_area, every: 10}, mean_nearest_neighbor_distance]\n");
  EXPECT_EQ(w.metric_names,
            (std::vector<std::string>{"covered_area", "mean_nearest_neighbor_distance"}));
  for (int i = 0; i < 20; ++i) w.world->Step();
  int area = 0, nearest = 0;
  for (const MetricSample& m : w.world->TakeMetrics()) {
    if (m.name == "covered_area") {
      EXPECT_EQ(m.step % 10, 0) << m.step;
      ++area;
    } else {
      ASSERT_EQ(m.name, "mean_nearest_neighbor_distance");
      ++nearest;
    }
  }
  EXPECT_EQ(area, 2);  // steps 10 and 20
  EXPECT_EQ(nearest, 20);
}

// A robot's metric under the name of a swarm metric the world records is a
// script error naming both: a sweep's series took the two as one metric
// and averaged the swarm's value in as one more robot.
TEST_F(MetricsSectionTest, ARobotsMetricNamedAsTheWorldsSwarmMetricIsAnError) {
  Write("bot.yaml", "model: bot\nobjects: {name: body, type: dummy, script: bot.lua}\n");
  Write("bot.lua", "function sysCall_actuation() sim.recordMetric('covered_area', 1) end\n");
  const std::string world =
      "simulation: {physics: kinematic, time_step: 0.1}\narena: {size: 2}\n"
      "models: [{model: bot.yaml, position: [0, 0]}]\n";
  LoadedWorld w = Load(world + "metrics: [covered_area]\n");
  std::string error = "(no error)";
  try {
    w.world->Step();
  } catch (const Error& e) {
    error = e.what();
  }
  ExpectHas(error, {"bot.lua:1:", "'covered_area' is a swarm metric this world records"});
  // The rule a plugin's record_metric follows too (it returns -1).
  EXPECT_TRUE(w.world->IsListedSwarmMetric("covered_area"));
  EXPECT_FALSE(w.world->IsListedSwarmMetric("mean_nearest_neighbor_distance")) << "not listed";
  // A world that does not list it: the robot's metric is its own.
  LoadedWorld own = Load(world);
  EXPECT_FALSE(own.world->IsListedSwarmMetric("covered_area"));
  own.world->Step();
  int rows = 0;
  for (const MetricSample& m : own.world->TakeMetrics()) rows += m.name == "covered_area";
  EXPECT_EQ(rows, 1);
}

TEST_F(MetricsSectionTest, MetricsMistakesNameTheirPlace) {
  ExpectHas(ErrorOfWorld("metrics: [covered_aera]\n"),
            {"world.yaml:1:11:", "unknown metric 'covered_aera'", "did you mean 'covered_area'?"});
  ExpectHas(ErrorOfWorld("metrics: [{name: covered_area, evry: 3}]\n"),
            {"world.yaml:1:32:", "unknown key 'evry' in a metric", "did you mean 'every'?"});
  ExpectHas(ErrorOfWorld("metrics: [{every: 3}]\n"),
            {"world.yaml:1:11:", "'name' is required in a metric"});
  ExpectHas(ErrorOfWorld("metrics: [{name: covered_area, every: 0}]\n"), {"world.yaml:1:39:"});
  // A second entry of one metric would be a second column of its name.
  ExpectHas(ErrorOfWorld("metrics: [{name: covered_area, every: 10},\n  covered_area]\n"),
            {"world.yaml:2:3: 'covered_area' is listed already, at ",
             "world.yaml:1:18: list a metric once"});
  ExpectHas(ErrorOfWorld("metrics: covered_area\n"),
            {"world.yaml:1:10:", "'metrics' must be a list of metrics"});
}

}  // namespace
}  // namespace swarmsim
