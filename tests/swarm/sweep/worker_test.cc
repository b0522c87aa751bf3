// Runs of a sweep as worker processes (swarm/sweep/worker.cc): a run that
// fails or times out is recorded with its message and the sweep goes on.
#include "swarm/sweep/worker.h"

#include <gtest/gtest.h>
#include <signal.h>
#include <sys/resource.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <string>
#include <vector>

#include "framework/sanitizers.h"
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

TEST(SweepTest, FailedRunsAndTimeoutsAreRecordedAndTheSweepGoesOn) {
  const fs::path dir = TempDir("fail");
  const fs::path db = dir / "r.db";
  // fail_at=0.2: a Lua error at t = 0.2 s; spin=1e9: far past the 1 s limit.
  Result r = RunProgram("sweep " + kWorld + " --param fail_at=-1,0.2 --param spin=0,1000000000 " +
                        "--seeds 2 --steps 10 --jobs 2 --timeout 1 --db " + db.string());
  // Every run is attempted; failures make the exit status 1, after the summary.
  ASSERT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find("sweep: 2 ok, 6 failed, 0 not run, of 8 runs"), std::string::npos)
      << r.output;
  EXPECT_NE(r.output.find("6 runs failed or timed out (exit status 1)"), std::string::npos)
      << r.output;
  const auto runs = ReadRuns(db);
  ASSERT_EQ(runs.size(), 8u);
  int ok = 0, lua = 0, timeout = 0;
  for (const auto& [id, run] : runs) {
    if (run.status == "ok") {
      ++ok;
      EXPECT_EQ(run.params.at("fail_at"), "-1");
      EXPECT_EQ(run.params.at("spin"), "0");
      EXPECT_EQ(run.hash.size(), 16u);
    } else {
      ASSERT_EQ(run.status, "failed") << id;
      if (run.error.find("timed out") != std::string::npos) ++timeout;
      if (run.error.find("bot.lua:13: planned failure") != std::string::npos) ++lua;
    }
  }
  EXPECT_EQ(ok, 2);
  EXPECT_EQ(lua, 2);      // fail_at=0.2, spin=0
  EXPECT_EQ(timeout, 4);  // spin=1e9: the first step never ends, fail_at or not
  EXPECT_EQ(Count(db,
                  "SELECT count(*) FROM final_metrics JOIN runs ON id = run "
                  "WHERE metric = 'x' AND status = 'ok'"),
            2);
  // The same command on the finished sweep runs nothing and still says it failed.
  r = RunProgram("sweep " + kWorld + " --param fail_at=-1,0.2 --param spin=0,1000000000 " +
                 "--seeds 2 --steps 10 --jobs 2 --timeout 1 --quiet --db " + db.string());
  EXPECT_EQ(r.exit_code, 1) << r.output;
  fs::remove_all(dir);
}

// Runs the machine fails (here: no thread can be started, as under a
// process limit; a full $TMPDIR is the other common case) stop the sweep
// with the runs' own message, and none is recorded as failed: a full
// TMPDIR marked every run of the grid failed in seconds, each "exit status
// 1" (the message went to a stderr.txt on the full disk). The same command
// resumes once the machine is mended.
TEST(SweepTest, RunsTheMachineFailsStopTheSweepAndResumeLater) {
  if (kAddressSanitizer) GTEST_SKIP() << "ulimit -v stops ASan builds before main";
  rlimit stack{};
  if (getrlimit(RLIMIT_STACK, &stack) != 0 ||
      (stack.rlim_max != RLIM_INFINITY && stack.rlim_max < 4000000ull * 1024))
    GTEST_SKIP() << "the hard stack limit is below 4 GB";
  const fs::path dir = TempDir("machine");
  const fs::path db = dir / "r.db";
  const std::string sweep = std::string(SWARMSIM_BINARY) + " sweep " + kWorld +
                            " --param fail_at=-1 --seeds 4 --steps 3 --jobs 2 --db " + db.string();
  // glibc gives each thread a stack of ulimit -s: 4 GB, in 3 GB of room.
  Result r = RunCommand("ulimit -s 4000000 && ulimit -v 3000000 && " + sweep);
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find("could not run on this machine, and the next ones would not either: "
                          "cannot start a thread for the run's watchdog"),
            std::string::npos)
      << r.output;
  EXPECT_NE(r.output.find("It is not recorded as failed"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("0 failed"), std::string::npos) << r.output;
  for (const auto& [id, run] : ReadRuns(db)) EXPECT_NE(run.status, "failed") << id;
  r = RunCommand(sweep);
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("sweep: 4 ok, 0 failed, 0 not run, of 4 runs"), std::string::npos)
      << r.output;
  fs::remove_all(dir);
}

