// The coordinator of a sweep (swarm/sweep/coordinator.cc): interrupted by a
// signal or killed, the same command resumes with every run exactly once; the
// hashes are those of `run`; another grid or an edited world is refused.
#include "swarm/sweep/coordinator.h"

#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "framework/error.h"
#include "swarm/sweep/grid.h"
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
  // Another world file on the database: named as another file, not as an edit.
  const fs::path other = fs::path(world).parent_path() / "other_world.yaml";
  fs::copy_file(world, other, fs::copy_options::overwrite_existing);
  std::ofstream(other, std::ios::app) << "# another\n";
  r = RunProgram("sweep " + other.string() + " --param robots=2,5 --seeds 3-4 --steps 12 --db " +
                 db.string());
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("holds a sweep of world file '" + world + "'"), std::string::npos)
      << r.output;
  EXPECT_NE(r.output.find("'" + other.string() + "' differs from it"), std::string::npos)
      << r.output;
  r = RunProgram("sweep " + world + " --param robots=2,5 --seeds 3-4 --steps 12 " +
                 "--allow-changed-world --db " + db.string());
  EXPECT_EQ(r.exit_code, 0) << r.output;
  // A misspelt parameter is one clear error before any run.
  r = RunProgram("sweep " + world + " --param robtos=2 --db " + (dir / "typo.db").string());
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("robots"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("error: --param robtos=2: no parameter 'robtos'"), std::string::npos)
      << "named as the user wrote it: " << r.output;
  r = RunProgram("sweep " + world + " --param robots=2 --param nosuch.x=1 --seeds 7 --db " +
                 (dir / "typo2.db").string());
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("error: --param nosuch.x=1: no model 'nosuch'"), std::string::npos)
      << r.output;
  // A first run whose world does not load (2,000 robots in 3 m x 3 m) is named.
  r = RunProgram("sweep " + world + " --param robots=2000,2 --seeds 2 --db " +
                 (dir / "crowded.db").string());
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("error: the sweep's first run (robots=2000, seed 1) does not load, so "
                          "the sweep does not start: "),
            std::string::npos)
      << r.output;
  // So is a value of the wrong type anywhere in the list, not only the first.
  const fs::path bad_db = dir / "bad_value.db";
  r = RunProgram("sweep " + world + " --param robots=2,abc --steps 2 --db " + bad_db.string());
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(
      r.output.find("--param robots=2,abc: parameter 'robots' is a finite number, got \"abc\""),
      std::string::npos)
      << r.output;
  EXPECT_FALSE(fs::exists(bad_db)) << "no database for a sweep refused up front";
  fs::remove_all(dir);
}

// A sweep resumed with --allow-changed-world keeps its first world hash, so
// the original file resumes it again without the flag; each run records the
// world it ran and `report` says the runs mixed two versions.
TEST(SweepTest, AllowedChangedWorldKeepsTheSweepsFirstWorldAndRecordsEachRuns) {
  const fs::path dir = TempDir("changed");
  for (const char* f : {"sweep.yaml", "bot.yaml", "bot.lua"})
    fs::copy_file(fs::path(SWARMSIM_SOURCE_DIR) / "tests/data/sweep" / f, dir / f);
  const std::string world = (dir / "sweep.yaml").string();
  const std::string original = ReadText(world);
  const fs::path db = dir / "r.db";
  const std::string grid = " --param robots=2,5 --seeds 3-4 --steps 4 --db " + db.string();
  Result r = RunProgram("sweep " + world + grid + " --shard 0/2 --quiet");  // runs 1 and 3
  ASSERT_EQ(r.exit_code, 0) << r.output;
  std::ofstream(world, std::ios::app) << "# edited\n";
  r = RunProgram("sweep " + world + grid + " --allow-changed-world");  // runs 2 and 4
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("world file changed since the sweep began"), std::string::npos)
      << r.output;
  EXPECT_EQ(Count(db, "SELECT count(DISTINCT world_hash) FROM runs"), 2);
  EXPECT_EQ(Count(db, "SELECT count(*) FROM runs r, sweep s WHERE r.world_hash = s.world_hash"), 2)
      << "the sweep keeps the first file's hash, runs 1 and 3 ran it";
  // The original file resumes the sweep without the flag (it was refused
  // when the flag replaced the sweep's hash).
  std::ofstream(world, std::ios::trunc) << original;
  r = RunProgram("sweep " + world + grid);
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("4 already finished, 0 to run"), std::string::npos) << r.output;
  r = RunProgram("report " + db.string());
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("note: these runs ran 2 versions of the world file"), std::string::npos)
      << r.output;
  fs::remove_all(dir);
}

