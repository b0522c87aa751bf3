// `swarmsim run --save-state FILE [--save-state-at STEP]` and `--load-state
// FILE` (framework/world_state.h): a run resumed from a saved state ends with
// the hash of the uninterrupted run that saved it, the summary says where it
// resumed, and what cannot be saved or loaded is a clear error before the run.
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "tests/swarm/run_program.h"

namespace {

namespace fs = std::filesystem;
using swarmsim::testing::FreshTempDir;
using swarmsim::testing::ReadFile;
using swarmsim::testing::RunCommand;
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
    const std::string whole_out = (dir / "whole").string();
    const auto whole =
        RunProgram("run " + kWorld + set + " --steps 30 --save-state-at 12 --save-state " + state +
                   " --hash --quiet --out " + whole_out);
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
    // The real-time factor is of this run's 1.8 s (it divided all 3 s of
    // the history by this run's wall time), as robot-ticks/s counts 18 steps.
    EXPECT_NEAR(summary["real_time_factor"].get<double>() * summary["wall_time"].get<double>(), 1.8,
                1e-9);
    EXPECT_NEAR(summary["simulated_time"].get<double>(), 3.0, 1e-9);
    // The resumed run's metrics.csv is the whole history, row for row (it
    // held the rows from step 10 on only, step 10's twice over the two files).
    const std::string history = ReadFile(fs::path(whole_out) / "metrics.csv");
    EXPECT_NE(history.find("\n5,0.5,,covered_area,"), std::string::npos) << history;
    EXPECT_EQ(ReadFile(dir / "out" / "metrics.csv"), history) << physics;
    // Resumed into the saved run's own folder: nothing of it lost.
    ASSERT_EQ(RunProgram("run " + kWorld + set + " --steps 18 --load-state " + state +
                         " --quiet --out " + whole_out)
                  .exit_code,
              0);
    EXPECT_EQ(ReadFile(fs::path(whole_out) / "metrics.csv"), history) << physics;
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
  // Its Python advice, placed for a program that runs no Python controller.
  EXPECT_NE(lua.output.find("(swarmsim run saves worlds whose robots run no script or controller; "
                            "a world driven from Python saves with World.snapshot()"),
            std::string::npos)
      << lua.output;
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

// The state is written beside its name and renamed over it: --save-state
// /dev/null turned the system's /dev/null into a file (exit 0), a world
// file was overwritten; --load-state of a folder threw a stream's error, of
// a pipe or /dev/zero never ended.
TEST(SaveStateTest, DevicesPipesFoldersAndTheWorldFileAreNoStateFiles) {
  const fs::path dir = FreshTempDir("swarmsim_save_state", "special");
  fs::create_directories(dir / "models");
  fs::copy_file(kWorld, dir / "w.yaml");
  fs::copy_file(fs::path(kWorld).parent_path() / "models" / "circler.yaml",
                dir / "models" / "circler.yaml");
  const std::string world = (dir / "w.yaml").string();
  ASSERT_EQ(::mkfifo((dir / "pipe").c_str(), 0600), 0);
  // (A broken check would hang on the pipe: `timeout` ends it.)
  const std::string program = "timeout 120 " + std::string(SWARMSIM_BINARY);
  auto r =
      RunCommand(program + " run " + world + " --steps 1 --save-state " + (dir / "pipe").string());
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("--save-state: '" + (dir / "pipe").string() +
                          "': it is a FIFO (named pipe), not an ordinary file: name a file"),
            std::string::npos)
      << r.output;
  EXPECT_TRUE(fs::is_fifo(dir / "pipe"));
  r = RunCommand(program + " run " + world + " --steps 1 --save-state " + world);
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("is the world file: name another file"), std::string::npos) << r.output;
  EXPECT_EQ(ReadFile(world), ReadFile(kWorld));
  // A symbolic link is written through: the link stays, its target is the state.
  fs::create_symlink(dir / "target.bin", dir / "link.bin");
  r = RunCommand(program + " run " + world + " --steps 1 --save-state " +
                 (dir / "link.bin").string());
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_TRUE(fs::is_symlink(dir / "link.bin"));
  EXPECT_TRUE(fs::is_regular_file(fs::symlink_status(dir / "target.bin")));
  EXPECT_EQ(RunCommand(program + " run " + world + " --steps 1 --load-state " +
                       (dir / "link.bin").string())
                .exit_code,
            0);
  for (const auto& [file, what] :
       {std::pair{dir / "models", "a folder"}, std::pair{dir / "pipe", "a FIFO (named pipe)"}}) {
    r = RunCommand(program + " run " + world + " --steps 1 --load-state " + file.string());
    EXPECT_EQ(r.exit_code, 2) << r.output;
    EXPECT_NE(r.output.find("--load-state: cannot read '" + file.string() + "': " + what),
              std::string::npos)
        << r.output;
  }
  // The run's own files in --out: a pipe named summary.json hung the run, a
  // folder named so threw a stream's error naming no file.
  fs::create_directories(dir / "out" / "summary.json");
  r = RunCommand(program + " run " + world + " --steps 1 --out " + (dir / "out").string());
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("error: --out: '" + (dir / "out" / "summary.json").string() +
                          "': it is a folder, not an ordinary file, and the run writes its "
                          "summary.json there"),
            std::string::npos)
      << r.output;
  fs::create_directories(dir / "out2");
  ASSERT_EQ(::mkfifo((dir / "out2" / "metrics.csv").c_str(), 0600), 0);
  r = RunCommand(program + " run " + world + " --steps 1 --out " + (dir / "out2").string());
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("it is a FIFO (named pipe), not an ordinary file, and the run writes its "
                          "metrics.csv there"),
            std::string::npos)
      << r.output;
  fs::remove_all(dir);
}

