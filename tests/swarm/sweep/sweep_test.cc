// `swarmsim sweep`, `report` and `merge` as a user meets them: failures
// recorded while the sweep goes on, a sweep killed with SIGKILL and resumed
// with every run exactly once, a changed world refused, hashes equal to
// `run`, shards merged, MPI ranks giving the local results.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <sstream>
#include <string>
#include <thread>

#include "swarm/sweep/sqlite_db.h"
#include "tests/swarm/run_program.h"

namespace swarmsim {
namespace {

namespace fs = std::filesystem;

using Result = swarmsim::testing::CommandResult;
using swarmsim::testing::RunCommand;
using swarmsim::testing::RunProgram;

const std::string kWorld = std::string(SWARMSIM_SOURCE_DIR) + "/tests/data/sweep/sweep.yaml";

fs::path TempDir(const std::string& name) {
  const fs::path dir =
      fs::temp_directory_path() / ("swarmsim_sweep_" + name + "_" + std::to_string(getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

struct RunRow {
  std::string status, error, hash, finished_at;
  int64_t attempts = 0;
  std::map<std::string, std::string> params;
  uint64_t seed = 0;
};

std::map<int64_t, RunRow> ReadRuns(const fs::path& db_path) {
  SqliteDb db(db_path, /*read_only=*/true);
  std::map<int64_t, RunRow> runs;
  SqliteStatement q(&db,
                    "SELECT id, status, coalesce(error, ''), coalesce(state_hash, ''), attempts, "
                    "coalesce(finished_at, ''), seed FROM runs");
  while (q.Step())
    runs[q.Int(0)] = {
        q.Text(1), q.Text(2), q.Text(3), q.Text(5), q.Int(4), {}, static_cast<uint64_t>(q.Int(6))};
  SqliteStatement p(&db, "SELECT run, name, value FROM run_params");
  while (p.Step()) runs[p.Int(0)].params[p.Text(1)] = p.Text(2);
  return runs;
}

int64_t Count(const fs::path& db_path, const std::string& sql) {
  SqliteDb db(db_path, /*read_only=*/true);
  SqliteStatement q(&db, sql);
  return q.Step() ? q.Int(0) : -1;
}

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

// Starts `args` in a process group of its own with stdout and stderr to
// `log`; returns its pid.
pid_t StartInOwnGroup(const std::vector<std::string>& args, const fs::path& log) {
  fflush(nullptr);
  std::cout.flush();
  const pid_t pid = fork();
  if (pid == 0) {
    setpgid(0, 0);
    std::vector<char*> argv;
    for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);
    freopen(log.c_str(), "w", stdout);
    dup2(fileno(stdout), STDERR_FILENO);
    execv(argv[0], argv.data());
    _exit(127);
  }
  setpgid(pid, pid);  // (either side may win the race)
  return pid;
}

std::string ReadText(const fs::path& path) {
  std::ifstream f(path);
  std::ostringstream s;
  s << f.rdbuf();
  return s.str();
}

TEST(SweepTest, InterruptedBySignalSaysSoAndTheSameCommandResumes) {
  const fs::path dir = TempDir("sigint");
  const fs::path db = dir / "r.db";
  // 30 runs of ~0.1 s each on 2 jobs.
  const std::vector<std::string> args{
      SWARMSIM_BINARY, "sweep", kWorld,    "--param", "robots=2,3,4", "--param", "spin=100000",
      "--seeds",       "10",    "--steps", "20",      "--jobs",       "2",       "--db",
      db.string()};
  // Ctrl-C (SIGINT to the whole process group, runs included), then SIGTERM
  // to the sweep alone.
  const int64_t kTargets[] = {3, 10};
  const int kSignals[] = {SIGINT, SIGTERM};
  for (int round = 0; round < 2; ++round) {
    const fs::path log = dir / ("log" + std::to_string(round));
    const pid_t pid = StartInOwnGroup(args, log);
    ASSERT_GT(pid, 0);
    const auto give_up = std::chrono::steady_clock::now() + std::chrono::seconds(30);
    while (std::chrono::steady_clock::now() < give_up) {
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
      if (!fs::exists(db)) continue;
      try {
        if (Count(db, "SELECT count(*) FROM runs WHERE status = 'ok'") >= kTargets[round]) break;
      } catch (const std::exception&) {  // schema not created yet
      }
    }
    if (round == 0)
      kill(-pid, SIGINT);
    else
      kill(pid, SIGTERM);
    int status = 0;
    waitpid(pid, &status, 0);
    const std::string output = ReadText(log);
    ASSERT_TRUE(WIFEXITED(status)) << "killed by signal " << WTERMSIG(status) << ":\n" << output;
    EXPECT_EQ(WEXITSTATUS(status), 128 + kSignals[round]) << output;
    const std::string name = round == 0 ? "SIGINT" : "SIGTERM";
    EXPECT_NE(output.find("sweep: interrupted by " + name + ": "), std::string::npos) << output;
    EXPECT_NE(output.find(" of 30 runs done (0 failed)"), std::string::npos) << output;
    EXPECT_NE(output.find("Run the same command to resume"), std::string::npos) << output;
    // The runs the signal cut short are not failures: they run again on resume.
    EXPECT_EQ(Count(db, "SELECT count(*) FROM runs WHERE status = 'failed'"), 0) << output;
    EXPECT_LT(Count(db, "SELECT count(*) FROM runs WHERE status = 'ok'"), 30)
        << "the sweep ended before the signal; make it longer";
  }
  std::string cmd;
  for (const std::string& a : args) cmd += a + " ";
  Result r = RunCommand(cmd);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ(Count(db, "SELECT count(*) FROM runs WHERE status = 'ok'"), 30);
  fs::remove_all(dir);
}

TEST(SweepTest, KilledWithSigkillAndResumedEveryRunExactlyOnce) {
  const fs::path dir = TempDir("kill");
  const fs::path db = dir / "r.db";
  // 30 runs of ~20 ms each on 2 jobs.
  const std::vector<std::string> args{
      SWARMSIM_BINARY, "sweep",    kWorld,    "--param", "robots=2,3,4", "--param", "spin=20000",
      "--seeds",       "10",       "--steps", "20",      "--jobs",       "2",       "--quiet",
      "--db",          db.string()};
  std::map<int64_t, RunRow> before;
  for (int kill_round = 0; kill_round < 3; ++kill_round) {
    fflush(nullptr);
    std::cout.flush();
    const pid_t pid = fork();
    ASSERT_GE(pid, 0);
    if (pid == 0) {
      std::vector<char*> argv;
      for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
      argv.push_back(nullptr);
      freopen("/dev/null", "w", stdout);
      freopen("/dev/null", "w", stderr);
      execv(argv[0], argv.data());
      _exit(127);
    }
    // Wait until a few more runs have finished, then kill without warning.
    const int64_t target = 4 + 6 * kill_round;
    const auto give_up = std::chrono::steady_clock::now() + std::chrono::seconds(20);
    while (std::chrono::steady_clock::now() < give_up) {
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
      if (!fs::exists(db)) continue;
      try {
        if (Count(db, "SELECT count(*) FROM runs WHERE status = 'ok'") >= target) break;
      } catch (const std::exception&) {  // schema not created yet
      }
    }
    kill(pid, SIGKILL);
    int status = 0;
    waitpid(pid, &status, 0);
    ASSERT_TRUE(WIFSIGNALED(status)) << "the sweep ended before it was killed; make it longer";
    const auto now = ReadRuns(db);
    ASSERT_EQ(now.size(), 30u);
    // Runs finished before are untouched by the later rounds (not run again).
    for (const auto& [id, run] : before)
      if (run.status == "ok") {
        EXPECT_EQ(now.at(id).status, "ok");
        EXPECT_EQ(now.at(id).finished_at, run.finished_at) << id;
        EXPECT_EQ(now.at(id).attempts, run.attempts) << id;
      }
    before = now;
  }
  int64_t interrupted = 0;
  for (const auto& [id, run] : before) interrupted += run.status == "running";

  // The same command again finishes the sweep.
  std::string cmd;
  for (const std::string& a : args) cmd += a + " ";
  Result r = RunCommand(cmd);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const auto after = ReadRuns(db);
  ASSERT_EQ(after.size(), 30u);
  std::map<std::pair<std::string, uint64_t>, int> seen;  // (robots, seed) -> times
  for (const auto& [id, run] : after) {
    EXPECT_EQ(run.status, "ok") << id << ": " << run.error;
    ++seen[{run.params.at("robots"), run.seed}];
    if (before.at(id).status == "ok") {
      EXPECT_EQ(run.finished_at, before.at(id).finished_at) << "run " << id << " was repeated";
      EXPECT_EQ(run.hash, before.at(id).hash);
    }
  }
  EXPECT_EQ(seen.size(), 30u);
  for (const auto& [point, times] : seen) EXPECT_EQ(times, 1);
  EXPECT_EQ(Count(db, "SELECT count(*) FROM final_metrics WHERE metric = 'x'"), 30);
  EXPECT_EQ(Count(db, "SELECT count(DISTINCT run) FROM series"), 30);
  std::cout << "interrupted runs re-run: " << interrupted << "\n";
  fs::remove_all(dir);
}

TEST(SweepTest, SameSeedSameHashAsRunAndChangedWorldIsRefused) {
  const fs::path dir = TempDir("hash");
  for (const char* f : {"sweep.yaml", "bot.yaml", "bot.lua"})
    fs::copy_file(fs::path(SWARMSIM_SOURCE_DIR) / "tests/data/sweep" / f, dir / f);
  const std::string world = (dir / "sweep.yaml").string();
  const fs::path db = dir / "r.db";
  Result r = RunProgram("sweep " + world +
                        " --param robots=2,5 --seeds 3-4 --steps 12 --quiet --db " + db.string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const auto runs = ReadRuns(db);
  ASSERT_EQ(runs.size(), 4u);
  for (const auto& [id, run] : runs) {
    Result single =
        RunProgram("run " + world + " --set robots=" + run.params.at("robots") + " --seed " +
                   std::to_string(run.seed) + " --steps 12 --threads 2 --hash --quiet");
    const size_t at = single.output.find("state-hash: ");
    ASSERT_NE(at, std::string::npos) << single.output;
    EXPECT_EQ(single.output.substr(at + 12, 16), run.hash) << "run " << id;
  }
  // A finished sweep run again does nothing.
  r = RunProgram("sweep " + world + " --param robots=2,5 --seeds 3-4 --steps 12 --db " +
                 db.string());
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("4 already finished, 0 to run"), std::string::npos) << r.output;
  // Another grid on the same database is refused.
  r = RunProgram("sweep " + world + " --param robots=2,6 --seeds 3-4 --steps 12 --db " +
                 db.string());
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("another sweep"), std::string::npos) << r.output;
  // An edited world file is refused unless asked.
  std::ofstream(world, std::ios::app) << "# edited\n";
  r = RunProgram("sweep " + world + " --param robots=2,5 --seeds 3-4 --steps 12 --db " +
                 db.string());
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("has changed since this sweep began"), std::string::npos) << r.output;
  r = RunProgram("sweep " + world + " --param robots=2,5 --seeds 3-4 --steps 12 " +
                 "--allow-changed-world --db " + db.string());
  EXPECT_EQ(r.exit_code, 0) << r.output;
  // A misspelt parameter is one clear error before any run.
  r = RunProgram("sweep " + world + " --param robtos=2 --db " + (dir / "typo.db").string());
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("robots"), std::string::npos) << r.output;
  fs::remove_all(dir);
}

TEST(SweepTest, MalformedSeedsAreClearErrorsNamingTheOptionAndTheValue) {
  const fs::path dir = TempDir("seeds");
  const fs::path db = dir / "r.db";
  // --seeds SPEC -> what the message must say after "error: --seeds SPEC: ".
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"18446744073709551616",
       "the number of seeds K must be 1 to 10^6, got '18446744073709551616'"},
      {"1-18446744073709551616",
       "'18446744073709551616' is not a seed (a whole number from 0 to 18446744073709551615)"},
      {"5-3", "a seed range A-B needs A <= B (got 5 > 3)"},
      {"1,,2", "empty seed in the list"},
      {"-1", "'-1' is not a seed (a whole number from 0 to 18446744073709551615)"},
      {"1.5", "expected K (seeds 1..K), a range A-B or a list A,B,C, got '1.5'"},
  };
  for (const auto& [spec, message] : cases) {
    Result r = RunProgram("sweep " + kWorld + " --seeds " + spec + " --steps 1 --quiet --db " +
                          db.string());
    EXPECT_EQ(r.exit_code, 2) << spec << ": " << r.output;
    EXPECT_NE(r.output.find("error: --seeds " + spec + ": " + message), std::string::npos)
        << r.output;
    EXPECT_FALSE(fs::exists(db)) << spec;
  }
  fs::remove_all(dir);
}