// Resuming a sweep whose runs failed counts those failures in its progress.
TEST(SweepTest, ProgressCountsTheFailuresOfBeforeAResume) {
  const fs::path dir = TempDir("failed_before");
  const fs::path db = dir / "r.db";
  const std::string cmd = "sweep " + kWorld + " --param fail_at=-1,0.1 --seeds 1 --steps 4 --db " +
                          db.string() + " --jobs 1";
  Result r = RunProgram(cmd + " --quiet");
  ASSERT_EQ(r.exit_code, 1) << r.output;
  r = RunProgram(cmd);  // nothing to run: the progress line is the database's
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find("2/2 runs  1 failed  0 left"), std::string::npos) << r.output;
  fs::remove_all(dir);
}

TEST(CoordinatorTest, TheWorldHashFollowsTheFilesBytes) {
  const fs::path dir = TempDir("world_hash");
  // 16 hex digits, the same for the same bytes wherever they are.
  std::ofstream(dir / "a.yaml") << "a";
  std::ofstream(dir / "a2.yaml") << "a";
  std::ofstream(dir / "b.yaml") << "b";
  std::ofstream(dir / "empty.yaml").close();
  const std::string a = WorldFileHash((dir / "a.yaml").string());
  EXPECT_EQ(a.size(), 16u);
  EXPECT_EQ(a.find_first_not_of("0123456789abcdef"), std::string::npos) << a;
  EXPECT_EQ(WorldFileHash((dir / "a2.yaml").string()), a);
  EXPECT_NE(WorldFileHash((dir / "b.yaml").string()), a) << "one byte changed";
  EXPECT_NE(WorldFileHash((dir / "empty.yaml").string()), a);
  // Any edit changes it, comments too.
  const std::string before = WorldFileHash(kWorld);
  fs::copy_file(kWorld, dir / "w.yaml");
  EXPECT_EQ(WorldFileHash((dir / "w.yaml").string()), before);
  std::ofstream(dir / "w.yaml", std::ios::app) << "# edited\n";
  EXPECT_NE(WorldFileHash((dir / "w.yaml").string()), before);
  try {
    WorldFileHash((dir / "none.yaml").string());
    ADD_FAILURE() << "no error";
  } catch (const Error& e) {
    EXPECT_EQ(std::string(e.what()),
              "cannot read world file '" + (dir / "none.yaml").string() + "'");
  }
  fs::remove_all(dir);
}

TEST(CoordinatorTest, TheSweepSpaceIsTheGridAndTheRunLength) {
  const std::vector<ParamSpec> params = {ParseParamSpec("robots=2,5"),
                                         ParseParamSpec("speed=0.1:0.3:3")};
  const std::string space = SweepSpace(params, {1, 2}, 10, std::nullopt);
  EXPECT_EQ(space, SweepSpace(params, {1, 2}, 10, std::nullopt)) << "the same sweep, the same text";
  EXPECT_NE(space, SweepSpace(params, {1, 3}, 10, std::nullopt));
  EXPECT_NE(space, SweepSpace(params, {1, 2}, 11, std::nullopt));
  EXPECT_NE(space, SweepSpace(params, {1, 2}, std::nullopt, 1.0));
  EXPECT_NE(space, SweepSpace({params[1], params[0]}, {1, 2}, 10, std::nullopt));
  EXPECT_NE(space,
            SweepSpace({params[0], ParseParamSpec("speed=0.1,0.2,0.3")}, {1, 2}, 10, std::nullopt))
      << "the same values from another spec";
  const auto json = nlohmann::json::parse(space);
  EXPECT_EQ(json["seeds"], nlohmann::json({1, 2}));
  EXPECT_EQ(json["steps"], 10);
  EXPECT_TRUE(json["duration"].is_null());
  EXPECT_EQ(json["params"][1]["name"], "speed");
  EXPECT_EQ(json["params"][1]["kind"], "linear");
  EXPECT_EQ(json["params"][1]["values"], nlohmann::json({"0.1", "0.2", "0.3"}));
}

