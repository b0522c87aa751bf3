// The swarmsim program as a user meets it: exit codes, messages, outputs.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

#include "tests/swarm/run_program.h"

namespace {

namespace fs = std::filesystem;

using Result = swarmsim::testing::CommandResult;
using swarmsim::testing::RunProgram;

std::string Data(const std::string& name) {
  return std::string(SWARMSIM_SOURCE_DIR) + "/tests/data/cli/" + name;
}

fs::path TempDir(const std::string& name) {
  const fs::path dir =
      fs::temp_directory_path() / ("swarmsim_cli_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  return dir;
}

std::string HashOf(const std::string& output) {
  const size_t at = output.find("state-hash: ");
  return at == std::string::npos ? "" : output.substr(at + 12, 16);
}

TEST(CliTest, HelpVersionAndModules) {
  Result help = RunProgram("--help");
  EXPECT_EQ(help.exit_code, 0);
  EXPECT_NE(help.output.find("run"), std::string::npos);
  EXPECT_NE(help.output.find("bench"), std::string::npos);
  Result version = RunProgram("version");
  EXPECT_EQ(version.exit_code, 0);
  EXPECT_NE(version.output.find("swarmsim "), std::string::npos);
  Result modules = RunProgram("modules");
  EXPECT_EQ(modules.exit_code, 0);
  EXPECT_NE(modules.output.find("box2d"), std::string::npos) << modules.output;
  EXPECT_NE(modules.output.find("proximity"), std::string::npos) << modules.output;
}

TEST(CliTest, UnknownFlagIsAClearErrorWithNonzeroExit) {
  Result r = RunProgram("run " + Data("ok.yaml") + " --stpes 10");
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.output.find("--stpes"), std::string::npos) << r.output;
  Result bad_set = RunProgram("run " + Data("ok.yaml") + " --set robots");
  EXPECT_NE(bad_set.exit_code, 0);
  EXPECT_NE(bad_set.output.find("name=value"), std::string::npos) << bad_set.output;
}

TEST(CliTest, OutOfRangeNumbersAreClearErrors) {
  Result huge = RunProgram("run " + Data("ok.yaml") + " --duration 1e300");
  EXPECT_EQ(huge.exit_code, 2);
  EXPECT_NE(huge.output.find("at most 1e15 steps"), std::string::npos) << huge.output;
  Result threads = RunProgram("run " + Data("ok.yaml") + " --threads 100000 --steps 1");
  EXPECT_EQ(threads.exit_code, 2);
  EXPECT_NE(threads.output.find("1 to 1024"), std::string::npos) << threads.output;
  Result negative = RunProgram("run " + Data("ok.yaml") + " --steps -1");
  EXPECT_EQ(negative.exit_code, 2);
  EXPECT_NE(negative.output.find("must be >= 0"), std::string::npos) << negative.output;
}

TEST(CliTest, MissingWorldFileIsNamed) {
  Result r = RunProgram("run /nonexistent/world.yaml --steps 1");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.output.find("/nonexistent/world.yaml"), std::string::npos) << r.output;
}

TEST(CliTest, TypoInWorldNamesLineAndSuggests) {
  Result r = RunProgram("run " + Data("typo.yaml") + " --steps 1");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.output.find("typo.yaml:4:"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("wall_thickness"), std::string::npos) << r.output;
}

TEST(CliTest, RunWritesSummaryAndMetricsAndHashIsStable) {
  const fs::path out = TempDir("ok");
  Result r =
      RunProgram("run " + Data("ok.yaml") + " --steps 20 --threads 2 --hash --out " + out.string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("robot-ticks/s"), std::string::npos) << r.output;
  const std::string hash = HashOf(r.output);
  ASSERT_EQ(hash.size(), 16u) << r.output;
  // Same hash on one thread; another seed gives another.
  EXPECT_EQ(
      HashOf(
          RunProgram("run " + Data("ok.yaml") + " --steps 20 --threads 1 --hash --quiet").output),
      hash);
  EXPECT_NE(
      HashOf(RunProgram("run " + Data("ok.yaml") + " --steps 20 --seed 99 --hash --quiet").output),
      hash);

  std::ifstream summary_file(out / "summary.json");
  ASSERT_TRUE(summary_file.good());
  const auto summary = nlohmann::json::parse(summary_file);
  EXPECT_EQ(summary["status"], "ok");
  EXPECT_EQ(summary["robots"], 4);
  EXPECT_EQ(summary["steps"], 20);
  EXPECT_EQ(summary["threads"], 2);
  EXPECT_EQ(summary["state_hash"], hash);

  std::ifstream metrics(out / "metrics.csv");
  std::string header, line;
  std::getline(metrics, header);
  EXPECT_EQ(header, "step,time,robot,metric,value");
  int robot_rows = 0, swarm_rows = 0;
  while (std::getline(metrics, line)) {
    if (line.find(",x,") != std::string::npos) ++robot_rows;
    if (line.find("mean_nearest_neighbor_distance") != std::string::npos) ++swarm_rows;
  }
  EXPECT_EQ(robot_rows, 4 * 20);  // each robot records x once per step
  EXPECT_EQ(swarm_rows, 4);       // every 5 steps
  fs::remove_all(out);
}

TEST(CliTest, ScriptErrorNamesRobotFileAndLineAndKeepsOutputs) {
  const fs::path out = TempDir("broken");
  Result r = RunProgram("run " + Data("broken.yaml") + " --steps 20 --out " + out.string());
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find("brokenbot#0"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("broken.lua:4:"), std::string::npos) << r.output;
  std::ifstream summary_file(out / "summary.json");
  ASSERT_TRUE(summary_file.good()) << "summary.json must be written on error";
  const auto summary = nlohmann::json::parse(summary_file);
  EXPECT_EQ(summary["status"], "error");
  EXPECT_EQ(summary["steps"], 5);  // steps at t = 0 .. 0.4 completed; the script fails at t = 0.5
  EXPECT_TRUE(fs::exists(out / "metrics.csv"));
  fs::remove_all(out);
}

}  // namespace
