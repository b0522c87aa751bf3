// The results database of a sweep (swarm/sweep/results_db.cc): the sweep's
// record and its runs as created, runs claimed and completed with their
// metrics, interrupted and failed runs put back to pending.
#include "swarm/sweep/results_db.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "framework/error.h"
#include "swarm/sweep/grid.h"
#include "swarm/sweep/sqlite_db.h"
#include "tests/swarm/sweep/sweep_db.h"

namespace swarmsim {
namespace {

namespace fs = std::filesystem;
using sweep_testing::Count;
using sweep_testing::ReadRuns;
using sweep_testing::TempDir;

const SweepRecord kRecord{"worlds/w.yaml",
                          "0123456789abcdef",
                          R"({"params":[]})",
                          "2026-01-02T03:04:05Z",
                          "9.9.9",
                          "swarmsim sweep worlds/w.yaml"};

// robots=2,3 x seeds 7,8: runs 1..4.
std::vector<GridRun> Runs() { return ExpandGrid({ParseParamSpec("robots=2,3")}, {7, 8}); }

TEST(ResultsDbTest, ASweepIsItsRecordAndOnePendingRunPerGridRun) {
  const fs::path dir = TempDir("results_create");
  const fs::path file = dir / "r.db";
  {
    ResultsDb db(file);
    EXPECT_FALSE(db.ReadSweep().has_value()) << "a new database holds no sweep";
    db.CreateSweep(kRecord, Runs());
    const auto record = db.ReadSweep();
    ASSERT_TRUE(record.has_value());
    EXPECT_EQ(record->world_path, kRecord.world_path);
    EXPECT_EQ(record->world_hash, kRecord.world_hash);
    EXPECT_EQ(record->space_json, kRecord.space_json);
    EXPECT_EQ(record->started_at, kRecord.started_at);
    EXPECT_EQ(record->version, kRecord.version);
    EXPECT_EQ(record->command, kRecord.command);
    const RunCounts c = db.Counts();
    EXPECT_EQ(c.total, 4);
    EXPECT_EQ(c.pending, 4);
    EXPECT_EQ(c.running + c.ok + c.failed, 0);
    const std::vector<GridRun> pending = db.PendingRuns();
    const std::vector<GridRun> expected = Runs();
    ASSERT_EQ(pending.size(), expected.size());
    for (size_t i = 0; i < pending.size(); ++i) {
      EXPECT_EQ(pending[i].id, expected[i].id);
      EXPECT_EQ(pending[i].point, expected[i].point);
      EXPECT_EQ(pending[i].seed, expected[i].seed);
      EXPECT_EQ(pending[i].params, expected[i].params);
    }
  }
  // What other readers see (report, Python): the parameters as rows, too.
  const auto runs = ReadRuns(file);
  ASSERT_EQ(runs.size(), 4u);
  EXPECT_EQ(runs.at(3).params.at("robots"), "3");
  EXPECT_EQ(runs.at(3).seed, 7u);
  EXPECT_EQ(runs.at(3).status, "pending");
  // A read-only reader of a database that holds no sweep learns so.
  { SqliteDb other(dir / "other.db"); }
  ResultsDb reader(dir / "other.db", /*read_only=*/true);
  EXPECT_FALSE(reader.ReadSweep().has_value());
  fs::remove_all(dir);
}

// A sweep's database from before runs recorded their world file gains the
// column when a sweep opens it; runs completed then record the file's hash.
TEST(ResultsDbTest, AnOlderDatabaseGainsEachRunsWorldHash) {
  const fs::path dir = TempDir("results_older");
  const fs::path file = dir / "r.db";
  {
    ResultsDb db(file);
    db.CreateSweep(kRecord, Runs());
    db.db().Exec("ALTER TABLE runs DROP COLUMN world_hash");  // as an older version made it
  }
  ResultsDb db(file);
  EXPECT_EQ(Count(file, "SELECT count(*) FROM pragma_table_info('runs') WHERE name = 'world_hash'"),
            1);
  EXPECT_EQ(db.WorldVersions(), 0) << "no run finished yet";
  RunOutcome first;
  first.id = 1;
  first.ok = true;
  db.Complete(first);  // no hash given: counted as the sweep's
  db.set_run_world_hash(kRecord.world_hash);
  first.id = 2;
  db.Complete(first);
  EXPECT_EQ(db.WorldVersions(), 1);
  db.set_run_world_hash("00000000000000ff");
  first.id = 3;
  db.Complete(first);
  EXPECT_EQ(db.WorldVersions(), 2);
  EXPECT_EQ(Count(file, "SELECT count(*) FROM runs WHERE world_hash = '00000000000000ff'"), 1);
  EXPECT_EQ(db.CountFailed(1, 0), 0);
}

TEST(ResultsDbTest, CompletedRunsKeepTheirOutcomeMetricsAndSeries) {
  const fs::path dir = TempDir("results_complete");
  const fs::path file = dir / "r.db";
  ResultsDb db(file);
  db.CreateSweep(kRecord, Runs());
  db.Claim(1, "host:1");
  db.Claim(2, "host:2");
  db.Claim(2, "host:3");  // no longer pending: not claimed again
  EXPECT_EQ(db.Counts().running, 2);
  EXPECT_EQ(db.PendingRuns().front().id, 3);
  RunOutcome ok;
  ok.id = 1;
  ok.ok = true;
  ok.wall_s = 0.5;
  ok.steps = 10;
  ok.robots = 2;
  ok.state_hash = "00000000000000aa";
  ok.final_metrics = {{"x", 1.5}, {"y", -2}};
  ok.series = {{"x", 1, 0.1, 1.0}, {"x", 2, 0.2, 1.5}};
  db.Complete(ok);
  RunOutcome failed;
  failed.id = 2;
  failed.error = "bot.lua:13: planned failure";
  failed.steps = 3;
  failed.state_hash = "";
  failed.final_metrics = {{"x", 0.25}};
  failed.series = {{"x", 1, 0.1, 0.25}};
  db.Complete(failed);
  const RunCounts c = db.Counts();
  EXPECT_EQ(c.ok, 1);
  EXPECT_EQ(c.failed, 1);
  EXPECT_EQ(c.pending, 2);
  const auto runs = ReadRuns(file);
  EXPECT_EQ(runs.at(1).status, "ok");
  EXPECT_EQ(runs.at(1).hash, "00000000000000aa");
  EXPECT_EQ(runs.at(1).error, "");
  EXPECT_EQ(runs.at(1).attempts, 1);
  EXPECT_NE(runs.at(1).finished_at, "");
  EXPECT_EQ(runs.at(2).status, "failed");
  EXPECT_EQ(runs.at(2).error, "bot.lua:13: planned failure");
  EXPECT_EQ(runs.at(2).hash, "");
  EXPECT_EQ(runs.at(2).attempts, 1) << "claimed once";
  EXPECT_EQ(Count(file, "SELECT count(*) FROM final_metrics WHERE run = 1"), 2);
  EXPECT_EQ(Count(file, "SELECT count(*) FROM series WHERE run = 1"), 2);
  EXPECT_EQ(Count(file, "SELECT value * 100 FROM final_metrics WHERE run = 1 AND metric = 'x'"),
            150);
  EXPECT_EQ(Count(file, "SELECT worker = 'host:1' FROM runs WHERE id = 1"), 1);
  // Completing a run again replaces its metrics, never adds to them.
  ok.final_metrics = {{"x", 2.0}};
  ok.series = {{"x", 1, 0.1, 2.0}};
  db.Complete(ok);
  EXPECT_EQ(Count(file, "SELECT count(*) FROM final_metrics WHERE run = 1"), 1);
  EXPECT_EQ(Count(file, "SELECT count(*) FROM series WHERE run = 1"), 1);
  fs::remove_all(dir);
}

TEST(ResultsDbTest, InterruptedAndFailedRunsGoBackToPending) {
  const fs::path dir = TempDir("results_reset");
  const fs::path file = dir / "r.db";
  ResultsDb db(file);
  db.CreateSweep(kRecord, Runs());
  for (int64_t id = 1; id <= 4; ++id) db.Claim(id, "host:1");
  RunOutcome failed;
  failed.id = 1;
  failed.error = "timed out after 1 s (--timeout)";
  failed.final_metrics = {{"x", 1}};
  failed.series = {{"x", 1, 0.1, 1}};
  db.Complete(failed);
  RunOutcome ok;
  ok.id = 2;
  ok.ok = true;
  ok.final_metrics = {{"x", 2}};
  db.Complete(ok);
  // Runs 3 and 4 were running when the sweep was killed.
  EXPECT_EQ(db.ResetInterrupted(), 2);
  EXPECT_EQ(db.ResetInterrupted(), 0);
  EXPECT_EQ(db.Counts().pending, 2);
  EXPECT_EQ(db.ResetFailed(), 1);
  const RunCounts c = db.Counts();
  EXPECT_EQ(c.pending, 3);
  EXPECT_EQ(c.ok, 1);
  EXPECT_EQ(c.failed, 0);
  // A failed run's error and results go with it; the finished run keeps its own.
  EXPECT_EQ(ReadRuns(file).at(1).error, "");
  EXPECT_EQ(Count(file, "SELECT count(*) FROM final_metrics WHERE run = 1"), 0);
  EXPECT_EQ(Count(file, "SELECT count(*) FROM series WHERE run = 1"), 0);
  EXPECT_EQ(Count(file, "SELECT count(*) FROM final_metrics WHERE run = 2"), 1);
  // Claimed again, a run counts its attempts.
  db.Claim(1, "host:2");
  EXPECT_EQ(ReadRuns(file).at(1).attempts, 2);
  fs::remove_all(dir);
}

// --db naming another program's database is refused before anything is
// written to it (QA: the sweep's tables and WAL mode were added first); a
// sweep's own, and an empty file, open.
TEST(ResultsDbTest, ADatabaseOfSomethingElseIsRefusedUntouched) {
  const fs::path dir = TempDir("results_foreign");
  const fs::path other = dir / "other.db";
  {
    SqliteDb db(other);
    db.Exec("PRAGMA journal_mode=DELETE");
    db.Exec("CREATE TABLE measurements (x REAL)");
  }
  const auto before = fs::file_size(other);
  try {
    ResultsDb db(other);
    ADD_FAILURE() << "opened";
  } catch (const Error& e) {
    EXPECT_EQ(std::string(e.what()),
              "database '" + other.string() +
                  "' is not a sweep's (it holds the tables measurements): name a new file for "
                  "--db, or one a sweep made");
  }
  EXPECT_EQ(fs::file_size(other), before);
  EXPECT_FALSE(fs::exists(dir / "other.db-wal"));
  EXPECT_EQ(Count(other, "SELECT count(*) FROM sqlite_master WHERE name = 'sweep'"), 0);
  {
    ResultsDb db(dir / "r.db");
    db.CreateSweep(kRecord, Runs());
  }
  EXPECT_NO_THROW(ResultsDb(dir / "r.db"));
  std::ofstream(dir / "empty.db").flush();
  EXPECT_NO_THROW(ResultsDb(dir / "empty.db"));
  fs::remove_all(dir);
}

TEST(ResultsDbTest, UtcNowIsIso8601) {
  const std::string now = UtcNow();
  ASSERT_EQ(now.size(), 20u) << now;
  EXPECT_EQ(now[4], '-');
  EXPECT_EQ(now[10], 'T');
  EXPECT_EQ(now[19], 'Z');
  EXPECT_GE(now, "2024-01-01T00:00:00Z");
}

}  // namespace
}  // namespace swarmsim
