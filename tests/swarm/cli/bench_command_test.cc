// swarmsim bench (swarm/cli/bench_command.cc): its world found from any folder
// and checked before the table, its --threads checked like run's.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <utility>
#include <vector>

#include "tests/swarm/run_program.h"

namespace {

namespace fs = std::filesystem;

using Result = swarmsim::testing::CommandResult;
using swarmsim::testing::RunProgram;

std::string Data(const std::string& name) { return swarmsim::testing::CliData(name); }

fs::path TempDir(const std::string& name) {
  return swarmsim::testing::FreshTempDir("swarmsim_cli", name);
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

// A comma list with an empty entry is refused (CLI11 would drop it), with
// the list as it was probably meant.
TEST(CliTest, BenchListsWithAnEmptyEntryAreRefused) {
  const std::string base = "bench --world " + Data("ok.yaml") + " --steps 1";
  for (const auto& [flags, expected] : std::vector<std::pair<std::string, std::string>>{
           {" --robots 1000,,2",
            "error: --robots '1000,,2': an empty entry in the list (did "
            "you mean --robots 1000,2?)"},
           {" --robots=2,",
            "error: --robots '2,': an empty entry in the list (did you mean "
            "--robots 2?)"},
           {" --robots 2 --threads ,1", "error: --threads ',1': an empty entry"},
           {" --robots ,", "error: --robots ',': an empty entry in the list (give one or more"}}) {
    const Result r = RunProgram(base + flags);
    EXPECT_EQ(r.exit_code, 2) << flags << ": " << r.output;
    EXPECT_NE(r.output.find(expected), std::string::npos) << flags << ": " << r.output;
    EXPECT_EQ(r.output.find("ticks/s"), std::string::npos) << flags << ": nothing measured";
  }
}

// --warmup: the unmeasured steps before the measured ones, said in the
// table's heading; a negative count is refused.
TEST(CliTest, BenchWarmupIsTheStepsBeforeTheMeasuredOnes) {
  const std::string base = "bench --world " + Data("ok.yaml") + " --robots 2 --threads 1";
  const Result r = RunProgram(base + " --steps 3 --warmup 7");
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("3 measured steps after 7 warm-up steps"), std::string::npos) << r.output;
  const Result negative = RunProgram(base + " --steps 3 --warmup -1");
  EXPECT_EQ(negative.exit_code, 2) << negative.output;
  EXPECT_NE(negative.output.find("--warmup"), std::string::npos) << negative.output;
}

// The world's load-time warnings at the measured count (here the
// large-swarm note about `order`) reach the user once, as `run` prints
// them, though every row's child loads the world.
TEST(CliTest, BenchPassesOnTheWorldsWarningsOnce) {
  const fs::path dir = TempDir("bench_warnings");
  fs::create_directories(dir);
  std::ofstream(dir / "dot.yaml") << "model: dot\n"
                                     "objects: {name: body, type: shape, shape: cylinder, "
                                     "radius: 0.05, height: 0.05}\n";
  std::ofstream(dir / "world.yaml") << "simulation: {physics: kinematic, time_step: 0.1}\n"
                                       "parameters: {robots: 10}\n"
                                       "arena: {size: 150}\n"
                                       "models:\n"
                                       "  - model: dot.yaml\n"
                                       "    count: $robots\n"
                                       "    distribute: {region: arena}\n";
  const std::string note = "numbered in the order they were drawn";
  const Result large = RunProgram("bench --world " + (dir / "world.yaml").string() +
                                  " --robots 10000 --threads 1,2 --steps 1 --warmup 0");
  EXPECT_EQ(large.exit_code, 0) << large.output;
  const size_t at = large.output.find(note);
  ASSERT_NE(at, std::string::npos) << large.output;
  EXPECT_EQ(large.output.find(note, at + 1), std::string::npos) << "said once: " << large.output;
  EXPECT_NE(large.output.find("world.yaml:6:12: 10,000 copies of 'dot'"), std::string::npos)
      << large.output;
  const Result small = RunProgram("bench --world " + (dir / "world.yaml").string() +
                                  " --robots 100 --threads 1 --steps 1 --warmup 0");
  EXPECT_EQ(small.exit_code, 0) << small.output;
  EXPECT_EQ(small.output.find(note), std::string::npos) << small.output;
  fs::remove_all(dir);
}

// A flag of one kind of bench given to another is refused, not ignored.
TEST(CliTest, BenchRefusesTheFlagsOfAnotherKindOfBench) {
  const std::string base = "bench --world " + Data("ok.yaml") + " --robots 2 --steps 1";
  for (const auto& [flags, expected] : std::vector<std::pair<std::string, std::string>>{
           {" --plot p.png", "error: bench: --plot is for bench --scaling and --scaling-robots"},
           {" --jobs 2", "error: bench: --jobs is for bench --scaling"},
           {" --sweep-runs 3", "error: bench: --sweep-runs is for bench --scaling"},
           {" --configs lua", "error: bench: --configs is for bench --scaling-robots"},
           {" --scaling-robots --jobs 2", "error: bench: --jobs is for bench --scaling"}}) {
    const Result r = RunProgram(base + flags);
    EXPECT_EQ(r.exit_code, 2) << flags << ": " << r.output;
    EXPECT_NE(r.output.find(expected), std::string::npos) << flags << ": " << r.output;
    EXPECT_EQ(r.output.find("ticks/s"), std::string::npos) << flags << ": nothing measured";
  }
}

// --csv and --plot are checked before anything is measured: a file bench
// did not write is not written over (a world file became a CSV, README.md
// too, exit 0), a folder that is not there is said before the measurements
// (they were lost after them, and gnuplot wrote its PNG onto the table's
// standard output), and a value listed twice is refused as sweep refuses it.
TEST(CliTest, BenchOutputsAreCheckedBeforeAnyMeasurement) {
  const fs::path dir = TempDir("bench_outputs");
  fs::create_directories(dir);
  const std::string notes = (dir / "notes.md").string();
  std::ofstream(notes) << "# my notes\n";
  const std::string image = (dir / "image.png").string();
  std::ofstream(image) << "not a png";
  const std::string base = "bench --world " + Data("ok.yaml") + " --steps 1 --threads 1";
  for (const auto& [flags, expected] : std::vector<std::pair<std::string, std::string>>{
           {" --robots 2 --csv " + notes,
            "error: bench --csv '" + notes +
                "' is a file that is not a CSV of bench's (its first line is not a bench "
                "header): bench would write over it; name another file, or remove it first"},
           {" --robots 2 --scaling-robots --csv " + notes, "is a file that is not a CSV"},
           {" --robots 2 --scaling --csv " + notes, "is a file that is not a CSV"},
           {" --robots 2 --scaling-robots --csv " + (dir / "a.csv").string() + " --plot " + image,
            "error: bench --plot '" + image + "' is a file that is not a PNG image"},
           {" --robots 2 --scaling --plot /nonexistent/s.png",
            "error: bench --plot: cannot write '/nonexistent/s.png': No such file or directory"},
           {" --robots 2 --scaling-robots --csv /nonexistent/s.csv",
            "error: bench --csv: cannot write '/nonexistent/s.csv'"},
           {" --robots 2 --csv " + dir.string(),
            "it is a folder, not an ordinary file: name a file"},
           // One file by two spellings (the plot was written over the CSV).
           {" --robots 2 --scaling-robots --csv " + (dir / "y.csv").string() + " --plot " +
                dir.string() + "/./y.csv",
            "error: bench: --csv and --plot name one file"},
           {" --robots 2 --scaling --csv " + (dir / "x").string() + " --plot " +
                (dir / "x").string(),
            "error: bench: --csv and --plot name one file"},
           {" --robots 2,3,2", "error: bench: --robots: value '2' appears twice"},
           {" --robots 2 --threads 1,1", "error: bench: --threads: value '1' appears twice"},
           {" --robots 2 --scaling-robots --configs lua,cpp,lua",
            "error: bench: --configs: value 'lua' appears twice"}}) {
    const Result r = RunProgram(base + flags);
    EXPECT_EQ(r.exit_code, 2) << flags << ": " << r.output;
    EXPECT_NE(r.output.find(expected), std::string::npos) << flags << ": " << r.output;
    EXPECT_EQ(r.output.find("ticks/s"), std::string::npos) << flags << ": nothing measured";
  }
  EXPECT_EQ(swarmsim::testing::ReadFile(notes), "# my notes\n");
  EXPECT_EQ(swarmsim::testing::ReadFile(image), "not a png");
  EXPECT_FALSE(fs::exists(dir / "a.csv")) << "made to try the folder, then removed";
  // A CSV bench wrote is written over, as before.
  const std::string csv = (dir / "bench.csv").string();
  for (int round = 0; round < 2; ++round) {
    const Result r = RunProgram(base + " --robots 2 --csv " + csv);
    EXPECT_EQ(r.exit_code, 0) << r.output;
  }
  EXPECT_EQ(swarmsim::testing::ReadFile(csv).rfind("config,robots,threads,", 0), 0u);
  fs::remove_all(dir);
}

}  // namespace