TEST(SweepTest, ReportTableCsvColumnsAndPlot) {
  const fs::path dir = TempDir("report");
  const fs::path db = dir / "r.db";
  Result r = RunProgram("sweep " + kWorld + " --param robots=2,4 --param fail_at=-1,0.3 " +
                        "--seeds 3 --steps 8 --quiet --db " + db.string());
  ASSERT_EQ(r.exit_code, 1) << r.output;  // the fail_at=0.3 runs fail, as planned
  const fs::path csv = dir / "runs.csv", png = dir / "plot.png";
  r = RunProgram("report " + db.string() + " --x robots --by fail_at --y x --csv " + csv.string() +
                 (RunCommand("command -v gnuplot").exit_code == 0 ? " --plot " + png.string()
                                                                  : std::string()));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  // Reading leaves nothing beside the database (no empty -wal/-shm files).
  EXPECT_FALSE(fs::exists(db.string() + "-wal"));
  EXPECT_FALSE(fs::exists(db.string() + "-shm"));
  EXPECT_NE(r.output.find("12 of 12 runs finished, 6 failed"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("ci95_low"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("planned failure"), std::string::npos) << r.output;
  std::ifstream f(csv);
  std::string header, line;
  std::getline(f, header);
  EXPECT_EQ(header,
            "run,point,seed,status,robots,fail_at,steps,wall_s,state_hash,error,"
            "mean_nearest_neighbor_distance,x");
  int rows = 0, failed = 0;
  while (std::getline(f, line)) {
    ++rows;
    // Runs are numbered from 1, in the CSV as in the database.
    EXPECT_EQ(line.substr(0, line.find(',')), std::to_string(rows)) << line;
    failed += line.find(",failed,") != std::string::npos;
  }
  EXPECT_EQ(rows, 12);
  EXPECT_EQ(failed, 6);
  if (fs::exists(png)) {
    std::ifstream p(png, std::ios::binary);
    char magic[8] = {};
    p.read(magic, 8);
    EXPECT_EQ(std::string(magic + 1, 3), "PNG");
  } else {
    std::cout << "gnuplot not installed: plot not checked\n";
  }
  r = RunProgram("report " + db.string() + " --by nosuch");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  fs::remove_all(dir);
}

TEST(SweepTest, ReportListsTheValidNamesAndSuggestsTheNearest) {
  const fs::path dir = TempDir("report_names");
  const fs::path db = dir / "r.db";
  Result r = RunProgram("sweep " + kWorld + " --param robots=2,3 --param fail_at=-1 " +
                        "--steps 4 --quiet --db " + db.string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  r = RunProgram("report " + db.string() + " --y mnnd");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("no run recorded metric 'mnnd' (the metrics recorded: "
                          "mean_nearest_neighbor_distance, x)"),
            std::string::npos)
      << r.output;
  r = RunProgram("report " + db.string() + " --y mean_nearest_neighbour_distance");
  EXPECT_NE(r.output.find("no run recorded metric 'mean_nearest_neighbour_distance' (the metrics "
                          "recorded: mean_nearest_neighbor_distance, x); did you mean "
                          "'mean_nearest_neighbor_distance'?"),
            std::string::npos)
      << r.output;
  r = RunProgram("report " + db.string() + " --x robts");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("'robts' is not a parameter of this sweep (its parameters: robots, "
                          "fail_at); did you mean 'robots'?"),
            std::string::npos)
      << r.output;
  r = RunProgram("report " + db.string() + " --by seed");
  EXPECT_NE(r.output.find("'seed' is not a parameter of this sweep (its parameters: robots, "
                          "fail_at)"),
            std::string::npos)
      << r.output;
  fs::remove_all(dir);
}

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

TEST(SweepTest, MpiTwoRanksGiveTheLocalResults) {
  if (RunCommand("command -v mpirun").exit_code != 0)
    GTEST_SKIP() << "mpirun not found (install openmpi-bin): MPI sweep not tested";
  const fs::path dir = TempDir("mpi");
  const std::string grid = " --param robots=2,3 --seeds 3 --steps 8 --quiet ";
  ASSERT_EQ(RunProgram("sweep " + kWorld + grid + "--db " + (dir / "local.db").string()).exit_code,
            0);
  Result r = RunCommand("mpirun --allow-run-as-root --oversubscribe -np 2 " +
                        std::string(SWARMSIM_BINARY) + " sweep " + kWorld + grid + "--mpi --db " +
                        (dir / "mpi.db").string());
  if (r.output.find("built without MPI") != std::string::npos)
    GTEST_SKIP() << "swarmsim built without MPI";
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const auto local = ReadRuns(dir / "local.db"), mpi = ReadRuns(dir / "mpi.db");
  ASSERT_EQ(mpi.size(), local.size());
  for (const auto& [id, run] : local) {
    EXPECT_EQ(mpi.at(id).status, "ok");
    EXPECT_EQ(mpi.at(id).hash, run.hash) << id;
  }
  EXPECT_EQ(Count(dir / "mpi.db", "SELECT count(DISTINCT worker) FROM runs"), 2);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace swarmsim