// A recording, a video or pictures cannot go on from a snapshot, nor can a
// camera's images or a graph: refused before the first step, naming the
// option or the module (the whole run went first, then "the world's module
// 'observer' cannot save its state", exit 1, no state written).
TEST(SaveStateTest, RecordingsCamerasAndGraphsAreRefusedBeforeTheRun) {
  const fs::path dir = FreshTempDir("swarmsim_save_state", "recordings");
  fs::create_directories(dir);
  const std::string state = (dir / "s.bin").string();
  const std::string out = (dir / "out").string();
  for (const std::string& flag :
       {std::string("--record"), "--video " + out + "/v.mp4", std::string("--snapshot-every 2")}) {
    const auto refused = RunProgram("run " + kWorld + " --steps 3 --out " + out + " " + flag +
                                    " --save-state " + state);
    EXPECT_EQ(refused.exit_code, 2) << flag << ": " << refused.output;
    EXPECT_NE(refused.output.find("--save-state: not with " + flag.substr(0, flag.find(' ')) +
                                  ": a snapshot holds no recording"),
              std::string::npos)
        << refused.output;
    EXPECT_EQ(refused.output.find("steps           "), std::string::npos) << refused.output;
    EXPECT_FALSE(fs::exists(state));
  }
  ASSERT_EQ(RunProgram("run " + kWorld + " --steps 3 --save-state " + state).exit_code, 0);
  const auto resumed =
      RunProgram("run " + kWorld + " --steps 3 --out " + out + " --record --load-state " + state);
  EXPECT_EQ(resumed.exit_code, 2) << resumed.output;
  EXPECT_NE(resumed.output.find("--load-state: not with --record"), std::string::npos)
      << resumed.output;
  // The world's own record: setting is left out, with a note.
  const fs::path recorded = dir / "recorded.yaml";
  std::ofstream(recorded) << "record: true\n" << ReadFile(kWorld);
  fs::create_directories(dir / "models");
  fs::copy_file(fs::path(kWorld).parent_path() / "models" / "circler.yaml",
                dir / "models" / "circler.yaml", fs::copy_options::overwrite_existing);
  const auto noted = RunProgram("run " + recorded.string() + " --steps 3 --out " + out +
                                " --save-state " + (dir / "r.bin").string());
  EXPECT_EQ(noted.exit_code, 0) << noted.output;
  EXPECT_NE(noted.output.find("note: the world's record: setting is not followed with "
                              "--save-state"),
            std::string::npos)
      << noted.output;
  EXPECT_TRUE(fs::exists(dir / "r.bin"));
  EXPECT_FALSE(fs::exists(fs::path(out) / "recording.swrec"));
  // A world whose modules cannot save (a graph here): refused as it starts,
  // before its first step.
  const fs::path graphed = dir / "graph.yaml";
  std::ofstream(graphed) << "simulation: {physics: box2d, time_step: 0.1, steps: 5}\n"
                            "obstacles:\n"
                            "  - {name: box, shape: box, size: [0.1, 0.1, 0.1], position: [0, 0, "
                            "0.05], dynamic: true, mass: 1}\n"
                            "objects:\n"
                            "  - {name: h, type: graph, streams: [\"z = position /box z\"]}\n";
  fs::remove(state);
  const auto graph = RunProgram("run " + graphed.string() + " --steps 3 --save-state " + state);
  EXPECT_EQ(graph.exit_code, 1) << graph.output;  // as the world starts: its modules are there
  EXPECT_NE(graph.output.find("--save-state: the world's module 'graphs' cannot save its state"),
            std::string::npos)
      << graph.output;
  EXPECT_EQ(graph.output.find("steps           "), std::string::npos) << graph.output;
  EXPECT_FALSE(fs::exists(state));
}

}  // namespace
