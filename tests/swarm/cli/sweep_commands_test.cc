// swarmsim sweep, report and merge as their command lines read them
// (swarm/cli/sweep_commands.cc): --duration, --shard and --max-memory handed to the sweep,
// the options' checks, and what report and merge require.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "tests/swarm/run_program.h"

namespace {

namespace fs = std::filesystem;

using Result = swarmsim::testing::CommandResult;
using swarmsim::testing::RunProgram;

const std::string kWorld = std::string(SWARMSIM_SOURCE_DIR) + "/tests/data/sweep/sweep.yaml";

fs::path TempDir(const std::string& name) {
  const fs::path dir = swarmsim::testing::FreshTempDir("swarmsim_sweep_cli", name);
  fs::create_directories(dir);
  return dir;
}

// The rows of a CSV as fields (no quoted commas in these).
std::vector<std::vector<std::string>> Csv(const fs::path& file) {
  std::vector<std::vector<std::string>> rows;
  std::ifstream in(file);
  for (std::string line; std::getline(in, line);) {
    std::vector<std::string> fields;
    std::stringstream s(line);
    for (std::string f; std::getline(s, f, ',');) fields.push_back(f);
    rows.push_back(fields);
  }
  return rows;
}

TEST(SweepCommandsTest, DurationIsTheRunLengthOfEveryRun) {
  const fs::path dir = TempDir("duration");
  const fs::path db = dir / "r.db", csv = dir / "runs.csv";
  // sweep.yaml steps 0.1 s: 0.3 s is 3 steps (its own length is 10).
  Result r =
      RunProgram("sweep " + kWorld + " --seeds 2 --duration 0.3 --quiet --db " + db.string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  r = RunProgram("report " + db.string() + " --csv " + csv.string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const auto rows = Csv(csv);
  ASSERT_EQ(rows.size(), 3u);
  ASSERT_GT(rows[0].size(), 4u);
  EXPECT_EQ(rows[0][4], "steps");
  EXPECT_EQ(rows[1][4], "3");
  EXPECT_EQ(rows[2][4], "3");
  fs::remove_all(dir);
}

TEST(SweepCommandsTest, OptionsSayWhatTheyExpect) {
  const fs::path dir = TempDir("options");
  const std::string sweep = "sweep " + kWorld + " --quiet --db " + (dir / "r.db").string();
  const std::vector<std::pair<std::string, std::string>> cases = {
      {" --jobs 0", "--jobs: must be >= 1, got 0"},
      {" --jobs 2.5", "--jobs: expected a whole number of jobs, got '2.5'"},
      {" --threads 0", "--threads: expected a whole number from 1 to 1024, got '0'"},
      {" --timeout -1", "--timeout: must be >= 0, got -1"},
      {" --max-memory 12X", "expected a memory size such as 500M, 2G or 1.5GiB, got '12X'"},
      {" --shard 1/2x", "--shard expects i/n (e.g. 0/10 for the first of 10 shards), got '1/2x'"},
  };
  for (const auto& [args, message] : cases) {
    const Result r = RunProgram(sweep + args);
    EXPECT_EQ(r.exit_code, 2) << args << ": " << r.output;
    EXPECT_NE(r.output.find(message), std::string::npos) << args << ": " << r.output;
    EXPECT_FALSE(fs::exists(dir / "r.db")) << args;
  }
  // One run length: steps or a duration.
  Result r = RunProgram(sweep + " --steps 3 --duration 0.3");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find(" excludes "), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(dir / "r.db"));
  r = RunProgram("sweep " + kWorld + " --db ''");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("--db: expected a database file"), std::string::npos) << r.output;
  r = RunProgram("sweep " + kWorld);
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("--db is required"), std::string::npos) << r.output;
  fs::remove_all(dir);
}

// --max-memory reaches every run: a world too large for it fails that run
// with the memory check's message (the sweep goes on and says so).
TEST(SweepCommandsTest, MaxMemoryIsEveryRunsCap) {
  const fs::path dir = TempDir("max_memory");
  const fs::path db = dir / "r.db", csv = dir / "runs.csv";
  Result r = RunProgram("sweep " + std::string(SWARMSIM_SOURCE_DIR) +
                        "/worlds/diffusion.yaml --param robots=40000 --steps 1 --jobs 1 "
                        "--max-memory 400M --quiet --db " +
                        db.string());
  EXPECT_EQ(r.exit_code, 1) << r.output;
  r = RunProgram("report " + db.string() + " --csv " + csv.string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const auto rows = Csv(csv);
  ASSERT_EQ(rows.size(), 2u);
  EXPECT_EQ(rows[1][3], "failed");
  EXPECT_NE(r.output.find("not enough memory for 40,000 robot"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("(--max-memory 400 MiB)"), std::string::npos) << r.output;
  fs::remove_all(dir);
}

TEST(SweepCommandsTest, ReportAndMergeNeedTheirFiles) {
  const fs::path dir = TempDir("report_merge");
  Result r = RunProgram("report " + (dir / "none.db").string());
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("no database '" + (dir / "none.db").string() + "'"), std::string::npos)
      << r.output;
  for (const char* option : {"--csv", "--plot"}) {
    r = RunProgram("report " + (dir / "none.db").string() + " " + option + " ''");
    EXPECT_EQ(r.exit_code, 2) << r.output;
    EXPECT_NE(r.output.find(std::string(option) + ": expected a file"), std::string::npos)
        << r.output;
  }
  r = RunProgram("merge " + (dir / "out.db").string());
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("inputs is required"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(dir / "out.db"));
  fs::remove_all(dir);
}

}  // namespace
