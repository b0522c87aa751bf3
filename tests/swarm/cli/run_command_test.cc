// swarmsim run WORLD (swarm/cli/run_command.cc) as a user meets it: exit codes,
// messages naming file and line, the summary and metrics it writes.
#include <gtest/gtest.h>
#include <sys/resource.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "framework/sanitizers.h"
#include "tests/swarm/run_program.h"

namespace {

namespace fs = std::filesystem;

using Result = swarmsim::testing::CommandResult;
using swarmsim::testing::RunProgram;

std::string Data(const std::string& name) { return swarmsim::testing::CliData(name); }

fs::path TempDir(const std::string& name) {
  return swarmsim::testing::FreshTempDir("swarmsim_cli", name);
}

std::string HashOf(const std::string& output) {
  const size_t at = output.find("state-hash: ");
  return at == std::string::npos ? "" : output.substr(at + 12, 16);
}

TEST(CliTest, DurationIsWholeStepsAndNotLessThanOne) {
  // ok.yaml steps 0.1 s.
  Result short_run = RunProgram("run " + Data("ok.yaml") + " --duration 0.01");
  EXPECT_EQ(short_run.exit_code, 2) << short_run.output;
  EXPECT_NE(short_run.output.find("--duration 0.01 s is shorter than one time step (0.1 s)"),
            std::string::npos)
      << short_run.output;
  // Not a multiple: the nearest whole number of steps, as --help says.
  const fs::path out = TempDir("duration");
  Result r =
      RunProgram("run " + Data("ok.yaml") + " --duration 0.26 --quiet --out " + out.string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  std::ifstream summary_file(out / "summary.json");
  ASSERT_TRUE(summary_file.good());
  EXPECT_EQ(nlohmann::json::parse(summary_file)["steps"], 3);
  // Halves round up as the decimals read: 0.15 / 0.1 is 1.4999999999999998
  // and 2.55 / 0.1 is 25.499999999999996 in binary (they ran 1 and 25 steps).
  for (const auto& [duration, steps] : {std::pair{"0.15", 2}, std::pair{"2.55", 26}}) {
    r = RunProgram("run " + Data("ok.yaml") + " --duration " + duration + " --quiet --out " +
                   out.string());
    ASSERT_EQ(r.exit_code, 0) << r.output;
    std::ifstream again(out / "summary.json");
    EXPECT_EQ(nlohmann::json::parse(again)["steps"], steps) << duration;
  }
  EXPECT_NE(
      RunProgram("run --help").output.find("rounded to the nearest whole number of time steps"),
      std::string::npos);
  fs::remove_all(out);
}

// --out that is a file, or a folder that cannot be made: a bad command line,
// refused before the run (no summary table printed), naming the path.
TEST(CliTest, OutThatIsNotAFolderIsABadCommandLine) {
  const fs::path dir = TempDir("out_not_folder");
  fs::create_directories(dir);
  const fs::path file = dir / "a_file";
  std::ofstream(file) << "kept\n";
  for (const std::string& out : {file.string(), std::string("/proc/swarmsim_no_such_dir")}) {
    Result r = RunProgram("run " + Data("ok.yaml") + " --steps 2 --out " + out);
    EXPECT_EQ(r.exit_code, 2) << r.output;
    EXPECT_NE(r.output.find("--out"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find(out), std::string::npos) << r.output;
    EXPECT_EQ(r.output.find("state-hash"), std::string::npos) << "the run did not start";
    EXPECT_EQ(r.output.find("steps "), std::string::npos) << r.output;
  }
  EXPECT_EQ(swarmsim::testing::ReadFile(file), "kept\n");
  fs::remove_all(dir);
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

TEST(CliTest, WorldThatDoesNotLoadWritesAnErrorSummaryWithOut) {
  // The --out folder is created (nested) and summary.json says what went wrong.
  const fs::path out = TempDir("load_error") / "run1";
  const std::string command = std::string(SWARMSIM_BINARY) + " run " + Data("typo.yaml") +
                              " --steps 1 --out " + out.string();
  Result r = swarmsim::testing::RunCommand(command);
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("error: "), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("typo.yaml:4:3: unknown key 'wall_thicknes'"), std::string::npos)
      << r.output;
  std::ifstream summary_file(out / "summary.json");
  ASSERT_TRUE(summary_file.good()) << "summary.json must be written when the world fails to load";
  const auto summary = nlohmann::json::parse(summary_file);
  EXPECT_EQ(summary["status"], "error");
  const std::string error = summary["error"];
  EXPECT_NE(error.find("typo.yaml:4:3: unknown key 'wall_thicknes'"), std::string::npos) << error;
  EXPECT_NE(r.output.find("error: " + error), std::string::npos) << r.output;
  EXPECT_EQ(summary["world"], Data("typo.yaml"));
  EXPECT_EQ(summary["command"], command);
  EXPECT_EQ("swarmsim " + summary["swarmsim_version"].get<std::string>() + "\n",
            RunProgram("version").output);
  EXPECT_FALSE(fs::exists(out / "metrics.csv"));
  // A --duration the world cannot run is bad input too, and says so in the folder.
  fs::remove_all(out);
  r = RunProgram("run " + Data("ok.yaml") + " --duration 0.01 --out " + out.string());
  EXPECT_EQ(r.exit_code, 2) << r.output;
  std::ifstream duration_file(out / "summary.json");
  ASSERT_TRUE(duration_file.good());
  EXPECT_EQ(nlohmann::json::parse(duration_file)["error"],
            "--duration 0.01 s is shorter than one time step (0.1 s)");
  fs::remove_all(out.parent_path());
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

// A world of `count` dummy robots whose script is `code`, in a fresh folder.
std::string DummyWorld(const fs::path& dir, int count, const std::string& code) {
  fs::create_directories(dir);
  std::ofstream(dir / "dummy.yaml") << "model: dummy\nobjects: {name: body, type: dummy, script: "
                                       "c.lua}\n";
  std::ofstream(dir / "c.lua") << code;
  std::ofstream(dir / "w.yaml") << "simulation: {physics: kinematic, time_step: 0.1, seed: 1}\n"
                                   "arena: {size: 3}\nmodels:\n  - model: dummy.yaml\n    count: "
                                << count << "\n    distribute: {region: arena}\n";
  return (dir / "w.yaml").string();
}

TEST(CliTest, ScriptErrorInOneRobotKeepsEveryRobotsPrintsInRobotOrder) {
  const fs::path dir = TempDir("prints");
  // A cleanup error in robot 1 of 3: every cleanup's line, in robot order, and the error.
  std::string world = DummyWorld(dir / "cleanup", 3,
                                 "function sysCall_cleanup() print('cleanup ran'); "
                                 "if sim.getRobotIndex() == 1 then error('boom') end end\n");
  Result r = RunProgram("run " + world + " --steps 1 --quiet");
  EXPECT_EQ(r.exit_code, 1) << r.output;
  const size_t p0 = r.output.find("[dummy#0] cleanup ran"),
               p1 = r.output.find("[dummy#1] cleanup ran"),
               p2 = r.output.find("[dummy#2] cleanup ran");
  ASSERT_NE(p0, std::string::npos) << r.output;
  ASSERT_NE(p1, std::string::npos) << r.output;
  ASSERT_NE(p2, std::string::npos) << r.output;
  EXPECT_TRUE(p0 < p1 && p1 < p2) << r.output;
  EXPECT_NE(r.output.find("c.lua:1: boom [in sysCall_cleanup of /dummy#1]"), std::string::npos)
      << r.output;
  // A sysCall_init error in robot 5 of 10: every robot's init line.
  world = DummyWorld(dir / "init", 10,
                     "function sysCall_init() print('init ran'); "
                     "if sim.getRobotIndex() == 5 then error('boom') end end\n");
  r = RunProgram("run " + world + " --steps 1 --threads 2 --quiet");
  EXPECT_EQ(r.exit_code, 1) << r.output;
  size_t last = 0;
  for (int i = 0; i < 10; ++i) {
    const size_t at = r.output.find("[dummy#" + std::to_string(i) + "] init ran");
    ASSERT_NE(at, std::string::npos) << i << ": " << r.output;
    EXPECT_GE(at, last) << r.output;
    last = at;
  }
  EXPECT_NE(r.output.find("c.lua:1: boom [in sysCall_init of /dummy#5]"), std::string::npos)
      << r.output;
  fs::remove_all(dir);
}

// The run leaves its world to the system at its end (a large world's blocks
// are not freed one by one), stopped first: every robot's cleanup still
// runs, after a run that ends well and after one a script error ends.
TEST(CliTest, EveryCleanupRunsAtTheEndOfARunWhateverItsEnd) {
  const fs::path dir = TempDir("cleanups");
  const std::string cleanup = "function sysCall_cleanup() print('cleanup ran') end\n";
  for (const bool fails : {false, true}) {
    const std::string world = DummyWorld(
        dir / (fails ? "fails" : "ends"), 3,
        cleanup + (fails ? "function sysCall_actuation() if sim.getRobotIndex() == 1 and "
                           "sim.getSimulationTime() > 0.15 then error('late') end end\n"
                         : ""));
    const Result r = RunProgram("run " + world + " --steps 5 --threads 2 --quiet");
    EXPECT_EQ(r.exit_code, fails ? 1 : 0) << r.output;
    for (int i = 0; i < 3; ++i)
      EXPECT_NE(r.output.find("[dummy#" + std::to_string(i) + "] cleanup ran"), std::string::npos)
          << (fails ? "after an error: " : "") << r.output;
    if (fails) {
      EXPECT_NE(r.output.find("late"), std::string::npos) << r.output;
    }
  }
  fs::remove_all(dir);
}

TEST(CliTest, ProgressShowsTheRobotsLoadedUnlessQuiet) {
  // Not a terminal here: the line comes with --progress only, and never with --quiet.
  const std::string run = "run " + std::string(SWARMSIM_SOURCE_DIR) +
                          "/worlds/diffusion.yaml --set robots=300 --steps 1";
  Result shown = RunProgram(run + " --progress");
  EXPECT_EQ(shown.exit_code, 0) << shown.output;
  EXPECT_NE(shown.output.find("loaded 300 robots in "), std::string::npos) << shown.output;
  EXPECT_NE(shown.output.find(" s; starting them\n"), std::string::npos) << shown.output;
  // Then how long the start took (each stage of 0.05 s or more before it,
  // "started module proximity in 0.1 s"), before the run's first step.
  const size_t loaded = shown.output.find(" s; starting them\n");
  const size_t started = shown.output.find("\nstarted in ");
  EXPECT_LT(loaded, started) << shown.output;
  EXPECT_NE(shown.output.find(" s\n", started), std::string::npos) << shown.output;
  for (size_t line = shown.output.find("\nstarted ", loaded); line < started;
       line = shown.output.find("\nstarted ", line + 1))
    EXPECT_NE(shown.output.substr(line, 80).find(" in "), std::string::npos) << shown.output;
  for (const std::string flags : {"", " --progress --quiet"}) {
    Result hidden = RunProgram(run + flags);
    EXPECT_EQ(hidden.exit_code, 0) << hidden.output;
    EXPECT_EQ(hidden.output.find("loaded 300"), std::string::npos) << flags << hidden.output;
    EXPECT_EQ(hidden.output.find("starting: "), std::string::npos) << flags << hidden.output;
  }
}

// Does `output` name the cap `cap` ("400 MiB") and go on with `next` (the
// forecast: ". About ", ". Fewer than ")? Under AddressSanitizer the program
// holds more than these caps before any robot (its shadow memory), so the
// message may be the one for a cap already used up instead.
bool NamesTheCap(const std::string& output, const std::string& cap, const std::string& next) {
  if (output.find("(--max-memory " + cap + ")" + next) != std::string::npos) return true;
  return swarmsim::kAddressSanitizer &&
         output.find("with no room left (--max-memory " + cap + ")") != std::string::npos;
}

}  // namespace

// A world that will not fit in memory is refused with a message while it is
// built, not killed by the kernel: --max-memory stands in for a small
// machine here. 20,000 Lua foot-bots with a Lua state each take ~600 MiB;
// under 400 MiB the
// forecast stops their Lua states (or, in a build whose copies are bigger,
// the copies), naming the cap, and summary.json says so.
TEST(CliTest, AWorldThatWillNotFitIsRefusedWithAMessage) {
  const fs::path out = TempDir("max_memory");
  Result r = RunProgram("run " + std::string(SWARMSIM_SOURCE_DIR) +
                        "/tests/data/worlds/lua_state_each.yaml --set robots=20000 --steps 1 "
                        "--quiet --max-memory 400M --out " +
                        out.string());
  EXPECT_NE(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("not enough memory for 20,000 robot"), std::string::npos) << r.output;
  EXPECT_TRUE(NamesTheCap(r.output, "400 MiB", ". About ")) << r.output;
  std::ifstream summary(out / "summary.json");
  ASSERT_TRUE(summary.good()) << r.output;
  const auto json = nlohmann::json::parse(summary);
  EXPECT_EQ(json["status"], "error");
  EXPECT_NE(json["error"].get<std::string>().find("not enough memory"), std::string::npos);

  // The copies' arrays are populated at once (framework/prefault.h), so
  // they are checked at once: 20,000 planar C++ foot-bots reserve ~140 MiB
  // of rows, refused under an 80 MiB cap before any copy is made (not left
  // to populate and, on a real machine, meet the out-of-memory killer).
  const fs::path out2 = TempDir("max_memory_reserved");
  r = RunProgram("run " + std::string(SWARMSIM_SOURCE_DIR) +
                 "/bench/worlds/diffusion_planar_native.yaml --set robots=20000 --steps 1 "
                 "--progress --max-memory 80M --out " +
                 out2.string());
  EXPECT_NE(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("not enough memory for 20,000 robot copies: the arrays reserved for "
                          "them take "),
            std::string::npos)
      << r.output;
  EXPECT_TRUE(NamesTheCap(r.output, "80.0 MiB", ". Fewer than ")) << r.output;
  EXPECT_EQ(r.output.find("1,024 of 20,000 robots built"), std::string::npos)
      << "refused before the copies: " << r.output;
  std::ifstream summary2(out2 / "summary.json");
  ASSERT_TRUE(summary2.good()) << r.output;
  EXPECT_NE(nlohmann::json::parse(summary2)["error"].get<std::string>().find("arrays reserved"),
            std::string::npos);

  // A small world is not held to it: said, not run silently past it.
  Result small = RunProgram("run " + Data("ok.yaml") + " --steps 1 --max-memory 1M");
  EXPECT_EQ(small.exit_code, 0) << small.output;
  EXPECT_NE(small.output.find("note: --max-memory 1M is not applied: worlds of fewer than 2,000 "
                              "robots are not checked (this one has 4)"),
            std::string::npos)
      << small.output;

  // The check's switch said: off drops the cap, a value neither off nor on keeps it on.
  Result off = swarmsim::testing::RunCommand("SWARMSIM_MEMORY_CHECK=off " SWARMSIM_BINARY " run " +
                                             Data("ok.yaml") + " --steps 1 --max-memory 1G");
  EXPECT_EQ(off.exit_code, 0) << off.output;
  EXPECT_NE(off.output.find("note: --max-memory 1G is not applied: SWARMSIM_MEMORY_CHECK=off "
                            "turns the memory check off"),
            std::string::npos)
      << off.output;
  Result unclear = swarmsim::testing::RunCommand(
      "SWARMSIM_MEMORY_CHECK=bogus " SWARMSIM_BINARY " run " + Data("ok.yaml") + " --steps 1");
  EXPECT_EQ(unclear.exit_code, 0) << unclear.output;
  EXPECT_NE(unclear.output.find("warning: SWARMSIM_MEMORY_CHECK='bogus' is neither 0, off, "
                                "false, no nor 1, on, true, yes: the memory check stays on"),
            std::string::npos)
      << unclear.output;

  Result bad = RunProgram("run " + Data("ok.yaml") + " --steps 1 --max-memory 12X");
  EXPECT_EQ(bad.exit_code, 2) << bad.output;
  EXPECT_NE(bad.output.find("expected a memory size such as 500M, 2G or 1.5GiB, got '12X'"),
            std::string::npos)
      << bad.output;
}

// A process limit (ulimit -v, common on clusters) is room like a cgroup's:
// the forecast names it. Without the forecast (SWARMSIM_MEMORY_CHECK=0),
// running out of it part-way through the start ends the run with a
// message and its summary: the state hash it prints read the half-built
// physics and crashed (exit 139). Not under AddressSanitizer, whose shadow
// memory takes more address space than any cap.
// A low stack limit (`ulimit -s 256` in bash sets the hard limit too): a
// script's recursion through C calls, which Lua stops after 200 levels
// with "C stack overflow", needs more than 256-400 KiB, and the program
// died of a segfault (exit 139). It now runs with the stack it needs.
TEST(CliTest, DeepRecursionInAScriptIsItsErrorUnderALowStackLimit) {
  for (const char* limit : {"", "ulimit -s 256 && "}) {
    const Result r = swarmsim::testing::RunCommand(std::string(limit) + SWARMSIM_BINARY + " run " +
                                                   Data("deep_calls.yaml") + " --quiet");
    EXPECT_EQ(r.exit_code, 1) << limit << r.output;
    EXPECT_NE(r.output.find("stack overflow"), std::string::npos) << limit << r.output;
    EXPECT_NE(r.output.find("deep_calls.lua"), std::string::npos) << limit << r.output;
  }
}

// A thread the run needs that the system does not start (ulimit -u; here
// ulimit -v against the stack size each thread takes, ulimit -s): the run
// ended with "error: Resource temporarily unavailable", no summary.json,
// and the earlier run's ("ok") left beside the files it had removed. Now
// the thread is named, and the summary says the run failed.
TEST(CliTest, AThreadThatCannotBeStartedIsNamedAndTheSummarySaysSo) {
  if (swarmsim::kAddressSanitizer) GTEST_SKIP() << "ulimit -v stops ASan builds before main";
  rlimit stack{};
  if (getrlimit(RLIMIT_STACK, &stack) != 0 ||
      (stack.rlim_max != RLIM_INFINITY && stack.rlim_max < 4000000ull * 1024))
    GTEST_SKIP() << "the hard stack limit is below 4 GB";
  const fs::path out = TempDir("no_thread");
  for (const auto& [flags, thread] :
       {std::pair{"", "the run's watchdog"}, std::pair{" --record", "the recording's writer"}}) {
    Result earlier =
        RunProgram("run " + Data("ok.yaml") + " --steps 2 --quiet --record --out " + out.string());
    ASSERT_EQ(earlier.exit_code, 0) << earlier.output;
    ASSERT_TRUE(fs::exists(out / "recording.swrec"));
    // glibc gives each thread a stack of ulimit -s: 4 GB, in 3 GB of room.
    Result r = swarmsim::testing::RunCommand(
        "ulimit -s 4000000 && ulimit -v 3000000 && " + std::string(SWARMSIM_BINARY) + " run " +
        Data("ok.yaml") + " --steps 2 --quiet" + flags + " --out " + out.string());
    EXPECT_TRUE(r.exit_code == 1 || r.exit_code == 2) << r.output;
    EXPECT_NE(r.output.find(std::string("cannot start a thread for ") + thread +
                            ": Resource temporarily unavailable"),
              std::string::npos)
        << r.output;
    EXPECT_NE(r.output.find("`ulimit -u`"), std::string::npos) << r.output;
    std::ifstream summary_file(out / "summary.json");
    ASSERT_TRUE(summary_file.good()) << r.output;
    const nlohmann::json summary = nlohmann::json::parse(summary_file);
    EXPECT_EQ(summary["status"], "error") << flags;
    EXPECT_NE(summary["error"].get<std::string>().find(thread), std::string::npos) << flags;
    // Nothing of the earlier run's is left to be taken for this one's.
    EXPECT_FALSE(fs::exists(out / "metrics.csv")) << flags;
    EXPECT_FALSE(fs::exists(out / "recording.swrec")) << flags;
  }
  fs::remove_all(out);
}

// A step that fails after its physics moved the clock on (the bodies blew
// up): the summary said 3 steps and 0.4 s simulated; the time is now that of
// the steps that finished.
TEST(CliTest, AStepThatFailsInItsPhysicsIsNotCountedInTheSimulatedTime) {
  const fs::path dir = TempDir("blow_up");
  fs::create_directories(dir);
  std::ofstream(dir / "world.yaml")
      << "simulation: {physics: ode, time_step: 0.1, gravity: 0}\n"
         "objects:\n"
         "  - {name: slide, type: joint, joint: prismatic, mode: force, position: [0, 0, 1],\n"
         "     script: blow.lua, children: [{name: b, type: shape, shape: box,\n"
         "     size: [0.1, 0.1, 0.1], dynamic: true, mass: 1}]}\n";
  std::ofstream(dir / "blow.lua")  // 1e15 N from the fourth step: 5e12 m in 0.1 s
      << "function sysCall_actuation()\n"
         "  if sim.getSimulationTime() > 0.25 then sim.setJointTargetForce(sim.getObject('.'), "
         "1e15) end\n"
         "end\n";
  const Result r = RunProgram("run " + (dir / "world.yaml").string() + " --steps 10 --out " +
                              (dir / "out").string());
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find("at step 4, beyond the 1e6 m"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("simulated time  0.30 s"), std::string::npos) << r.output;
  std::ifstream summary_file(dir / "out" / "summary.json");
  const nlohmann::json summary = nlohmann::json::parse(summary_file);
  EXPECT_EQ(summary["steps"], 3);
  EXPECT_NEAR(summary["simulated_time"].get<double>(), 0.3, 1e-12);
  fs::remove_all(dir);
}

// Too few open files (`ulimit -n`): the recording and metrics.csv took the
// last ones, and the run ended with "cannot write 'summary.json': Too many
// open files", leaving it "running". Whatever the limit, the summary now
// says how the run ended: ok, or the error, never "running".
TEST(CliTest, TooFewOpenFilesStillGiveTheSummaryItsEnd) {
  const fs::path out = TempDir("open_files");
  int ended = 0;
  for (int files = 5; files <= 12; ++files) {
    fs::remove_all(out);
    // In a subshell: the shell's own redirection (2>&1) comes before the
    // limit (dash keeps a copy of the descriptor it redirects above 10).
    const Result r = swarmsim::testing::RunCommand(
        "(ulimit -n " + std::to_string(files) + " && " + std::string(SWARMSIM_BINARY) + " run " +
        Data("ok.yaml") + " --steps 3 --quiet --record --out " + out.string() + ")");
    std::ifstream summary_file(out / "summary.json");
    if (!summary_file.good()) continue;  // too few to begin
    const nlohmann::json summary = nlohmann::json::parse(summary_file);
    EXPECT_NE(summary["status"], "running") << files << " files: " << r.output;
    if (summary["status"] == "ok") {
      EXPECT_EQ(r.exit_code, 0) << files << " files: " << r.output;
    } else {
      EXPECT_NE(r.exit_code, 0) << files << " files: " << r.output;
      EXPECT_FALSE(summary["error"].get<std::string>().empty()) << files;
    }
    ++ended;
  }
  EXPECT_GT(ended, 0) << "no limit let the run begin";
  fs::remove_all(out);
}

// A stop signal while a large world starts (its robots' sysCall_init take
// seconds here; a million robots' start does too) ends the start between
// robots: it was not looked at until the start ended, or the run was ended
// 3 s after the signal as a stuck start ("which did not finish within 3 s
// of the signal; no Lua script was running"). The signal is sent once the
// run's first summary.json is written, just before the start (waited for,
// not timed).
TEST(CliTest, AStopSignalWhileTheWorldStartsEndsTheStart) {
  const fs::path out = TempDir("stop_start");
  const Result r = swarmsim::testing::RunCommand(
      "(" + std::string(SWARMSIM_BINARY) + " run " + Data("slow_start.yaml") +
      " --steps 5 --quiet --out " + out.string() + " & pid=$!; while [ ! -s " +
      (out / "summary.json").string() + " ]; do sleep 0.01; done; kill -INT $pid; wait $pid; " +
      "echo exit=$?)");
  EXPECT_NE(r.output.find("exit=130"), std::string::npos) << r.output;  // 128 + SIGINT
  EXPECT_NE(r.output.find("error: interrupted by SIGINT while the world was starting"),
            std::string::npos)
      << r.output;
  std::ifstream summary_file(out / "summary.json");
  ASSERT_TRUE(summary_file.good());
  const nlohmann::json summary = nlohmann::json::parse(summary_file);
  EXPECT_EQ(summary["status"], "interrupted");
  EXPECT_EQ(summary["steps"], 0);
  fs::remove_all(out);
}

// The output folder renamed (or removed) while the run writes into it: the
// run ended with exit 0 and no word, its summary.json never written (a new
// folder of that name would hold a summary listing files it does not
// have). Now it says so and fails. The run is stopped by SIGTERM once its
// first metrics are in the folder (waited for, not timed).
TEST(CliTest, AnOutputFolderRenamedDuringTheRunIsSaid) {
  const fs::path out = TempDir("renamed");
  const fs::path moved = out.string() + "_moved";
  fs::remove_all(moved);
  const Result r = swarmsim::testing::RunCommand(
      "cd " + out.parent_path().string() + " && (" + SWARMSIM_BINARY + " run " + Data("ok.yaml") +
      " --steps 100000000 --quiet --out " + out.string() + " & pid=$!; while [ ! -s " +
      (out / "metrics.csv").string() + " ]; do sleep 0.02; done; mv " + out.string() + " " +
      moved.string() + "; kill -TERM $pid; wait $pid; echo exit=$?)");
  EXPECT_NE(r.output.find("exit=143"), std::string::npos) << r.output;  // 128 + SIGTERM
  EXPECT_NE(r.output.find("the output folder '" + out.string() +
                          "' was removed or renamed during the run"),
            std::string::npos)
      << r.output;
  EXPECT_FALSE(fs::exists(out)) << "no new folder";
  EXPECT_TRUE(fs::exists(moved / "metrics.csv"));
  fs::remove_all(moved);
}

// The same while a large world loads (100,000 robots; the folder is moved
// once the load's first progress line is out): the run made a new folder
// of that name and wrote an "ok" summary into it, exit 0.
TEST(CliTest, AnOutputFolderRenamedWhileTheWorldLoadsIsSaid) {
  const fs::path out = TempDir("renamed_load");
  const fs::path moved = out.string() + "_moved";
  const fs::path err = out.string() + "_err.txt";
  fs::remove_all(moved);
  const Result r = swarmsim::testing::RunCommand(
      "(" + std::string(SWARMSIM_BINARY) + " run " + SWARMSIM_SOURCE_DIR +
      "/bench/worlds/diffusion_planar_native.yaml --set robots=100000 --steps 1 --progress --out " +
      out.string() + " 2> " + err.string() + " & pid=$!; while ! grep -q loading: " + err.string() +
      " 2>/dev/null; do sleep 0.01; done; mv " + out.string() + " " + moved.string() +
      "; wait $pid; echo exit=$?; cat " + err.string() + ")");
  EXPECT_NE(r.output.find("exit=1\n"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("the output folder '" + out.string() + "' was removed or renamed"),
            std::string::npos)
      << r.output;
  EXPECT_FALSE(fs::exists(out)) << "no new folder";
  fs::remove_all(moved);
  fs::remove(err);
}

TEST(CliTest, AnAddressSpaceLimitIsRoomTooAndRunningOutOfItIsNamed) {
  if (swarmsim::kAddressSanitizer) GTEST_SKIP() << "ulimit -v stops ASan builds before main";
  const std::string limit = swarmsim::testing::AddressSpaceLimit(600000);
  const fs::path out = TempDir("ulimit_forecast");
  Result r = swarmsim::testing::RunCommand(
      limit + SWARMSIM_BINARY + std::string(" run ") + SWARMSIM_SOURCE_DIR +
      "/bench/worlds/diffusion_planar_native.yaml --set robots=100000 --steps 1 --quiet --out " +
      out.string());
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("not enough memory for 100,000 robot copies"), std::string::npos)
      << r.output;
  EXPECT_NE(r.output.find("(the address-space limit (ulimit -v))"), std::string::npos) << r.output;

  // The Lua world ran out in Box2D's build; the planar C++ one in the
  // controllers' init, whose error message then could not be composed
  // ("error: std::bad_alloc").
  for (const auto& [world, kb] :
       {std::pair{"/worlds/diffusion.yaml", 1000000},
        std::pair{"/bench/worlds/diffusion_planar_native.yaml", 1100000}}) {
    const fs::path out2 = TempDir("ulimit_start");
    r = swarmsim::testing::RunCommand(
        "export SWARMSIM_MEMORY_CHECK=0; " + swarmsim::testing::AddressSpaceLimit(kb) +
        SWARMSIM_BINARY + " run " + SWARMSIM_SOURCE_DIR + world +
        " --set robots=100000 --steps 1 --quiet --hash --out " + out2.string());
    if (swarmsim::testing::EndedByGlibcOutOfMemory(r.exit_code, r.output)) continue;
    EXPECT_TRUE(r.exit_code == 1 || r.exit_code == 2) << world << ": " << r.output;
    EXPECT_NE(r.output.find("memory"), std::string::npos) << world << ": " << r.output;
    EXPECT_EQ(r.output.find("std::bad_alloc"), std::string::npos) << world << ": " << r.output;
    std::ifstream summary(out2 / "summary.json");
    ASSERT_TRUE(summary.good()) << world << ": " << r.output;
    EXPECT_EQ(nlohmann::json::parse(summary)["status"], "error") << world;
  }
}
