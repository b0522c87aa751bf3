// `swarmsim bench --scaling-robots` (swarm/bench/robot_scaling.cc): one row
// per configuration and robot count in the table and the CSV, with the
// per-phase costs adding up to the measured rate, start-up and memory, and
// a log-log plot that decodes; configurations checked before any output.
#include "swarm/bench/robot_scaling.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "framework/error.h"
#include "modules/paint/png_io.h"
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

TEST(RobotScalingTest, StepsKeepARowNearTwoMillionRobotTicks) {
  // What the README promises: 1,000 steps at 1,000 robots, 200 at 10,000,
  // 20 at 100,000, and at least 3 (the plot needs a rate) at a million.
  EXPECT_EQ(AutoScalingSteps(1000), 1000);
  EXPECT_EQ(AutoScalingSteps(10000), 200);
  EXPECT_EQ(AutoScalingSteps(100000), 20);
  EXPECT_EQ(AutoScalingSteps(1000000), 3);
  EXPECT_EQ(AutoScalingSteps(100), 1000) << "small swarms are capped, not run for 20,000 steps";
  EXPECT_EQ(AutoWarmupSteps(1000), 20);
  EXPECT_EQ(AutoWarmupSteps(20), 2);
  EXPECT_EQ(AutoWarmupSteps(3), 2);
}