// The database's disk full (here: a file size limit, its signal ignored,
// so that writes fail with EFBIG as on a full disk) ends the sweep with
// the database's error and how to go on; the same command resumes it, and
// no run is lost or counted twice.
TEST(SweepTest, ADatabaseThatCannotGrowSaysTheSweepResumes) {
  const fs::path dir = TempDir("db_full");
  const fs::path db = dir / "r.db";
  const std::string sweep = std::string(SWARMSIM_BINARY) + " sweep " + kWorld +
                            " --param robots=3,4 --seeds 10 --steps 10 --jobs 1 --quiet --db " +
                            db.string();
  // 200 blocks: the new database (~50 KB with its log) fits, its runs' commits do not.
  Result r = RunCommand("trap '' XFSZ; ulimit -f 200 && " + sweep);
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("error: database '" + db.string() + "': "), std::string::npos)
      << r.output;
  // SQLite says only "disk I/O error": the limit is named (dash's ulimit
  // counts blocks of 512 bytes).
  EXPECT_NE(r.output.find("this process may write no file past 102400 bytes: its file size "
                          "limit, `ulimit -f`)"),
            std::string::npos)
      << r.output;
  EXPECT_NE(r.output.find("the runs finished before it are kept in the database: mend this and "
                          "run the same command to resume"),
            std::string::npos)
      << r.output;
  r = RunCommand(sweep);
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("sweep: 20 ok, 0 failed, 0 not run, of 20 runs"), std::string::npos)
      << r.output;
  EXPECT_EQ(ReadRuns(db).size(), 20u);
  fs::remove_all(dir);
}

GridRun Run5() {
  GridRun run;
  run.id = 5;
  run.seed = 7;
  run.params = {{"robots", "5"}, {"bot.speed", "0.1"}};
  return run;
}

TEST(WorkerTest, ARunIsTheRunCommandWithItsSeedAndParameters) {
  WorkerConfig config;
  config.world = "worlds/w.yaml";
  config.steps = 12;
  config.threads_per_run = 2;
  EXPECT_EQ(RunArguments(config, Run5(), "/tmp/run-5"),
            (std::vector<std::string>{"run", "worlds/w.yaml", "--seed", "7", "--set", "robots=5",
                                      "--set", "bot.speed=0.1", "--steps", "12", "--threads", "2",
                                      "--quiet", "--out", "/tmp/run-5"}));
  // A duration when no steps are given, as `run` reads it back; neither: the world's own.
  config.steps.reset();
  config.duration = 2.5;
  const auto with_duration = RunArguments(config, Run5(), "/tmp/run-5");
  EXPECT_EQ(with_duration[8], "--duration");
  EXPECT_EQ(with_duration[9], "2.5");
  config.duration.reset();
  config.max_memory = "2147483648";  // the sweep's share or --max-memory, passed on
  const auto capped = RunArguments(config, Run5(), "/tmp/run-5");
  const auto cap = std::find(capped.begin(), capped.end(), "--max-memory");
  ASSERT_NE(cap, capped.end());
  EXPECT_EQ(*(cap + 1), "2147483648");
  config.max_memory.clear();
  const auto own_length = RunArguments(config, Run5(), "/tmp/run-5");
  EXPECT_EQ(std::count(own_length.begin(), own_length.end(), "--steps") +
                std::count(own_length.begin(), own_length.end(), "--duration"),
            0);
}

// A run folder as `run --out` leaves it.
fs::path RunFolder(const std::string& name, const std::string& summary, const std::string& metrics,
                   const std::string& stderr_text = "") {
  const fs::path dir = TempDir("worker_" + name);
  if (!summary.empty()) std::ofstream(dir / "summary.json") << summary;
  if (!metrics.empty()) std::ofstream(dir / "metrics.csv") << metrics;
  if (!stderr_text.empty()) std::ofstream(dir / "stderr.txt") << stderr_text;
  return dir;
}

// What the run wrote on stderr (the pool reads it from a pipe).
std::string StderrOf(const fs::path& dir) {
  std::ifstream in(dir / "stderr.txt");
  return std::string(std::istreambuf_iterator<char>(in), {});
}

constexpr int kExited0 = 0;  // waitpid statuses: exit code << 8, or the signal
constexpr int Exited(int code) { return code << 8; }

