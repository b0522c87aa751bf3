// `swarmsim bench --scaling` (swarm/bench/scaling.cc): robot-ticks/s over
// threads and sweep runs/min over jobs, each against its first, into a table,
// a CSV and a plot; the world checked before any of it.
#include "swarm/bench/scaling.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "framework/error.h"
#include "tests/swarm/run_program.h"

namespace swarmsim {
namespace {

namespace fs = std::filesystem;

std::vector<std::string> Fields(const std::string& line) {
  std::vector<std::string> fields;
  std::stringstream s(line);
  for (std::string f; std::getline(s, f, ',');) fields.push_back(f);
  return fields;
}

ScalingOptions Small(const fs::path& dir) {
  ScalingOptions o;
  o.bench.world = std::string(SWARMSIM_SOURCE_DIR) + "/worlds/diffusion.yaml";
  o.bench.robots = {2};
  o.bench.threads = {1, 2};
  o.bench.steps = 2;
  o.bench.self_exe = SWARMSIM_BINARY;
  o.threads_given = true;
  o.jobs = {1, 2};
  o.sweep_runs = 2;
  o.sweep_robots = 2;
  o.sweep_steps = 2;
  o.csv = (dir / "scaling.csv").string();
  o.plot = (dir / "scaling.png").string();
  return o;
}

TEST(ScalingTest, SpeedUpsAreOverTheFirstThreadAndTheFirstJob) {
  const fs::path dir = testing::FreshTempDir("scaling_test", "run");
  fs::create_directories(dir);
  const ScalingOptions o = Small(dir);
  std::ostringstream out, err;
  const int code = RunScalingBench(o, out, err);
  const bool gnuplot = testing::RunCommand("command -v gnuplot").exit_code == 0;
  EXPECT_EQ(code, gnuplot ? 0 : 1) << err.str();
  if (!gnuplot) {
    EXPECT_NE(err.str().find("bench: gnuplot failed or is missing"), std::string::npos);
  }
  EXPECT_EQ(fs::exists(o.plot), gnuplot);
  std::ifstream csv(o.csv);
  std::vector<std::vector<std::string>> rows;
  for (std::string line; std::getline(csv, line);) rows.push_back(Fields(line));
  ASSERT_EQ(rows.size(), 5u) << out.str();
  EXPECT_EQ(rows[0],
            (std::vector<std::string>{"series", "workers", "throughput", "unit", "speedup"}));
  const std::vector<std::vector<std::string>> expected = {{"robots=2", "1", "robot-ticks/s"},
                                                          {"robots=2", "2", "robot-ticks/s"},
                                                          {"sweep", "1", "runs/min"},
                                                          {"sweep", "2", "runs/min"}};
  for (size_t i = 0; i < expected.size(); ++i) {
    ASSERT_EQ(rows[i + 1].size(), 5u);
    EXPECT_EQ(rows[i + 1][0], expected[i][0]);
    EXPECT_EQ(rows[i + 1][1], expected[i][1]);
    EXPECT_EQ(rows[i + 1][3], expected[i][2]);
    EXPECT_GT(std::stod(rows[i + 1][2]), 0) << i;
  }
  // The first of each series is its own base; the others are over it.
  EXPECT_EQ(rows[1][4], "1");
  EXPECT_EQ(rows[3][4], "1");
  EXPECT_NEAR(std::stod(rows[2][4]), std::stod(rows[2][2]) / std::stod(rows[1][2]), 1e-6);
  EXPECT_NEAR(std::stod(rows[4][4]), std::stod(rows[4][2]) / std::stod(rows[3][2]), 1e-6);
  EXPECT_NE(out.str().find("== sweep throughput: 2 runs of "), std::string::npos) << out.str();
  EXPECT_NE(out.str().find("csv: " + o.csv), std::string::npos) << out.str();
  fs::remove_all(dir);
}

TEST(ScalingTest, AWorldWithoutRobotsIsRefusedBeforeAnyOutput) {
  const fs::path dir = testing::FreshTempDir("scaling_test", "refused");
  fs::create_directories(dir);
  ScalingOptions o = Small(dir);
  o.bench.world = (dir / "fixed.yaml").string();
  std::ofstream(o.bench.world) << "simulation: {physics: kinematic, time_step: 0.1}\n";
  std::ostringstream out, err;
  EXPECT_THROW(RunScalingBench(o, out, err), Error);
  EXPECT_EQ(out.str(), "");
  EXPECT_FALSE(fs::exists(o.csv));
  fs::remove_all(dir);
}

}  // namespace
}  // namespace swarmsim