TEST(CoordinatorTest, WorkersRunThisProgramWithTheSweepsSettings) {
  SweepOptions options;
  options.world = kWorld;
  options.steps = 12;
  options.threads_per_run = 3;
  options.timeout_s = 2.5;
  options.self_exe = SWARMSIM_BINARY;
  const WorkerConfig config = MakeWorkerConfig(options, 1);
  EXPECT_EQ(config.self_exe, SWARMSIM_BINARY);
  EXPECT_EQ(config.world, kWorld);
  EXPECT_EQ(config.steps, std::optional<int64_t>(12));
  EXPECT_FALSE(config.duration.has_value());
  EXPECT_EQ(config.threads_per_run, 3);
  EXPECT_EQ(config.timeout_s, 2.5);
  // A scratch folder of this process's own (a killed sweep's is cleared by the next).
  EXPECT_EQ(config.scratch.filename(), "swarmsim-sweep-" + std::to_string(getpid()));
}

// Jobs side by side share the memory: each run's --max-memory is the user's,
// else with several jobs an equal share of what is available at the start.
TEST(CoordinatorTest, EachRunGetsTheUsersMemoryCapOrItsShare) {
  constexpr uint64_t k8GiB = uint64_t{8} << 30;
  EXPECT_EQ(RunMemoryCap("6G", 4, k8GiB), "6G");
  EXPECT_EQ(RunMemoryCap("", 4, k8GiB), std::to_string(uint64_t{2} << 30));
  EXPECT_EQ(RunMemoryCap("", 3, 9000), "3000");
  EXPECT_EQ(RunMemoryCap("", 1, k8GiB), "") << "one job: the run's own check is enough";
  EXPECT_EQ(RunMemoryCap("", 4, UINT64_MAX), "") << "unknown room: no cap";
  // Shared by the runs that can be side by side, not by jobs that have no run.
  EXPECT_EQ(RunsSideBySide(8, 2), 2);
  EXPECT_EQ(RunsSideBySide(2, 100), 2);
  EXPECT_EQ(RunsSideBySide(4, 0), 1);
  EXPECT_EQ(RunMemoryCap("", RunsSideBySide(8, 1), k8GiB), "") << "one run left: no share";
  SweepOptions options;
  options.world = kWorld;
  options.max_memory = "3G";
  EXPECT_EQ(MakeWorkerConfig(options, 2).max_memory, "3G");
  options.max_memory.clear();
  EXPECT_EQ(MakeWorkerConfig(options, 1).max_memory, "");
}

// The share is a cap the user did not give: the sweep says where a refused
// run's "--max-memory ..." comes from, and says nothing when it is theirs.
TEST(CoordinatorTest, TheSweepSaysEachRunsShareOfTheMemory) {
  const fs::path dir = TempDir("share");
  const std::string base =
      "sweep " + kWorld + " --param robots=2 --seeds 1-3 --steps 2 --jobs 2 --db ";
  Result r = RunProgram(base + (dir / "a.db").string());
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("sweep: each run may take up to "), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("shared by 2 runs side by side; sweep --max-memory sets it)"),
            std::string::npos)
      << r.output;
  r = RunProgram(base + (dir / "b.db").string() + " --max-memory 3G");
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ(r.output.find("each run may take"), std::string::npos) << r.output;
  fs::remove_all(dir);
}

TEST(CoordinatorTest, AWorldWithoutARunLengthNeedsStepsOrDuration) {
  const fs::path dir = TempDir("no_length");
  for (const char* f : {"bot.yaml", "bot.lua"})
    fs::copy_file(fs::path(SWARMSIM_SOURCE_DIR) / "tests/data/sweep" / f, dir / f);
  std::string world = testing::ReadFile(kWorld);
  const std::string steps = ", steps: 10";
  world.replace(world.find(steps), steps.size(), "");
  std::ofstream(dir / "sweep.yaml") << world;
  const std::string base = "sweep " + (dir / "sweep.yaml").string() + " --quiet --db ";
  Result r = RunProgram(base + (dir / "a.db").string());
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("sweep.yaml gives no run length; pass --steps N or --duration SECONDS"),
            std::string::npos)
      << r.output;
  r = RunProgram(base + (dir / "b.db").string() + " --duration 0.3");
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ(Count(dir / "b.db", "SELECT steps FROM runs"), 3);
  // Shorter than a step: refused before any run, no database made (QA).
  r = RunProgram(base + (dir / "c.db").string() + " --duration 0.01");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("--duration 0.01 s is shorter than one time step (0.1 s)"),
            std::string::npos)
      << r.output;
  EXPECT_FALSE(fs::exists(dir / "c.db"));
  fs::remove_all(dir);
}

}  // namespace
}  // namespace swarmsim