TEST(WorkerTest, AFinishedRunIsItsSummaryAndItsMetricsMeanOverRobots) {
  const fs::path dir = RunFolder(
      "ok", R"({"status": "ok", "steps": 2, "robots": 2, "state_hash": "00000000000000aa"})",
      "step,time,robot,metric,value\n"
      "1,0.1,bot#0,x,1\n1,0.1,bot#1,x,3\n1,0.1,,mnnd,0.5\n"
      "2,0.2,bot#0,x,2\n2,0.2,bot#1,x,6\n2,0.2,,mnnd,0.75\n");
  const RunOutcome o = CollectRun(5, dir, StderrOf(dir), kExited0, false, 0);
  EXPECT_EQ(o.id, 5);
  EXPECT_TRUE(o.ok) << o.error;
  EXPECT_EQ(o.steps, 2);
  EXPECT_EQ(o.robots, 2);
  EXPECT_EQ(o.state_hash, "00000000000000aa");
  EXPECT_EQ(o.final_metrics.at("x"), 4);  // step 2: (2 + 6) / 2
  EXPECT_EQ(o.final_metrics.at("mnnd"), 0.75);
  ASSERT_EQ(o.series.size(), 4u);
  std::map<std::pair<std::string, int64_t>, double> series;
  for (const SeriesPoint& p : o.series) series[{p.metric, p.step}] = p.value;
  EXPECT_EQ((series[{"x", 1}]), 2);
  EXPECT_EQ((series[{"mnnd", 1}]), 0.5);
  fs::remove_all(dir);
}

// Values at the ends of the doubles: a subnormal one (std::stod's
// out_of_range) was dropped, so the "final" value was an earlier step's;
// two robots of 1.5e308 each had the mean inf. Infinities and NaNs
// recorded stay what they were.
TEST(WorkerTest, SubnormalAndHugeValuesAreMetricsLikeAnyOther) {
  const fs::path dir = RunFolder("extremes", R"({"status": "ok", "steps": 2, "robots": 2})",
                                 "step,time,robot,metric,value\n"
                                 "0,0,,decay,8.900295434e-308\n"
                                 "1,0.1,,decay,8.094771541e-320\n"
                                 "1,0.1,bot#0,near_max,1.5e+308\n1,0.1,bot#1,near_max,1.5e+308\n"
                                 "1,0.1,bot#0,mixed,1.5e+308\n1,0.1,bot#1,mixed,inf\n"
                                 "1,0.1,,gone,1e999\n");
  const RunOutcome o = CollectRun(1, dir, StderrOf(dir), kExited0, false, 0);
  EXPECT_TRUE(o.ok) << o.error;
  EXPECT_EQ(o.final_metrics.at("decay"), 8.094771541e-320) << "the last step's";
  EXPECT_EQ(o.series.size(), 4u);  // decay at steps 0 and 1, near_max, mixed
  EXPECT_EQ(o.final_metrics.at("near_max"), 1.5e308);
  EXPECT_EQ(o.final_metrics.at("mixed"), INFINITY);
  EXPECT_FALSE(o.final_metrics.contains("gone")) << "past the largest double: no number";
  fs::remove_all(dir);
}

// Metric names as metrics.csv quotes them: 'left,v' and 'right,v' were
// one metric 'v"' (their values averaged), a quote kept the CSV's quoting,
// and a name with a line break was lost.
TEST(WorkerTest, QuotedMetricNamesAreReadAsTheyWereRecorded) {
  const fs::path dir =
      RunFolder("quoted", R"({"status": "ok", "steps": 1, "robots": 1})",
                "step,time,robot,metric,value\n"
                "1,0.1,,\"left,v\",10\n1,0.1,,\"right,v\",20\n1,0.1,,\"c\"\"d\",3\n"
                "1,0.1,,\"new\nline\",7\n1,0.1,\"bot,#0\",plain,5\n");
  const RunOutcome o = CollectRun(1, dir, StderrOf(dir), kExited0, false, 0);
  EXPECT_TRUE(o.ok) << o.error;
  std::map<std::string, double> expected = {
      {"left,v", 10}, {"right,v", 20}, {"c\"d", 3}, {"new\nline", 7}, {"plain", 5}};
  EXPECT_EQ(o.final_metrics, expected);
  fs::remove_all(dir);
}

TEST(WorkerTest, ATornLastMetricsRowIsLeftOut) {
  // A run killed while writing (a timeout): the rows before the torn one
  // count, and the torn one adds no metric and no value.
  for (const std::string torn : {"3,0.3,bot#0,x,", "3,0.3,bot#0,x", "3,0.3,b"}) {
    const fs::path dir = RunFolder("torn", R"({"status": "running", "steps": 0})",
                                   "step,time,robot,metric,value\n"
                                   "1,0.1,bot#0,x,1\n2,0.2,bot#0,x,2\n" +
                                       torn);
    const RunOutcome o = CollectRun(1, dir, StderrOf(dir), SIGKILL, true, 1.5);
    EXPECT_EQ(o.final_metrics.size(), 1u) << torn;
    EXPECT_EQ(o.final_metrics.count("x"), 1u) << torn;
    if (o.final_metrics.count("x")) {
      EXPECT_EQ(o.final_metrics.at("x"), 2) << torn;
    }
    EXPECT_EQ(o.series.size(), 2u) << torn;
    fs::remove_all(dir);
  }
}