TEST(RobotScalingTest, ATableACsvAndAPlotOfEveryConfigurationAndCount) {
  const fs::path dir = testing::FreshTempDir("robot_scaling_test", "run");
  fs::create_directories(dir);
  const fs::path csv = dir / "s.csv", plot = dir / "s.png";
  // Through the program: the C++ configurations load its plugins from beside it.
  const testing::CommandResult r = testing::RunProgram(
      "bench --scaling-robots --robots 100,400 --threads 2 --steps 2 --configs "
      "lua,planar-lua,planar-cpp "
      "--csv " +
      csv.string() + " --plot " + plot.string());
  const bool gnuplot = testing::RunCommand("command -v gnuplot").exit_code == 0;
  EXPECT_EQ(r.exit_code, gnuplot ? 0 : 1) << r.output;

  // The table: a header with the phases, a row per configuration and count.
  for (const std::string column :
       {"sense", "control", "physics", "other", "start s", "peak MiB", "KB/robot"})
    EXPECT_NE(r.output.find(column), std::string::npos) << column << "\n" << r.output;
  EXPECT_NE(r.output.find("worlds/diffusion.yaml"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("worlds/diffusion_planar.yaml"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("diffusion_planar_native.yaml"), std::string::npos) << r.output;

  std::ifstream in(csv);
  std::vector<std::vector<std::string>> rows;
  for (std::string line; std::getline(in, line);) rows.push_back(Fields(line));
  ASSERT_EQ(rows.size(), 7u) << r.output;
  const std::vector<std::string> header{
      "config",    "world",       "robots",      "threads",  "steps",    "robot_ticks_per_s",
      "us_sense",  "us_control",  "us_physics",  "us_other", "us_total", "cost_ratio",
      "startup_s", "peak_rss_mb", "kb_per_robot"};
  EXPECT_EQ(rows[0], header);
  const std::vector<std::pair<std::string, std::string>> expected = {
      {"lua", "100"},        {"lua", "400"},        {"planar-lua", "100"},
      {"planar-lua", "400"}, {"planar-cpp", "100"}, {"planar-cpp", "400"}};
  for (size_t i = 0; i < expected.size(); ++i) {
    const std::vector<std::string>& f = rows[i + 1];
    ASSERT_EQ(f.size(), header.size()) << i;
    EXPECT_EQ(f[0], expected[i].first) << i;
    EXPECT_EQ(f[2], expected[i].second) << i;
    EXPECT_EQ(f[3], "2") << i;
    EXPECT_EQ(f[4], "2") << i;
    const double rate = std::stod(f[5]), total = std::stod(f[10]);
    ASSERT_GT(rate, 0) << i;
    // The total is the measured wall time per robot-tick; the phases are parts of it.
    EXPECT_NEAR(total, 1e6 / rate, 1e-4 * total) << i;
    const double parts = std::stod(f[6]) + std::stod(f[7]) + std::stod(f[8]) + std::stod(f[9]);
    EXPECT_NEAR(parts, total, 1e-3 * total + 1e-6) << i;
    EXPECT_GT(std::stod(f[7]), 0) << "control time: " << i;
    EXPECT_GT(std::stod(f[8]), 0) << "physics time: " << i;
    EXPECT_GT(std::stod(f[12]), 0) << "start-up: " << i;
    EXPECT_GT(std::stod(f[13]), 0) << "peak memory: " << i;
    EXPECT_NEAR(std::stod(f[14]), std::stod(f[13]) * 1024 / std::stod(f[2]),
                1e-4 * std::stod(f[14]))
        << "KB per robot: " << i;
  }
  // Each configuration's first count is its own base.
  EXPECT_EQ(rows[1][11], "1");
  EXPECT_EQ(rows[3][11], "1");
  EXPECT_EQ(rows[5][11], "1");
  EXPECT_NEAR(std::stod(rows[2][11]), std::stod(rows[2][10]) / std::stod(rows[1][10]), 1e-5);

  if (gnuplot) {
    const paint::RgbImage image = paint::ReadPng(plot);
    EXPECT_EQ(image.width, 1200);
    EXPECT_EQ(image.height, 640);
    // Lines in more than a couple of colours, not a blank page.
    std::set<uint32_t> colours;
    for (size_t p = 0; p + 2 < image.rgb.size(); p += 3)
      colours.insert(image.rgb[p] << 16 | image.rgb[p + 1] << 8 | image.rgb[p + 2]);
    EXPECT_GT(colours.size(), 10u);
  } else {
    EXPECT_NE(r.output.find("bench: gnuplot failed or is missing"), std::string::npos);
  }
  fs::remove_all(dir);
}

// One count of one configuration: the plot's axes get a range about it, with
// no warning from gnuplot about an empty one.
TEST(RobotScalingTest, OneCountIsPlottedWithoutAWarning) {
  if (testing::RunCommand("command -v gnuplot").exit_code != 0) GTEST_SKIP() << "no gnuplot";
  const fs::path dir = testing::FreshTempDir("robot_scaling_test", "one");
  fs::create_directories(dir);
  const fs::path plot = dir / "one.png";
  const testing::CommandResult r = testing::RunProgram(
      "bench --scaling-robots --robots 100 --threads 1 --steps 2 --configs planar-cpp --csv " +
      (dir / "one.csv").string() + " --plot " + plot.string());
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ(r.output.find("Warning"), std::string::npos) << r.output;
  EXPECT_EQ(paint::ReadPng(plot).width, 1200);
  fs::remove_all(dir);
}

// --repeat N: every row measured once a round, rounds one after the other
// (all rows of round 1, then of round 2, ...), and each row reports its
// median round, the ratios taken between those.
TEST(RobotScalingTest, RoundsAreInterleavedAndEachRowIsItsMedianRound) {
  const fs::path dir = testing::FreshTempDir("robot_scaling_test", "repeat");
  fs::create_directories(dir);
  // Through the program: the C++ configuration loads its plugin from beside it.
  const fs::path csv = dir / "r.csv";
  const testing::CommandResult r = testing::RunProgram(
      "bench --scaling-robots --configs planar-cpp --robots 60,120 --threads 1 --steps 2 "
      "--repeat 3 --csv " +
      csv.string() + " --plot " + (dir / "r.png").string());
  // The rounds' lines, in order: 60, 120, 60, 120, 60, 120 robots.
  std::vector<std::pair<int, double>> runs;  // robots, us per robot-tick
  std::istringstream lines(r.output);
  for (std::string line; std::getline(lines, line);) {
    const size_t at = line.find("planar-cpp, ");
    if (line.find("bench: round ") != 0 || at == std::string::npos) continue;
    const int robots = std::stoi(line.substr(at + 12));
    runs.push_back({robots, std::stod(line.substr(line.rfind(": ") + 2))});
  }
  ASSERT_EQ(runs.size(), 6u) << r.output;
  for (size_t i = 0; i < runs.size(); ++i) EXPECT_EQ(runs[i].first, i % 2 == 0 ? 60 : 120) << i;
  std::ifstream in(csv);
  std::vector<std::vector<std::string>> rows;
  for (std::string line; std::getline(in, line);) rows.push_back(Fields(line));
  ASSERT_EQ(rows.size(), 3u) << "the header and one row per count";
  double totals[2];
  for (int k = 0; k < 2; ++k) {
    std::vector<double> mine;
    for (size_t i = static_cast<size_t>(k); i < runs.size(); i += 2) mine.push_back(runs[i].second);
    std::sort(mine.begin(), mine.end());
    totals[k] = std::stod(rows[static_cast<size_t>(k) + 1][10]);
    EXPECT_NEAR(totals[k], mine[1], 0.0051) << "row " << k << ": the median of its rounds";
  }
  EXPECT_NEAR(std::stod(rows[2][11]), totals[1] / totals[0], 1e-5);
  fs::remove_all(dir);
}

TEST(RobotScalingTest, ConfigurationsAreCheckedBeforeAnyOutput) {
  const testing::CommandResult unknown =
      testing::RunProgram("bench --scaling-robots --robots 2 --configs lua,pyhton");
  EXPECT_EQ(unknown.exit_code, 2) << unknown.output;
  EXPECT_NE(unknown.output.find(
                "bench: unknown configuration 'pyhton' (known: lua, cpp, planar-lua, planar-cpp)"),
            std::string::npos)
      << unknown.output;
  EXPECT_EQ(unknown.output.find("ticks/s"), std::string::npos) << unknown.output;

  // The four default worlds, in the table's order, each a file that exists.
  const std::vector<ScalingConfig> all = DefaultScalingConfigs();
  ASSERT_EQ(all.size(), 4u);
  const char* names[] = {"lua", "cpp", "planar-lua", "planar-cpp"};
  const char* files[] = {"diffusion.yaml", "diffusion_native.yaml", "diffusion_planar.yaml",
                         "diffusion_planar_native.yaml"};
  for (size_t i = 0; i < all.size(); ++i) {
    EXPECT_EQ(all[i].name, names[i]);
    EXPECT_EQ(fs::path(all[i].world).filename(), files[i]) << all[i].world;
    EXPECT_TRUE(fs::exists(all[i].world)) << all[i].world;
  }

  // A world without the `robots` parameter, as plain bench refuses it.
  const fs::path dir = testing::FreshTempDir("robot_scaling_test", "refused");
  fs::create_directories(dir);
  RobotScalingOptions o;
  o.configs = {{"fixed", (dir / "fixed.yaml").string()}};
  std::ofstream(o.configs[0].world) << "simulation: {physics: kinematic, time_step: 0.1}\n";
  o.csv = (dir / "s.csv").string();
  o.self_exe = SWARMSIM_BINARY;
  std::ostringstream out, err;
  try {
    RunRobotScalingBench(o, out, err);
    ADD_FAILURE() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("has no parameter 'robots'"), std::string::npos)
        << e.what();
  }
  EXPECT_EQ(out.str(), "");
  EXPECT_FALSE(fs::exists(o.csv));

  const testing::CommandResult both =
      testing::RunProgram("bench --scaling-robots --scaling --robots 2");
  EXPECT_EQ(both.exit_code, 2) << both.output;
  EXPECT_NE(both.output.find("excludes"), std::string::npos) << both.output;
  fs::remove_all(dir);
}

}  // namespace
}  // namespace swarmsim
