// `swarmsim merge OUT IN...` (swarm/sweep/results_merge.cc): the shards of a
// sweep merge into the whole sweep, each run once.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <string>
#include <vector>

#include "tests/swarm/run_program.h"
#include "tests/swarm/sweep/sweep_db.h"

namespace swarmsim {
namespace {

namespace fs = std::filesystem;

using Result = swarmsim::testing::CommandResult;
using swarmsim::testing::RunCommand;
using swarmsim::testing::RunProgram;
using sweep_testing::Count;
using sweep_testing::kWorld;
using sweep_testing::ReadRuns;
using sweep_testing::RunRow;
using sweep_testing::TempDir;

TEST(SweepTest, ShardsMergeIntoTheWholeSweep) {
  const fs::path dir = TempDir("shard");
  const std::string grid = " --param robots=2,3,4 --seeds 2 --steps 8 --quiet ";
  ASSERT_EQ(RunProgram("sweep " + kWorld + grid + "--db " + (dir / "all.db").string()).exit_code,
            0);
  for (int i = 0; i < 2; ++i) {
    const std::string shard = std::to_string(i);
    Result r = RunProgram("sweep " + kWorld + grid + "--shard " + shard + "/2 --db " +
                          (dir / "s").string() + shard + ".db");
    ASSERT_EQ(r.exit_code, 0) << r.output;
  }
  EXPECT_EQ(Count(dir / "s0.db", "SELECT count(*) FROM runs WHERE status = 'ok'"), 3);
  Result m = RunProgram("merge " + (dir / "m.db").string() + " " + (dir / "s0.db").string() + " " +
                        (dir / "s1.db").string() + " " + (dir / "s0.db").string());
  ASSERT_EQ(m.exit_code, 0) << m.output;
  EXPECT_NE(m.output.find("6 of 6 runs finished"), std::string::npos) << m.output;
  EXPECT_NE(m.output.find("3 already in"), std::string::npos) << m.output;  // s0 twice: kept once
  const auto all = ReadRuns(dir / "all.db"), merged = ReadRuns(dir / "m.db");
  ASSERT_EQ(merged.size(), 6u);
  for (const auto& [id, run] : all) {
    EXPECT_EQ(merged.at(id).status, "ok");
    EXPECT_EQ(merged.at(id).hash, run.hash) << id;
  }
  EXPECT_EQ(Count(dir / "m.db", "SELECT count(*) FROM final_metrics"),
            Count(dir / "all.db", "SELECT count(*) FROM final_metrics"));
  fs::remove_all(dir);
}

// A run failed in one input and ok in a later one: the ok one (the failure
// was kept and the result dropped, with no word). An input that does not
// fit leaves no output behind (the inputs before it were merged already).
TEST(SweepTest, MergeKeepsAnOkRunOverAFailedOneAndChecksEveryInputFirst) {
  const fs::path dir = TempDir("merge_failed");
  const std::string grid = " --param robots=2,3 --seeds 1 --steps 8 --quiet ";
  ASSERT_EQ(RunProgram("sweep " + kWorld + grid + "--db " + (dir / "ok.db").string()).exit_code, 0);
  fs::copy_file(dir / "ok.db", dir / "failed.db");
  {
    SqliteDb db(dir / "failed.db");
    db.Exec("UPDATE runs SET status = 'failed', error = 'planned' WHERE id = 1");
    db.Exec("DELETE FROM final_metrics WHERE run = 1");
  }
  Result m = RunProgram("merge " + (dir / "m.db").string() + " " + (dir / "failed.db").string() +
                        " " + (dir / "ok.db").string());
  ASSERT_EQ(m.exit_code, 0) << m.output;
  EXPECT_NE(m.output.find("1 runs copied (1 of them ok where"), std::string::npos) << m.output;
  EXPECT_NE(m.output.find("2 of 2 runs finished (0 failed)"), std::string::npos) << m.output;
  EXPECT_EQ(ReadRuns(dir / "m.db").at(1).status, "ok");
  EXPECT_EQ(Count(dir / "m.db", "SELECT count(*) FROM final_metrics WHERE run = 1"),
            Count(dir / "ok.db", "SELECT count(*) FROM final_metrics WHERE run = 1"));
  // Another sweep, a missing file, a file that is no database: refused, no output.
  ASSERT_EQ(RunProgram("sweep " + kWorld + " --param robots=5 --seeds 1 --steps 8 --quiet --db " +
                       (dir / "other.db").string())
                .exit_code,
            0);
  std::ofstream(dir / "junk.db") << "not a database\n";
  for (const char* bad : {"other.db", "missing.db", "junk.db"}) {
    const Result r = RunProgram("merge " + (dir / "new.db").string() + " " +
                                (dir / "ok.db").string() + " " + (dir / bad).string());
    EXPECT_EQ(r.exit_code, 2) << bad << ": " << r.output;
    EXPECT_FALSE(fs::exists(dir / "new.db")) << bad;
  }
  fs::remove_all(dir);
}

}  // namespace
}  // namespace swarmsim