TEST(WorkerTest, AFailedRunSaysWhy) {
  const std::string summary_error =
      R"({"status": "error", "error": "bot.lua:13: planned failure", "steps": 2})";
  // The run's own error, from its summary.
  fs::path dir = RunFolder("error", summary_error, "", "noise\n");
  RunOutcome o = CollectRun(1, dir, StderrOf(dir), Exited(1), false, 0);
  EXPECT_FALSE(o.ok);
  EXPECT_EQ(o.error, "bot.lua:13: planned failure");
  EXPECT_EQ(o.steps, 2);
  fs::remove_all(dir);
  // Timed out: the limit, and no state hash (the state is not a final one).
  dir = RunFolder("timeout", R"({"status": "running", "state_hash": "00000000000000aa"})", "");
  o = CollectRun(1, dir, StderrOf(dir), SIGKILL, true, 1.5);
  EXPECT_FALSE(o.ok);
  EXPECT_EQ(o.error, "timed out after 1.5 s (--timeout)");
  EXPECT_EQ(o.state_hash, "");
  fs::remove_all(dir);
  // Crashed: the signal and the last three lines of its stderr.
  dir = RunFolder("crash", "", "", "one\n\ntwo\nthree\nfour\n");
  o = CollectRun(1, dir, StderrOf(dir), SIGSEGV, false, 0);
  EXPECT_EQ(o.error, "crashed: killed by signal " + std::to_string(SIGSEGV) + " (" +
                         strsignal(SIGSEGV) + "): two | three | four");
  fs::remove_all(dir);
  // No summary and nothing on stderr: the exit status; 127: not started.
  dir = RunFolder("status", "", "");
  EXPECT_EQ(CollectRun(1, dir, StderrOf(dir), Exited(3), false, 0).error, "exit status 3");
  EXPECT_EQ(CollectRun(1, dir, StderrOf(dir), Exited(127), false, 0).error,
            "cannot start the worker program");
  // Exit 0 without an ok summary is no success.
  EXPECT_EQ(CollectRun(1, dir, StderrOf(dir), kExited0, false, 0).error,
            "the run wrote no valid summary.json");
  std::ofstream(dir / "summary.json") << R"({"status": "ok", "steps": "many"})";
  o = CollectRun(1, dir, StderrOf(dir), kExited0, false, 0);
  EXPECT_TRUE(o.ok);
  EXPECT_EQ(o.steps, 0) << "a field of the wrong type is not read";
  std::ofstream(dir / "summary.json") << "{\"status\": \"ok\", trunc";
  EXPECT_EQ(CollectRun(1, dir, StderrOf(dir), kExited0, false, 0).error,
            "the run wrote no valid summary.json");
  fs::remove_all(dir);
  // Whatever bytes stderr held, the error is UTF-8 (it goes to SQLite and JSON).
  dir = RunFolder("bytes", "", "", "caf\xe9 au lait\n");
  EXPECT_EQ(CollectRun(1, dir, StderrOf(dir), Exited(1), false, 0).error,
            "caf\xef\xbf\xbd au lait");
  fs::remove_all(dir);
}

// A run the machine failed (its disk full, no thread or file to be had) is
// told apart from one the world failed: the sweep does not record it.
TEST(WorkerTest, ARunTheMachineFailedIsToldApart) {
  const fs::path dir = RunFolder("machine", "", "");
  const std::string full = "error: cannot write '/tmp/x/summary.json': No space left on device\n";
  RunOutcome o = CollectRun(1, dir, full, Exited(1), false, 0);
  EXPECT_FALSE(o.ok);
  EXPECT_TRUE(o.machine);
  EXPECT_NE(o.error.find("No space left on device"), std::string::npos) << o.error;
  EXPECT_TRUE(CollectRun(1, dir, "", Exited(127), false, 0).machine) << "not started";
  EXPECT_TRUE(CollectRun(1, dir, "error: cannot start a thread for the run's watchdog: x\n",
                         Exited(1), false, 0)
                  .machine);
  // The world's: a script's error, a crash or a timeout, whatever was said before.
  EXPECT_FALSE(CollectRun(1, dir, "bot.lua:13: planned failure\n", Exited(1), false, 0).machine);
  EXPECT_FALSE(CollectRun(1, dir, full, SIGSEGV, false, 0).machine);
  EXPECT_FALSE(CollectRun(1, dir, full, SIGKILL, true, 1).machine);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace swarmsim
