// `swarmsim sweep` (swarm/sweep/sweep.cc): --shard i/n read and checked, and
// a sweep that sits whole in one shard or in none. The sweep's parts have
// their own tests: coordinator_test (resume, refusals), worker_test
// (failures), grid_test, report_test, results_merge_test, mpi_test.
#include "swarm/sweep/sweep.h"

#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/file.h>
#include <unistd.h>

#include <filesystem>
#include <string>

#include "framework/error.h"
#include "tests/swarm/run_program.h"
#include "tests/swarm/sweep/sweep_db.h"

namespace swarmsim {
namespace {

namespace fs = std::filesystem;

using swarmsim::testing::RunProgram;
using sweep_testing::Count;
using sweep_testing::kWorld;
using sweep_testing::TempDir;

// What ParseShard says about `text` ("" when it reads).
std::string ShardError(const std::string& text) {
  int index = -1, count = -1;
  try {
    ParseShard(text, &index, &count);
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

TEST(SweepTest, ShardIsAnIndexBelowACount) {
  int index = -1, count = -1;
  ParseShard("0/10", &index, &count);
  EXPECT_EQ(index, 0);
  EXPECT_EQ(count, 10);
  ParseShard("9/10", &index, &count);
  EXPECT_EQ(index, 9);
  EXPECT_EQ(count, 10);
  for (const std::string text : {"10/10", "-1/3", "1/0", "0/0"})
    EXPECT_EQ(ShardError(text), "--shard " + text + ": need 0 <= i < n") << text;
  for (const std::string text : {"3", "a/3", "1/3x", "1 /3", "/3", "1/", ""})
    EXPECT_EQ(ShardError(text),
              "--shard expects i/n (e.g. 0/10 for the first of 10 shards), got '" + text + "'")
        << text;
}

TEST(SweepTest, AShardTakesEveryNthRun) {
  const fs::path dir = TempDir("shard_ids");
  // Runs 1..6 (robots 2,3,4 x seeds 1,2), counted from 0 for the shards:
  // shard 1/3 takes runs 2 and 5.
  const std::string grid = " --param robots=2,3,4 --seeds 2 --steps 2 --quiet ";
  const fs::path db = dir / "s1.db";
  auto r = RunProgram("sweep " + kWorld + grid + "--shard 1/3 --db " + db.string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ(Count(db, "SELECT count(*) FROM runs"), 6);
  EXPECT_EQ(Count(db, "SELECT count(*) FROM runs WHERE status = 'ok'"), 2);
  EXPECT_EQ(Count(db, "SELECT count(*) FROM runs WHERE status = 'ok' AND (id - 1) % 3 = 1"), 2);
  // A shard outside the count is bad input before any database is made.
  r = RunProgram("sweep " + kWorld + grid + "--shard 3/3 --db " + (dir / "bad.db").string());
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("--shard 3/3: need 0 <= i < n"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(dir / "bad.db"));
  fs::remove_all(dir);
}

// A second sweep on a database another sweep is running on is refused
// (it would take the first's runs in progress for a stopped sweep's and run
// them again beside it); once the first is over, the same command resumes.
TEST(SweepTest, ASecondSweepOnTheSameDatabaseIsRefused) {
  const fs::path dir = TempDir("locked");
  const fs::path db = dir / "s.db";
  const std::string sweep =
      "sweep " + kWorld + " --param robots=2,3 --seeds 1 --steps 2 --quiet --db " + db.string();
  // The first sweep, as the second sees it: its lock held, its pid inside.
  const std::string lock_path = db.string() + ".lock";
  const int fd = ::open(lock_path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
  ASSERT_GE(fd, 0);
  ASSERT_EQ(::flock(fd, LOCK_EX | LOCK_NB), 0);
  ASSERT_EQ(::write(fd, "4242\n", 5), 5);
  auto r = RunProgram(sweep);
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("another sweep (process 4242) is running on '" + db.string() +
                          "'; wait for it to finish"),
            std::string::npos)
      << r.output;
  ::close(fd);  // the first sweep is over
  r = RunProgram(sweep);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ(Count(db, "SELECT count(*) FROM runs WHERE status = 'ok'"), 2);
  EXPECT_FALSE(fs::exists(lock_path)) << "the lock is removed when the sweep ends";
  fs::remove_all(dir);
}

}  // namespace
}  // namespace swarmsim
