// worlds/rab_aggregation.yaml: foot-bots that hear each other through
// range-and-bearing boards gather. Over the run the mean distance from each
// robot to its nearest neighbour falls well below the start and below the
// same robots ignoring their boards (a random walk); the run is the same at
// 1 and 2 threads.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>

#include "tests/swarm/run_program.h"

namespace swarmsim {
namespace {

namespace fs = std::filesystem;

constexpr int kSteps = 600;  // the world's duration

struct RunOutputs {
  std::string hash;
  std::map<long, double> nearest;  // step -> mean_nearest_neighbor_distance
  std::string csv;
};

RunOutputs RunWorld(const std::string& name, const std::string& flags) {
  const fs::path out = testing::FreshTempDir("swarmsim_rab_aggregation", name);
  const auto r = testing::RunProgram(
      "run " + std::string(SWARMSIM_SOURCE_DIR) + "/worlds/rab_aggregation.yaml --steps " +
      std::to_string(kSteps) + " --hash --quiet --out " + out.string() + " " + flags);
  EXPECT_EQ(r.exit_code, 0) << r.output;
  RunOutputs run;
  const size_t at = r.output.find("state-hash: ");
  if (at != std::string::npos) run.hash = r.output.substr(at, 28);
  for (const testing::MetricRow& row : testing::ReadMetricsCsv(out / "metrics.csv"))
    if (row.robot.empty() && row.metric == "mean_nearest_neighbor_distance")
      run.nearest[row.step] = row.value;
  std::ifstream csv(out / "metrics.csv");
  std::stringstream s;
  s << csv.rdbuf();
  run.csv = s.str();
  fs::remove_all(out);
  return run;
}

TEST(RabAggregationTest, RobotsGatherOnlyWhenTheyListen) {
  const RunOutputs listening = RunWorld("listening", "--threads 1");
  const RunOutputs deaf = RunWorld("deaf", "--threads 1 --set rabbot.listen=false");
  ASSERT_TRUE(listening.nearest.count(10) && listening.nearest.count(kSteps));
  ASSERT_TRUE(deaf.nearest.count(kSteps));
  const double start = listening.nearest.at(10), end = listening.nearest.at(kSteps);
  const double deaf_end = deaf.nearest.at(kSteps);
  // 60 robots at 0.5 per m^2 spread at random: about 0.7 m apart. Gathered,
  // their bodies (0.17 m across) nearly touch; a random walk stays spread.
  EXPECT_GT(start, 0.6);
  EXPECT_LT(end, 0.5 * start);
  EXPECT_LT(end, 0.5 * deaf_end);
  EXPECT_GT(deaf_end, 0.6);
  EXPECT_GE(end, 0.17);  // bodies do not overlap
}

TEST(RabAggregationTest, OneAndTwoThreadsGiveTheSameRun) {
  const RunOutputs one = RunWorld("one", "--threads 1");
  const RunOutputs two = RunWorld("two", "--threads 2");
  ASSERT_FALSE(one.hash.empty());
  EXPECT_EQ(one.hash, two.hash);
  EXPECT_EQ(one.csv, two.csv);
}

}  // namespace
}  // namespace swarmsim
