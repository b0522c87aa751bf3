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

std::string Data(const std::string& name) { return swarmsim::testing::CliData(name); }

fs::path TempDir(const std::string& name) {
  return swarmsim::testing::FreshTempDir("swarmsim_cli", name);
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
  // Every object type and every registered module has its line: kind, name,
  // version, one line of description.
  for (const char* line :
       {"object type\tjoint\tbuilt-in\t", "object type\tforce_sensor\t", "calculation\tik\t",
        "record\tpaint\t", "record\tgraphs\t", "metric\tcovered_area\t"})
    EXPECT_NE(modules.output.find(line), std::string::npos) << line << "\n" << modules.output;
  // describe names the modules a world gets: every world's, then its own.
  Result describe =
      RunProgram("describe " + std::string(SWARMSIM_SOURCE_DIR) + "/worlds/hexapod.yaml");
  EXPECT_EQ(describe.exit_code, 0) << describe.output;
  EXPECT_NE(
      describe.output.find(
          "modules: ik paint proximity collision mill paths planning rendering graphs blobs\n"),
      std::string::npos)
      << describe.output;
}

TEST(CliTest, UnknownFlagIsAClearErrorWithNonzeroExit) {
  Result r = RunProgram("run " + Data("ok.yaml") + " --stpes 10");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.output.find("error: unknown option '--stpes' for 'run' (did you mean '--steps'?)"),
            std::string::npos)
      << r.output;
  Result with_value = RunProgram("run " + Data("ok.yaml") + " --stpes=10");
  EXPECT_NE(with_value.output.find("unknown option '--stpes' for 'run' (did you mean '--steps'?)"),
            std::string::npos)
      << with_value.output;
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

TEST(CliTest, UnknownCommandSuggestsTheNearestAndListsThem) {
  Result r = RunProgram("runn " + Data("ok.yaml"));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.output.find("error: unknown command 'runn' (did you mean 'run'?)"), std::string::npos)
      << r.output;
  EXPECT_NE(r.output.find("commands: run, bench, sweep"), std::string::npos) << r.output;
}

TEST(CliTest, WholeNumberOptionsSayWhatTheyExpect) {
  Result r = RunProgram("run " + Data("ok.yaml") + " --steps 1e2");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.output.find("--steps: expected a whole number of steps, got '1e2'"),
            std::string::npos)
      << r.output;
}

TEST(CliTest, SeedOutsideZeroTo2To64Minus1IsRejected) {
  for (const std::string seed : {"-1", "18446744073709551616", "1.5"}) {
    Result r = RunProgram("run " + Data("ok.yaml") + " --steps 1 --quiet --seed " + seed);
    EXPECT_EQ(r.exit_code, 2) << seed << ": " << r.output;
    EXPECT_NE(r.output.find("--seed: expected a whole number from 0 to 18446744073709551615"),
              std::string::npos)
        << r.output;
  }
  Result largest =
      RunProgram("run " + Data("ok.yaml") + " --steps 1 --quiet --seed 18446744073709551615");
  EXPECT_EQ(largest.exit_code, 0) << largest.output;
  // Decimal, as in the world file: 010 is ten, not octal eight.
  const std::string run = "run " + Data("ok.yaml") + " --steps 3 --quiet --hash --seed ";
  EXPECT_EQ(HashOf(RunProgram(run + "010").output), HashOf(RunProgram(run + "10").output));
  EXPECT_NE(HashOf(RunProgram(run + "010").output), HashOf(RunProgram(run + "8").output));
}

TEST(CliTest, SetTakesOneNameEqualsValueEach) {
  Result help = RunProgram("run --help");
  EXPECT_NE(help.output.find("--set NAME=VALUE"), std::string::npos) << help.output;
  EXPECT_EQ(help.output.find("--set TEXT"), std::string::npos) << help.output;
  // Two values after one --set, with the world before them or after them.
  for (const std::string& args :
       {"run " + Data("ok.yaml") + " --steps 1 --set robots=2 bot.speed=0.1",
        "run --steps 1 --set robots=2 bot.speed=0.1 " + Data("ok.yaml")}) {
    Result r = RunProgram(args);
    EXPECT_EQ(r.exit_code, 2) << r.output;
    EXPECT_NE(r.output.find("each --set takes one NAME=VALUE; repeat --set for more"),
              std::string::npos)
        << r.output;
  }
  Result repeated = RunProgram("run " + Data("ok.yaml") +
                               " --steps 1 --quiet --set robots=2 --set bot.speed=0.1");
  EXPECT_EQ(repeated.exit_code, 0) << repeated.output;
}

