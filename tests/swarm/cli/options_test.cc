// The option checks the commands share (swarm/cli/options.cc): whole numbers,
// seeds, thread counts and folder names, each refused with what it expects.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <thread>

#include "tests/swarm/run_program.h"

namespace {

namespace fs = std::filesystem;

using Result = swarmsim::testing::CommandResult;
using swarmsim::testing::RunProgram;

std::string Data(const std::string& name) { return swarmsim::testing::CliData(name); }

std::string HashOf(const std::string& output) {
  const size_t at = output.find("state-hash: ");
  return at == std::string::npos ? "" : output.substr(at + 12, 16);
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

// More threads than the machine runs at once: a note (slower, same results);
// as many as it runs: none.
TEST(CliTest, MoreThreadsThanCoresGetANote) {
  const int cores = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  const Result over = RunProgram("run " + Data("ok.yaml") + " --steps 1 --quiet --threads " +
                                 std::to_string(cores + 1));
  EXPECT_EQ(over.exit_code, 0) << over.output;
  EXPECT_NE(over.output.find("note: " + std::to_string(cores + 1) + " threads on "),
            std::string::npos)
      << over.output;
  EXPECT_NE(over.output.find(" hardware threads: the steps wait for threads that cannot run"),
            std::string::npos)
      << over.output;
  const Result fits = RunProgram("run " + Data("ok.yaml") + " --steps 1 --quiet --threads 1");
  EXPECT_EQ(fits.output.find("hardware threads"), std::string::npos) << fits.output;
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

TEST(CliTest, EmptyOutIsRejected) {
  Result r = RunProgram("run " + Data("ok.yaml") + " --steps 1 --quiet --out ''");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("--out: expected a folder"), std::string::npos) << r.output;
  // A file where the folder would be: bad input before the world loads.
  const std::string file = ::testing::TempDir() + "/swarmsim_out_is_a_file";
  std::ofstream(file) << "x";
  r = RunProgram("run " + Data("ok.yaml") + " --steps 1 --quiet --out " + file);
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("error: --out: '" + file + "' is not a folder; pass a folder"),
            std::string::npos)
      << r.output;
  std::filesystem::remove(file);
}

}  // namespace
