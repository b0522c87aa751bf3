// worlds/led_aggregation.yaml: robots that see each other's LEDs through
// blob cameras gather by colour. Over the run the share of each robot's
// nearest neighbours with its colour rises well above the mixed start and
// above a run with the cameras off, and each colour's robots draw together;
// the run is the same at 1 and 2 threads.
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

constexpr int kSteps = 400;

struct RunOutputs {
  std::string hash;
  std::map<long, std::map<std::string, double>> metrics;  // step -> metric -> value
  std::string csv;
};

RunOutputs RunWorld(const std::string& name, const std::string& flags) {
  const fs::path out = testing::FreshTempDir("swarmsim_led_aggregation", name);
  const auto r = testing::RunProgram(
      "run " + std::string(SWARMSIM_SOURCE_DIR) + "/worlds/led_aggregation.yaml --steps " +
      std::to_string(kSteps) + " --hash --quiet --out " + out.string() + " " + flags);
  EXPECT_EQ(r.exit_code, 0) << r.output;
  RunOutputs run;
  const size_t at = r.output.find("state-hash: ");
  if (at != std::string::npos) run.hash = r.output.substr(at, 28);
  for (const testing::MetricRow& row : testing::ReadMetricsCsv(out / "metrics.csv"))
    if (row.robot.empty()) run.metrics[row.step][row.metric] = row.value;
  std::ifstream csv(out / "metrics.csv");
  std::stringstream s;
  s << csv.rdbuf();
  run.csv = s.str();
  fs::remove_all(out);
  return run;
}

TEST(LedAggregationTest, RobotsGatherByColourOnlyWhenTheySeeEachOther) {
  const RunOutputs seeing = RunWorld("seeing", "--threads 1");
  const RunOutputs blind = RunWorld("blind", "--threads 1 --set ledbot.camera_on=false");
  ASSERT_TRUE(seeing.metrics.count(10) && seeing.metrics.count(kSteps));
  ASSERT_TRUE(blind.metrics.count(kSteps));
  const auto value = [](const RunOutputs& run, long step, const char* metric) {
    return run.metrics.at(step).at(metric);
  };
  const double start = value(seeing, 10, "same_color_neighbor_fraction");
  const double end = value(seeing, kSteps, "same_color_neighbor_fraction");
  const double blind_end = value(blind, kSteps, "same_color_neighbor_fraction");
  // Three colours well mixed: about a third of one's neighbours share one's
  // colour; gathered, most of them.
  EXPECT_LT(start, 0.5);
  EXPECT_GT(end, 0.8);
  EXPECT_GT(end, start + 0.3);
  EXPECT_GT(end, blind_end + 0.3);
  EXPECT_LT(value(seeing, kSteps, "color_dispersion"), 0.8 * value(seeing, 10, "color_dispersion"));
  EXPECT_LT(value(seeing, kSteps, "color_dispersion"), value(blind, kSteps, "color_dispersion"));
}

TEST(LedAggregationTest, OneAndTwoThreadsGiveTheSameRun) {
  const RunOutputs one = RunWorld("one", "--threads 1");
  const RunOutputs two = RunWorld("two", "--threads 2");
  ASSERT_FALSE(one.hash.empty());
  EXPECT_EQ(one.hash, two.hash);
  EXPECT_EQ(one.csv, two.csv);
}

}  // namespace
}  // namespace swarmsim
