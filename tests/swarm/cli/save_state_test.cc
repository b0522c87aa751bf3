// `swarmsim run --save-state FILE [--save-state-at STEP]` and `--load-state
// FILE` (framework/world_state.h): a run resumed from a saved state ends with
// the hash of the uninterrupted run that saved it, the summary says where it
// resumed, and what cannot be saved or loaded is a clear error before the run.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "tests/swarm/run_program.h"

namespace {

namespace fs = std::filesystem;
using swarmsim::testing::FreshTempDir;
using swarmsim::testing::ReadFile;
using swarmsim::testing::RunProgram;

const std::string kWorld =
    std::string(SWARMSIM_SOURCE_DIR) + "/tests/data/worlds/snapshot_cli.yaml";

std::string HashOf(const std::string& output) {
  const size_t at = output.find("state-hash: ");
  return at == std::string::npos ? "" : output.substr(at + 12, 16);
}

TEST(SaveStateTest, ResumedRunEndsWithTheHashOfTheUninterruptedOne) {
  for (const char* physics : {"box2d", "ode", "planar"}) {
    const fs::path dir = FreshTempDir("swarmsim_save_state", physics);
    fs::create_directories(dir);
    const std::string state = (dir / "s12.bin").string();
    const std::string set = std::string(" --set physics=") + physics;
    const auto whole =
        RunProgram("run " + kWorld + set + " --steps 30 --save-state-at 12 --save-state " + state +
                   " --hash --quiet");
    ASSERT_EQ(whole.exit_code, 0) << whole.output;
    ASSERT_TRUE(fs::exists(state));
    const auto resumed =
        RunProgram("run " + kWorld + set + " --threads 1 --steps 18 --load-state " + state +
                   " --hash --out " + (dir / "out").string());
    ASSERT_EQ(resumed.exit_code, 0) << resumed.output;
    EXPECT_EQ(HashOf(resumed.output), HashOf(whole.output)) << physics;
    EXPECT_NE(resumed.output.find("resumed at      step 12"), std::string::npos) << resumed.output;
    const auto summary = nlohmann::json::parse(ReadFile(dir / "out" / "summary.json"));
    EXPECT_EQ(summary["resumed_from"]["step"], 12);
    EXPECT_EQ(summary["steps"], 18);
    // A state at the end, loaded again with no steps: the same hash.
    const std::string end = (dir / "end.bin").string();
    const auto saved =
        RunProgram("run " + kWorld + set + " --steps 5 --save-state " + end + " --hash");
    ASSERT_EQ(saved.exit_code, 0) << saved.output;
    EXPECT_NE(saved.output.find("state saved     after step 5"), std::string::npos) << saved.output;
    const auto again =
        RunProgram("run " + kWorld + set + " --steps 0 --load-state " + end + " --hash");
    ASSERT_EQ(again.exit_code, 0) << again.output;
    EXPECT_EQ(HashOf(again.output), HashOf(saved.output));
  }
}

TEST(SaveStateTest, WhatCannotBeSavedOrLoadedIsAnErrorBeforeTheRun) {
  const fs::path dir = FreshTempDir("swarmsim_save_state", "errors");
  fs::create_directories(dir);
  // Lua scripts: refused, naming the robot and the script.
  const auto lua = RunProgram("run " + std::string(SWARMSIM_SOURCE_DIR) +
                              "/worlds/diffusion.yaml --set robots=3 --steps 2 --save-state " +
                              (dir / "x.bin").string());
  EXPECT_EQ(lua.exit_code, 2) << lua.output;
  EXPECT_NE(lua.output.find("robot 'footbot#0' runs Lua script"), std::string::npos) << lua.output;
  EXPECT_FALSE(fs::exists(dir / "x.bin"));
  // Native controllers: the robot, the controller and its plugin named, and what to do.
  const auto native = RunProgram("run " + std::string(SWARMSIM_SOURCE_DIR) +
                                 "/worlds/diffusion_native.yaml --set robots=3 --steps 2 "
                                 "--save-state " +
                                 (dir / "x.bin").string());
  EXPECT_EQ(native.exit_code, 2) << native.output;
  EXPECT_NE(native.output.find("robot 'footbot#0' runs the native controller 'diffusion' ("),
            std::string::npos)
      << native.output;
  EXPECT_NE(native.output.find("drive the robots from Python"), std::string::npos) << native.output;
  EXPECT_FALSE(fs::exists(dir / "x.bin"));
  // A missing file, another world's state, a corrupt one.
  const auto missing = RunProgram("run " + kWorld + " --load-state " + (dir / "none.bin").string());
  EXPECT_EQ(missing.exit_code, 2) << missing.output;
  EXPECT_NE(missing.output.find("none.bin"), std::string::npos) << missing.output;
  const std::string state = (dir / "s.bin").string();
  ASSERT_EQ(RunProgram("run " + kWorld + " --steps 3 --save-state " + state).exit_code, 0);
  const auto other = RunProgram("run " + kWorld + " --set robots=25 --load-state " + state);
  EXPECT_EQ(other.exit_code, 2) << other.output;
  EXPECT_NE(other.output.find("24 robots"), std::string::npos) << other.output;
  // Another seed than the state's was ignored without a word.
  const auto seeded = RunProgram("run " + kWorld + " --seed 4 --load-state " + state);
  EXPECT_EQ(seeded.exit_code, 2) << seeded.output;
  EXPECT_NE(seeded.output.find("--seed 4: the run --load-state " + state +
                               " resumes goes on with its own seed ("),
            std::string::npos)
      << seeded.output;
  // The file it writes: not one of the run's own outputs (a summary.json
  // overwritten by the state, exit 0), nor in a folder that is not there
  // (found after the whole run).
  const std::string out = (dir / "out").string();
  const auto own = RunProgram("run " + kWorld + " --steps 2 --out " + out + " --save-state " + out +
                              "/summary.json");
  EXPECT_EQ(own.exit_code, 2) << own.output;
  EXPECT_NE(own.output.find("--save-state: '" + out +
                            "/summary.json' is this run's own "
                            "summary.json (--out " +
                            out + "): name another file"),
            std::string::npos)
      << own.output;
  const auto nowhere =
      RunProgram("run " + kWorld + " --steps 2 --save-state " + (dir / "no" / "s.bin").string());
  EXPECT_EQ(nowhere.exit_code, 2) << nowhere.output;
  EXPECT_NE(nowhere.output.find("there is no folder"), std::string::npos) << nowhere.output;
  std::string bytes = ReadFile(state);
  bytes[bytes.size() / 2] ^= 0x10;
  std::ofstream(dir / "bad.bin", std::ios::binary) << bytes;
  const auto bad = RunProgram("run " + kWorld + " --load-state " + (dir / "bad.bin").string());
  EXPECT_EQ(bad.exit_code, 2) << bad.output;
  EXPECT_NE(bad.output.find("corrupt"), std::string::npos) << bad.output;
  // --save-state-at outside the run.
  const auto late = RunProgram("run " + kWorld + " --steps 3 --save-state-at 9 --save-state " +
                               (dir / "y.bin").string());
  EXPECT_EQ(late.exit_code, 2) << late.output;
}

}  // namespace