TEST(CliTest, EmptyOutIsRejected) {
  Result r = RunProgram("run " + Data("ok.yaml") + " --steps 1 --quiet --out ''");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("--out: expected a folder"), std::string::npos) << r.output;
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
  EXPECT_NE(
      RunProgram("run --help").output.find("rounded to the nearest whole number of time steps"),
      std::string::npos);
  fs::remove_all(out);
}

TEST(CliTest, BenchFindsItsWorldFromAnyFolder) {
  // Without --world: worlds/diffusion.yaml beside the program, not in the current folder.
  const fs::path elsewhere = TempDir("bench_elsewhere");
  fs::create_directories(elsewhere);
  Result r = swarmsim::testing::RunCommand("cd " + elsewhere.string() + " && " + SWARMSIM_BINARY +
                                           " bench --robots 2 --threads 1 --steps 1");
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("worlds/diffusion.yaml"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("box2d-only"), std::string::npos) << r.output;
  fs::remove_all(elsewhere);
}

TEST(CliTest, BenchChecksItsWorldBeforeTheTable) {
  Result missing = RunProgram("bench --world /nonexistent/world.yaml --robots 2 --steps 1");
  EXPECT_EQ(missing.exit_code, 2);
  EXPECT_NE(missing.output.find("world file '/nonexistent/world.yaml' not found"),
            std::string::npos)
      << missing.output;
  EXPECT_EQ(missing.output.find("ticks/s"), std::string::npos) << missing.output;

  // A world whose robot count is not the `robots` parameter.
  const fs::path dir = TempDir("bench_no_robots");
  fs::create_directories(dir);
  const fs::path world = dir / "fixed_count.yaml";
  std::ofstream(world) << "simulation: {physics: box2d, time_step: 0.1, physics_substeps: 5}\n"
                       << "arena: {size: 3}\n"
                       << "models:\n"
                       << "  - model: " << Data("bot.yaml") << "\n"
                       << "    count: 4\n"
                       << "    distribute: {region: arena}\n";
  for (const std::string mode : {"", " --scaling"}) {
    Result r =
        RunProgram("bench --world " + world.string() + " --robots 50 --threads 1 --steps 1" + mode);
    EXPECT_EQ(r.exit_code, 2) << r.output;
    EXPECT_NE(r.output.find("has no parameter 'robots'; bench sets the robot count through it"),
              std::string::npos)
        << r.output;
    EXPECT_NE(r.output.find("count: $robots"), std::string::npos) << r.output;
    EXPECT_EQ(r.output.find("robots=1"), std::string::npos) << r.output;
    EXPECT_EQ(r.output.find("ticks/s"), std::string::npos) << r.output;
  }
  fs::remove_all(dir);
}

TEST(CliTest, BenchThreadsAreCheckedLikeRun) {
  const std::string expected = "--threads: expected a whole number from 1 to 1024, got '0'";
  Result run = RunProgram("run " + Data("ok.yaml") + " --steps 1 --threads 0");
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_NE(run.output.find(expected), std::string::npos) << run.output;
  Result bench =
      RunProgram("bench --world " + Data("ok.yaml") + " --robots 2 --steps 1 --threads 0");
  EXPECT_EQ(bench.exit_code, 2) << bench.output;
  EXPECT_NE(bench.output.find(expected), std::string::npos) << bench.output;
  Result negative =
      RunProgram("bench --world " + Data("ok.yaml") + " --robots 2 --steps 1 --threads 1,-1");
  EXPECT_EQ(negative.exit_code, 2) << negative.output;
  EXPECT_NE(negative.output.find("got '-1'"), std::string::npos) << negative.output;
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

}  // namespace
