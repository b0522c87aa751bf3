// Start-up on any number of threads gives the same world: the robots' Lua
// states are made and their sysCall_init run in parallel (script_host.cc,
// each source compiled once and loaded as bytecode by the others), and
// what sysCall_init draws from the robot's random streams, records as
// metrics and writes to its own model must not depend on which thread ran
// which robot, or on which robot compiled the shared chunk.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <string>

#include "tests/swarm/run_program.h"

namespace swarmsim {
namespace {

namespace fs = std::filesystem;
using testing::RunProgram;

std::string HashOf(const std::string& output) {
  const size_t at = output.find("state-hash: ");
  return at == std::string::npos ? "" : output.substr(at + 12, 16);
}

std::string ReadFile(const fs::path& file) {
  std::ifstream in(file);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

TEST(ParallelStartTest, SysCallInitGivesTheSameWorldOnOneAndTwoThreads) {
  const fs::path dir = testing::FreshTempDir("parallel_start_test", "world");
  fs::create_directories(dir);
  // 300 robots: many start-up tasks (a few robots each) on each thread.
  std::ofstream(dir / "world.yaml") << "simulation: {physics: kinematic, time_step: 0.1, seed: 7}\n"
                                       "arena: {size: 40}\n"
                                       "models:\n"
                                       "  - model: bot.yaml\n"
                                       "    count: 300\n"
                                       "    distribute: {region: arena}\n";
  std::ofstream(dir / "bot.yaml") << "model: bot\n"
                                     "objects:\n"
                                     "  name: body\n"
                                     "  type: shape\n"
                                     "  shape: cylinder\n"
                                     "  radius: 0.05\n"
                                     "  height: 0.05\n"
                                     "  script: bot.lua\n";
  std::ofstream(dir / "bot.lua")
      << "local offset\n"
         "function sysCall_init()\n"
         "  -- the robot's stream and Lua's own math.random, both seeded per robot\n"
         "  offset = sim.random() + math.random()\n"
         "  sim.recordMetric('init_draw', offset)\n"
         "  local body = sim.getObject('.')\n"
         "  local p = sim.getObjectPosition(body, -1)\n"
         "  sim.setObjectPosition(body, -1, {p[1] + 0.01 * offset, p[2], p[3]})\n"
         "end\n"
         "function sysCall_actuation()\n"
         "  sim.recordMetric('step_draw', sim.random() + offset)\n"
         "end\n";
  std::string hash[2], metrics[2];
  for (int threads : {1, 2}) {
    const fs::path out = dir / ("out" + std::to_string(threads));
    const testing::CommandResult r =
        RunProgram("run " + (dir / "world.yaml").string() + " --steps 3 --hash --quiet --threads " +
                   std::to_string(threads) + " --out " + out.string());
    ASSERT_EQ(r.exit_code, 0) << r.output;
    hash[threads - 1] = HashOf(r.output);
    ASSERT_EQ(hash[threads - 1].size(), 16u) << r.output;
    metrics[threads - 1] = ReadFile(out / "metrics.csv");
  }
  EXPECT_EQ(hash[0], hash[1]);
  EXPECT_EQ(metrics[0], metrics[1]) << "the same samples, in robot order";
  // Every robot drew its own numbers at start-up.
  std::set<double> draws;
  size_t init_rows = 0;
  for (const auto& row : testing::ReadMetricsCsv(dir / "out2/metrics.csv")) {
    if (row.metric != "init_draw") continue;
    ++init_rows;
    draws.insert(row.value);
  }
  EXPECT_EQ(init_rows, 300u);
  EXPECT_EQ(draws.size(), 300u);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace swarmsim
