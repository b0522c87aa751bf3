// worlds/visual_servo.yaml as a user runs it: the arm finds the puck with
// its camera's filter chain and brings the tool above it, wherever the puck
// is put; the tool's path (the model's tip_path graph) is checked against
// the puck's true position, which the script is never told.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "tests/swarm/run_program.h"

namespace swarmsim {
namespace {

namespace fs = std::filesystem;
using testing::FreshTempDir;
using testing::ReadMetricsCsv;
using testing::RunProgram;

const std::string kWorld = std::string(SWARMSIM_SOURCE_DIR) + "/worlds/visual_servo.yaml";

struct Servo {
  int exit_code = -1;
  std::string output;
  std::vector<double> tip;            // the tool tip's last position (x, y, z)
  double puck_x = NAN, puck_y = NAN;  // the script's last estimate
  int estimates = 0;
};

Servo RunServo(const std::string& name, const std::string& sets) {
  const fs::path out = FreshTempDir("swarmsim_visual_servo", name);
  Servo s;
  const auto r =
      RunProgram("run " + kWorld + " --quiet --threads 2 --out " + out.string() + " " + sets);
  s.exit_code = r.exit_code;
  s.output = r.output;
  for (const auto& row : ReadMetricsCsv(out / "metrics.csv")) {
    if (row.metric == "puck_x") s.puck_x = row.value, ++s.estimates;
    if (row.metric == "puck_y") s.puck_y = row.value;
  }
  std::ifstream path(out / "graphs" / "ur5#0" / "tip_path.csv");
  std::string line, last;
  while (std::getline(path, line)) last = line;
  std::stringstream cells(last);
  std::string cell;
  std::getline(cells, cell, ',');  // time
  while (std::getline(cells, cell, ',')) s.tip.push_back(std::stod(cell));
  fs::remove_all(out);
  return s;
}

TEST(VisualServoTest, TheToolEndsAboveThePuckWhereverItLies) {
  for (const auto& [x, y] :
       std::vector<std::pair<double, double>>{{0.5, 0.2}, {0.3, -0.35}, {0.65, 0}}) {
    const Servo s = RunServo(
        "puck", "--set puck_x=" + std::to_string(x) + " --set puck_y=" + std::to_string(y));
    ASSERT_EQ(s.exit_code, 0) << s.output;
    EXPECT_NEAR(s.puck_x, x, 0.005) << "the camera's estimate";
    EXPECT_NEAR(s.puck_y, y, 0.005);
    ASSERT_EQ(s.tip.size(), 3u);
    EXPECT_NEAR(s.tip[0], x, 0.01) << "the tool above the puck";
    EXPECT_NEAR(s.tip[1], y, 0.01);
    EXPECT_NEAR(s.tip[2], 0.42 + 0.10, 0.01) << "hovering 10 cm over its top";
  }
}

TEST(VisualServoTest, APuckOutOfViewIsNotFoundAndTheArmWaits) {
  const Servo s = RunServo("away", "--set puck_x=3");
  ASSERT_EQ(s.exit_code, 0) << s.output;
  EXPECT_EQ(s.estimates, 0);
  ASSERT_EQ(s.tip.size(), 3u);
  EXPECT_LT(s.tip[0], 0) << "the tool stays where it started, behind the base";
}

TEST(VisualServoTest, TheSameHashAtOneAndTwoThreads) {
  const auto one = RunProgram("run " + kWorld + " --quiet --hash --steps 60 --threads 1");
  const auto two = RunProgram("run " + kWorld + " --quiet --hash --steps 60 --threads 2");
  ASSERT_EQ(one.exit_code, 0) << one.output;
  EXPECT_NE(one.output.find("state-hash: "), std::string::npos);
  EXPECT_EQ(one.output, two.output);
}

}  // namespace
}  // namespace swarmsim
