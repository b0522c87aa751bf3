// The example worlds of issue 3: each runs, does what its README line says,
// and gives the same state hash at 1, 2 and 4 threads.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "framework/registry.h"
#include "framework/world.h"
#include "modules/builtin.h"
#include "swarm/loader/world_loader.h"
#include "tests/swarm/run_program.h"

namespace swarmsim {
namespace {

struct WorldRun {
  uint64_t hash = 0;
  std::vector<MetricSample> metrics;
};

WorldRun RunWorld(const std::string& name, int threads, int steps,
                  std::vector<std::pair<std::string, std::string>> overrides = {}) {
  ModuleRegistry registry;
  RegisterBuiltinModules(&registry);
  LoadOptions options;
  options.threads = threads;
  options.overrides = std::move(overrides);
  LoadedWorld loaded =
      LoadWorld(std::string(SWARMSIM_SOURCE_DIR) + "/worlds/" + name, options, registry);
  loaded.world->set_log_sink([](std::string_view) {});
  loaded.world->Start();
  WorldRun run;
  for (int i = 0; i < steps; ++i) loaded.world->Step();
  run.hash = loaded.world->StateHash();
  run.metrics = loaded.world->TakeMetrics();
  return run;
}

TEST(ExamplesTest, FirefliesSynchroniseAndAreIndependentOfThreadCount) {
  const WorldRun one = RunWorld("fireflies.yaml", 1, 400);
  ASSERT_FALSE(one.metrics.empty());
  EXPECT_EQ(one.metrics.front().name, "phase_spread");
  // Random phases at the start (spread ~0.9 for 200 robots), much closer
  // at the end, at every sample of the last 3 s.
  double last_max = 0;
  for (size_t i = one.metrics.size() - 6; i < one.metrics.size(); ++i)
    last_max = std::max(last_max, one.metrics[i].value);
  EXPECT_LT(last_max, 0.5);
  for (int threads : {2, 4}) {
    const WorldRun other = RunWorld("fireflies.yaml", threads, 400);
    EXPECT_EQ(other.hash, one.hash) << threads << " threads";
    ASSERT_EQ(other.metrics.size(), one.metrics.size());
    for (size_t i = 0; i < one.metrics.size(); ++i)
      EXPECT_EQ(other.metrics[i].value, one.metrics[i].value) << i;
  }
}

// Values of one metric, in recorded order.
std::vector<double> Values(const std::vector<MetricSample>& metrics, const std::string& name,
                           int instance = -1) {
  std::vector<double> out;
  for (const MetricSample& m : metrics)
    if (m.name == name && m.instance == instance) out.push_back(m.value);
  return out;
}

TEST(ExamplesTest, FlockingAlignsHeadingsAndIsIndependentOfThreadCount) {
  const WorldRun one = RunWorld("flocking.yaml", 1, 300);
  const std::vector<double> alignment = Values(one.metrics, "alignment");
  const std::vector<double> cohesion = Values(one.metrics, "cohesion");
  // Step 0, then every 10 steps (the main script's samples of the last step
  // are collected with the next step's).
  ASSERT_GE(alignment.size(), 30u);
  ASSERT_EQ(cohesion.size(), alignment.size());
  // Random headings at the start; one direction after 30 s, still together.
  EXPECT_LT(alignment.front(), 0.6);
  EXPECT_GT(alignment.back(), 0.95);
  EXPECT_LT(cohesion.back(), 1.5 * cohesion.front());
  for (int threads : {2, 4}) {
    const WorldRun other = RunWorld("flocking.yaml", threads, 300);
    EXPECT_EQ(other.hash, one.hash) << threads << " threads";
    EXPECT_EQ(Values(other.metrics, "alignment"), alignment) << threads << " threads";
  }
}

TEST(ExamplesTest, ThreadedArmsCycleWithWaitsAndAreIndependentOfThreadCount) {
  const WorldRun one = RunWorld("threaded_arms.yaml", 1, 600);
  // A cycle takes 2 x 0.8 s (finger) + 2 x 0.5 s (holds) + 2 x pi/2 s
  // (shoulder) = 5.74 s plus step rounding, after a 0..1 s start delay:
  // every arm finishes 4 or 5 cycles in 30 s, numbered 1, 2, ...
  for (int arm = 0; arm < 16; ++arm) {
    const std::vector<double> cycles = Values(one.metrics, "cycles", arm);
    ASSERT_GE(cycles.size(), 4u) << "arm " << arm;
    ASSERT_LE(cycles.size(), 5u) << "arm " << arm;
    for (size_t i = 0; i < cycles.size(); ++i) EXPECT_EQ(cycles[i], i + 1.0);
  }
  for (const MetricSample& m : one.metrics) {
    if (m.value == 1) {
      EXPECT_GE(m.time, 5.74) << m.instance;
    }
  }
  for (int threads : {2, 4}) {
    const WorldRun other = RunWorld("threaded_arms.yaml", threads, 600);
    EXPECT_EQ(other.hash, one.hash) << threads << " threads";
    ASSERT_EQ(other.metrics.size(), one.metrics.size());
    for (size_t i = 0; i < one.metrics.size(); ++i)
      EXPECT_EQ(other.metrics[i].step, one.metrics[i].step) << i;
  }
}

TEST(ExamplesTest, PluginDemoRunsThroughTheProgramWithTheWorldsPlugin) {
  // plugins: [example_plugin] is found in plugins/ beside the program.
  const std::string world = std::string(SWARMSIM_SOURCE_DIR) + "/worlds/plugin_demo.yaml";
  const std::filesystem::path out =
      std::filesystem::temp_directory_path() / ("swarmsim_plugin_demo_" + std::to_string(getpid()));
  std::string hash;
  for (int threads : {1, 2, 4}) {
    const auto [status, text] =
        swarmsim::testing::RunProgram("run " + world + " --quiet --hash --threads " +
                                      std::to_string(threads) + " --out " + out.string());
    ASSERT_EQ(status, 0) << text;
    const std::string line = text.substr(text.find("state-hash: "));
    if (hash.empty()) hash = line;
    EXPECT_EQ(line, hash) << threads << " threads";
  }
  // Each robot drove 5 legs of 5 s at 0.05 m/s, turning away from walls,
  // the pillar and each other: after the last leg it is away from its start.
  std::ifstream csv(out / "metrics.csv");
  std::map<std::string, double> last;
  std::string row;
  while (std::getline(csv, row)) {
    std::vector<std::string> cells;
    std::stringstream ss(row);
    for (std::string cell; std::getline(ss, cell, ',');) cells.push_back(cell);
    if (cells.size() == 5 && cells[3] == "distance") last[cells[2]] = std::stod(cells[4]);
  }
  EXPECT_EQ(last.size(), 20u);
  int away = 0;
  for (const auto& [robot, distance] : last) away += distance > 0.1;
  EXPECT_GE(away, 15);
  std::filesystem::remove_all(out);
}

TEST(ExamplesTest, PluginLightSensorReadsTheLightThroughTheProgram) {
  // The example plugin's `light` sensor type: four per puck, sensed robots in
  // parallel; the scripts check every reading against their own calculation.
  const std::string world = std::string(SWARMSIM_SOURCE_DIR) + "/worlds/plugin_light.yaml";
  const std::filesystem::path out = std::filesystem::temp_directory_path() /
                                    ("swarmsim_plugin_light_" + std::to_string(getpid()));
  std::string hash;
  for (int threads : {1, 2}) {
    const auto [status, text] =
        swarmsim::testing::RunProgram("run " + world + " --quiet --hash --threads " +
                                      std::to_string(threads) + " --out " + out.string());
    ASSERT_EQ(status, 0) << text;
    const std::string line = text.substr(text.find("state-hash: "));
    if (hash.empty()) hash = line;
    EXPECT_EQ(line, hash) << threads << " threads";
  }
  std::ifstream csv(out / "metrics.csv");
  std::map<std::string, std::vector<double>> intensity;
  int unsensed = 0, checked = 0;
  std::string row;
  while (std::getline(csv, row)) {
    std::vector<std::string> cells;
    std::stringstream ss(row);
    for (std::string cell; std::getline(ss, cell, ',');) cells.push_back(cell);
    if (cells.size() != 5) continue;
    if (cells[3] == "unsensed") unsensed += std::stod(cells[4]) == 1;
    if (cells[3] == "reading_error") {
      EXPECT_LE(std::stod(cells[4]), 1e-12) << row;
      ++checked;
    }
    if (cells[3] == "intensity") intensity[cells[2]].push_back(std::stod(cells[4]));
  }
  EXPECT_EQ(unsensed, 20);       // nil before the first sense phase
  EXPECT_EQ(checked, 20 * 100);  // every robot, every step
  ASSERT_EQ(intensity.size(), 20u);
  int brighter = 0;
  for (const auto& [robot, values] : intensity) brighter += values.back() > values.front();
  EXPECT_GE(brighter, 18);  // they climbed toward the light
  std::filesystem::remove_all(out);
}

TEST(ExamplesTest, UnknownPluginSensorTypeIsALoadErrorWithASuggestion) {
  const std::filesystem::path dir = std::filesystem::temp_directory_path() /
                                    ("swarmsim_plugin_sensor_" + std::to_string(getpid()));
  std::filesystem::create_directories(dir);
  std::ofstream(dir / "bot.yaml") << "model: bot\n"
                                     "objects:\n"
                                     "  type: dummy\n"
                                     "  children:\n"
                                     "    - {name: eye, type: plugin_sensor, sensor: lihgt}\n";
  std::ofstream(dir / "world.yaml") << "plugins: [example_plugin]\n"
                                       "models:\n"
                                       "  - {model: bot.yaml, count: 1, position: [0, 0, 0]}\n";
  const auto [status, text] =
      swarmsim::testing::RunProgram("run " + (dir / "world.yaml").string() + " --steps 1");
  EXPECT_NE(status, 0);
  EXPECT_NE(text.find("bot.yaml:5:"), std::string::npos) << text;
  EXPECT_NE(text.find("unknown plugin sensor type 'lihgt' (registered: light); did you mean "
                      "'light'?"),
            std::string::npos)
      << text;
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace swarmsim
