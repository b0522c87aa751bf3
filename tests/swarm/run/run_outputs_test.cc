// What `swarmsim run --out` leaves behind, also when a run is cut short:
// metrics.csv as proper CSV, written as the run goes; summary.json with the
// scripts that were disabled and the signal that stopped the run.
#include <gtest/gtest.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "modules/rendering/video/video_writer.h"
#include "tests/swarm/run_program.h"
#include "tests/text_lines.h"

extern char** environ;

namespace {

namespace fs = std::filesystem;
using swarmsim::testing::ProbeWorld;
using swarmsim::testing::ReadFile;
using swarmsim::testing::RunProgram;

std::string Data(const std::string& name) { return swarmsim::testing::CliData(name); }

fs::path TempDir(const std::string& name) {
  return swarmsim::testing::FreshTempDir("swarmsim_outputs", name);
}

std::vector<std::string> Lines(const std::string& text) {
  return swarmsim::testing::TextLines(text);
}

// Memory that ran out said "error: std::bad_alloc" (summary.json too),
// naming neither when nor what might have taken it: here a camera of
// 8192 x 8192 pixels under a 1 GB address-space cap.
TEST(RunOutputsTest, RunningOutOfMemorySaysWhenAndWhatGrows) {
  const std::string cap = swarmsim::testing::AddressSpaceLimit(1000000);
  if (cap.empty()) GTEST_SKIP() << "no address-space cap under AddressSanitizer";
  const fs::path dir = TempDir("oom");
  fs::create_directories(dir);
  std::ofstream(dir / "w.yaml") << "simulation: {physics: kinematic, time_step: 0.1}\n"
                                   "objects:\n  - {name: cam, type: vision_sensor, "
                                   "resolution: [8192, 8192], position: [0, 0, 1]}\n";
  const auto r = swarmsim::testing::RunCommand(cap + std::string(SWARMSIM_BINARY) + " run " +
                                               (dir / "w.yaml").string() + " --steps 2 --out " +
                                               (dir / "out").string());
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find("error: out of memory as the world started (the machine, a ulimit or "
                          "--max-memory gave no more; what grows besides the robots: cameras' "
                          "and vision sensors' images"),
            std::string::npos)
      << r.output;
  EXPECT_NE(ReadFile(dir / "out" / "summary.json").find("out of memory as the world started"),
            std::string::npos);
  fs::remove_all(dir);
}

TEST(RunOutputsTest, MetricNamesAreCsvQuotedAndNanIsSpelledNan) {
  const fs::path out = TempDir("csv");
  const auto r =
      RunProgram("run " + Data("outputs.yaml") + " --steps 2 --quiet --out " + out.string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const std::vector<std::string> lines = Lines(ReadFile(out / "metrics.csv"));
  ASSERT_EQ(lines.size(), 1u + 2 * 3 * 2) << "header + 2 steps x 3 robots x 2 metrics";
  EXPECT_EQ(lines[0], "step,time,robot,metric,value");
  // Step 0 is the first control step (t = 0); robot outputs#0's two samples.
  EXPECT_EQ(lines[1], "0,0,outputs#0,\"a,b\"\"c\",0");
  EXPECT_EQ(lines[2], "0,0,outputs#0,undefined,nan");
  fs::remove_all(out);
}

TEST(RunOutputsTest, DisabledScriptsAreReportedInTheSummary) {
  const fs::path out = TempDir("disabled");
  const auto r = RunProgram("run " + Data("outputs.yaml") + " --steps 6 --out " + out.string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("disabled scripts 1 (on_script_error: disable_script), first: "
                          "outputs#1: "),
            std::string::npos)
      << r.output;
  const auto summary = nlohmann::json::parse(ReadFile(out / "summary.json"));
  EXPECT_EQ(summary["status"], "ok");
  ASSERT_EQ(summary["disabled_scripts"].size(), 1u) << summary.dump(2);
  const std::string why = summary["disabled_scripts"][0];
  EXPECT_NE(why.find("outputs#1: "), std::string::npos) << why;
  EXPECT_NE(why.find("outputs.lua:13: robot one gives up"), std::string::npos) << why;
  fs::remove_all(out);
}

// A run stopped by SIGTERM (a sweep's timeout, a batch system, Ctrl-C's
// SIGINT alike) ends at a step boundary with everything written, and exits
// 128 + 15 as a shell expects.
// Spawns `swarmsim ARGS...` without waiting; returns its pid.
pid_t Spawn(std::vector<std::string> args) {
  args.insert(args.begin(), SWARMSIM_BINARY);
  std::vector<char*> argv;
  for (std::string& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  pid_t pid = 0;
  if (posix_spawn(&pid, argv[0], nullptr, nullptr, argv.data(), environ) != 0) return -1;
  return pid;
}

// Waits (for a condition, not a time) until metrics.csv holds rows beyond
// its header; returns its size then (0 if it never did within two minutes).
size_t WaitForRows(const fs::path& csv) {
  const auto give_up = std::chrono::steady_clock::now() + std::chrono::seconds(120);
  while (std::chrono::steady_clock::now() < give_up) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    const std::string text = ReadFile(csv);
    if (Lines(text).size() > 1) return text.size();
  }
  return 0;
}

// A slow run with sparse rows (one ~25-byte row a step, a step taking tens
// of milliseconds, so a few hundred bytes a second on any machine): rows must reach the file while
// it is far smaller than a stream buffer, i.e. flushed by time, not when a buffer fills.
TEST(RunOutputsTest, SparseMetricsReachTheFileWhileTheRunGoesOn) {
  const fs::path out = TempDir("sparse");
  const pid_t pid = Spawn({"run", Data("outputs.yaml"), "--set", "outputs.slow=1", "--steps",
                           "1000000000", "--out", out.string(), "--quiet"});
  ASSERT_GT(pid, 0);
  const size_t size = WaitForRows(out / "metrics.csv");
  kill(pid, SIGKILL);  // as a sweep's --timeout does: nothing gets written after this
  waitpid(pid, nullptr, 0);
  EXPECT_GT(size, 0u) << "no rows reached metrics.csv while the run went on";
  EXPECT_LT(size, 4096u) << "rows arrived only when a buffer filled";
  fs::remove_all(out);
}

// Sends SIGTERM to run `pid`, checks it exits 128 + 15 with summary.json's
// status 'interrupted', and returns the summary ({} if there is none).
nlohmann::json TerminateAndReadSummary(pid_t pid, const fs::path& out) {
  EXPECT_EQ(kill(pid, SIGTERM), 0);
  int status = 0;
  EXPECT_EQ(waitpid(pid, &status, 0), pid);
  EXPECT_TRUE(WIFEXITED(status)) << "killed by signal " << WTERMSIG(status);
  EXPECT_EQ(WEXITSTATUS(status), 128 + SIGTERM);
  const nlohmann::json summary =
      nlohmann::json::parse(ReadFile(out / "summary.json"), nullptr, /*allow_exceptions=*/false);
  if (!summary.is_object()) {
    ADD_FAILURE() << "no summary.json";
    return nlohmann::json::object();
  }
  EXPECT_EQ(summary.value("status", ""), "interrupted");
  return summary;
}

TEST(RunOutputsTest, TerminatedRunKeepsItsOutputsAndSaysSo) {
  const fs::path out = TempDir("sigterm");
  const pid_t pid = Spawn(
      {"run", Data("outputs.yaml"), "--steps", "1000000000", "--out", out.string(), "--quiet"});
  ASSERT_GT(pid, 0);
  EXPECT_GT(WaitForRows(out / "metrics.csv"), 0u) << "the run never got going";

  const nlohmann::json summary = TerminateAndReadSummary(pid, out);
  const std::string error = summary.value("error", "");
  EXPECT_EQ(error.rfind("interrupted by SIGTERM after ", 0), 0u) << error;
  const int64_t steps = summary["steps"];
  EXPECT_GT(steps, 0);
  const std::string metrics = ReadFile(out / "metrics.csv");
  ASSERT_FALSE(metrics.empty());
  EXPECT_EQ(metrics.back(), '\n') << "the last row is complete";
  // Every completed step's rows are there: robots 0 and 2 record 2 metrics
  // a step throughout; robot 1 until its script is disabled at t = 0.3.
  EXPECT_GE(Lines(metrics).size(), 1u + static_cast<size_t>(steps) * 4);
  fs::remove_all(out);
}

// A world whose one robot records its time every step and, from step 4 on,
// gets stuck in one C call the instruction budget cannot stop (a pattern
// match backtracking over 300,000 characters: hours). It writes 'stuck' to
// the run's folder first.
fs::path StuckWorld(const std::string& name, const std::string& step_timeout) {
  return ProbeWorld("swarmsim_outputs", name, "step_timeout: " + step_timeout,
                    "function sysCall_actuation()\n"
                    "  sim.recordMetric('t', sim.getSimulationTime())\n"
                    "  if sim.getSimulationTime() > 0.25 then\n"
                    "    io.open('stuck', 'w'):close()\n"
                    "    print('about to get stuck')\n"
                    "    return string.rep('a', 300000):find('.-.-b')\n"
                    "  end\n"
                    "end\n");
}

// The watchdog: a step stuck past simulation.step_timeout ends the run with
// the calls in progress named and the outputs written.
TEST(RunOutputsTest, StuckStepEndsTheRunNamingTheScriptAndKeepsTheOutputs) {
  const fs::path dir = StuckWorld("stuck", "1");
  const auto r = RunProgram("run " + (dir / "world.yaml").string() + " --steps 100 --out " +
                            (dir / "out").string());
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find("error: step 4 of 100 did not finish within 1 s "
                          "(simulation.step_timeout); running: probe#0: "),
            std::string::npos)
      << r.output;
  EXPECT_NE(r.output.find("probe.lua, in sysCall_actuation of /probe#0"), std::string::npos)
      << r.output;
  EXPECT_NE(r.output.find("outputs of the 3 steps that finished are in"), std::string::npos)
      << "steps counted as in the error (step 4 did not finish): " << r.output;
  // What the script printed in the stuck step comes before the error.
  const size_t printed = r.output.find("[probe#0] about to get stuck\n");
  EXPECT_NE(printed, std::string::npos) << r.output;
  EXPECT_LT(printed, r.output.find("error: step 4")) << r.output;
  const auto summary = nlohmann::json::parse(ReadFile(dir / "out" / "summary.json"));
  EXPECT_EQ(summary["status"], "error");
  EXPECT_EQ(summary["steps"], 3);
  EXPECT_NE(std::string(summary["error"]).find("did not finish"), std::string::npos);
  EXPECT_TRUE(summary["state_hash"].is_null()) << "a stuck step's state is not a state";
  const std::vector<std::string> rows = Lines(ReadFile(dir / "out" / "metrics.csv"));
  ASSERT_EQ(rows.size(), 1u + 3) << "the header and steps 1-3";
  EXPECT_EQ(rows[3], "2,0.2,probe#0,t,0.2");
  fs::remove_all(dir);
}

// The start of the world (every robot's sysCall_init) is watched too, and
// may take simulation.step_timeout for each 10,000 robots: a million Lua
// robots take about 45 s to start on a 2-core VM, and must not be ended as
// stuck for being many.
TEST(RunOutputsTest, AStuckStartEndsTheRunWithALimitThatGrowsWithTheRobots) {
  const fs::path dir = swarmsim::testing::FreshTempDir("swarmsim_outputs", "stuck_start");
  fs::create_directories(dir);
  std::ofstream(dir / "probe.yaml") << "model: probe\n"
                                       "objects: {name: body, type: dummy, script: probe.lua}\n";
  std::ofstream(dir / "probe.lua") << "function sysCall_init()\n"
                                      "  return string.rep('a', 300000):find('.-.-b')\n"
                                      "end\n";
  for (const auto& [robots, limit] : {std::pair{1, "1"}, std::pair{20000, "2"}}) {
    std::ofstream(dir / "world.yaml") << "simulation: {physics: kinematic, time_step: 0.1, "
                                         "step_timeout: 1}\n"
                                         "arena: {size: 300}\n"
                                         "models:\n  - {model: probe.yaml, count: "
                                      << robots << ", distribute: {region: arena}}\n";
    const auto r = RunProgram("run " + (dir / "world.yaml").string() + " --steps 5 --quiet --out " +
                              (dir / "out").string());
    EXPECT_EQ(r.exit_code, 1) << r.output;
    EXPECT_NE(
        r.output.find(std::string("error: the start of the world did not finish within ") + limit +
                      " s (simulation.step_timeout, for each 10,000 robots); "
                      "running: probe#"),
        std::string::npos)
        << robots << " robots: " << r.output;
    const auto summary = nlohmann::json::parse(ReadFile(dir / "out" / "summary.json"));
    EXPECT_EQ(summary["status"], "error");
    EXPECT_EQ(summary["steps"], 0);
    EXPECT_FALSE(fs::exists(dir / "out" / ".swarmsim-lock")) << "left by the ended run";
  }
  fs::remove_all(dir);
}

// A run the watchdog ends finishes its video before summary.json: the
// frames encoded but not yet in a written fragment (up to a second of
// video) were lost, and the summary counted them all.
TEST(RunOutputsTest, StuckStepFinishesTheVideoTheSummaryCounts) {
  const fs::path dir = StuckWorld("stuck_video", "1");
  const auto r = RunProgram("run " + (dir / "world.yaml").string() +
                            " --steps 100 --quiet --video --out " + (dir / "out").string());
  EXPECT_EQ(r.exit_code, 1) << r.output;
  const auto summary = nlohmann::json::parse(ReadFile(dir / "out" / "summary.json"));
  EXPECT_EQ(summary["steps"], 3);
  std::string description;
  for (const auto& output : summary["outputs"])
    if (output["kind"] == "video") description = output["description"].get<std::string>();
  swarmsim::video::VideoReader reader(dir / "out" / "video.mp4");
  swarmsim::Image frame;
  int frames = 0;
  while (reader.Next(&frame)) ++frames;
  EXPECT_EQ(frames, 4) << "steps 0 to 3, each a frame at 10 frames/s";
  EXPECT_NE(description.find(", 4 frames, "), std::string::npos) << description;
  // Its folder's lock went with the process and is not left behind.
  EXPECT_FALSE(fs::exists(dir / "out" / ".swarmsim-lock"));
  fs::remove_all(dir);
}

// A run the watchdog ends still closes its recording with the end chunk
// (record-info says how it ended, not "no end yet").
TEST(RunOutputsTest, StuckStepClosesTheRecording) {
  const fs::path dir = StuckWorld("stuck_record", "1");
  const auto r = RunProgram("run " + (dir / "world.yaml").string() +
                            " --steps 100 --quiet --record --out " + (dir / "out").string());
  EXPECT_EQ(r.exit_code, 1) << r.output;
  const auto info = RunProgram("record-info " + (dir / "out" / "recording.swrec").string());
  EXPECT_EQ(info.exit_code, 0) << info.output;
  EXPECT_EQ(info.output.find("no end yet"), std::string::npos) << info.output;
  EXPECT_NE(info.output.find("the run ended (error: step 4 of 100 did not finish within 1 s"),
            std::string::npos)
      << info.output;
  fs::remove_all(dir);
}

// A stop signal after the last step's check (here from the script's
// cleanup, while the world stops) is not lost: the run ends as interrupted,
// 128 + the signal, saying every step was run.
TEST(RunOutputsTest, StopSignalAfterTheLastStepEndsTheRunAsInterrupted) {
  const fs::path dir =
      ProbeWorld("swarmsim_outputs", "late_signal", "",
                 "function sysCall_cleanup() os.execute('kill -TERM $PPID') end\n");
  const fs::path out = dir / "out";
  const auto r = RunProgram("run " + (dir / "world.yaml").string() +
                            " --steps 3 --quiet --trust-scripts --record --out " + out.string());
  EXPECT_EQ(r.exit_code, 128 + SIGTERM) << r.output;
  EXPECT_NE(r.output.find("error: interrupted by SIGTERM after all 3 steps"), std::string::npos)
      << r.output;
  const auto summary = nlohmann::json::parse(ReadFile(out / "summary.json"));
  EXPECT_EQ(summary["status"], "interrupted");
  EXPECT_EQ(summary["steps"], 3);
  const auto info = RunProgram("record-info " + (out / "recording.swrec").string());
  EXPECT_NE(info.output.find("the run ended (interrupted"), std::string::npos) << info.output;
  fs::remove_all(dir);
}

// A stop signal after summary.json was written (here raised inside the
// program as it writes the recording's end, its last output, by
// late_signal_preload.cc) changes nothing: the run is complete, the program
// exits 0 as its summary says, and the recording is closed. (The signals
// used to be let go once the summary was written: such a signal killed the
// program before the recording's end.)
TEST(RunOutputsTest, StopSignalAfterTheSummaryChangesNothing) {
  const fs::path dir =
      ProbeWorld("swarmsim_outputs", "after_summary", "", "function sysCall_actuation() end\n");
  const fs::path out = dir / "out";
  const auto r = swarmsim::testing::RunCommand(
      std::string("LD_PRELOAD=" LATE_SIGNAL_PRELOAD
                  " ASAN_OPTIONS=\"$ASAN_OPTIONS:verify_asan_link_order=0\" " SWARMSIM_BINARY
                  " run ") +
      (dir / "world.yaml").string() + " --steps 3 --quiet --record --out " + out.string());
  ASSERT_TRUE(fs::exists(out / "late_signal_raised")) << "no signal was raised:\n" << r.output;
  EXPECT_EQ(r.exit_code, 0) << r.output;
  const auto summary = nlohmann::json::parse(ReadFile(out / "summary.json"));
  EXPECT_EQ(summary["status"], "ok");
  EXPECT_EQ(summary["steps"], 3);
  const auto info = RunProgram("record-info " + (out / "recording.swrec").string());
  EXPECT_NE(info.output.find("the run ended (ok"), std::string::npos) << info.output;
  fs::remove_all(dir);
}

// Without a timeout, a stop signal still ends a stuck step: a few seconds
// after it, with status 'interrupted' and 128 + signal.
TEST(RunOutputsTest, StopSignalEndsAStuckStep) {
  const fs::path dir = StuckWorld("stuck_signal", "0");
  const fs::path out = dir / "out";
  const pid_t pid = Spawn(
      {"run", (dir / "world.yaml").string(), "--steps", "100", "--out", out.string(), "--quiet"});
  ASSERT_GT(pid, 0);
  const auto give_up = std::chrono::steady_clock::now() + std::chrono::seconds(120);
  while (!fs::exists(out / "stuck") && std::chrono::steady_clock::now() < give_up)
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  ASSERT_TRUE(fs::exists(out / "stuck"));
  const std::string error = TerminateAndReadSummary(pid, out).value("error", "");
  EXPECT_EQ(error.rfind("interrupted by SIGTERM during step 4 of 100, which did not finish", 0), 0u)
      << error;
  EXPECT_NE(error.find("probe#0: "), std::string::npos) << error;
  EXPECT_EQ(Lines(ReadFile(out / "metrics.csv")).size(), 1u + 3);
  fs::remove_all(dir);
}

// A binary STL of `triangles` triangles, each with corners of its own (a
// scattered cloud: nothing to weld), written to `path`.
void WriteScatteredStl(const fs::path& path, uint32_t triangles) {
  std::string bytes(80, '\0');
  bytes.append(reinterpret_cast<const char*>(&triangles), 4);
  uint32_t state = 12345;
  const auto next = [&state] {  // in [-5, 5)
    state = state * 1664525u + 1013904223u;
    return static_cast<float>(state >> 8) / static_cast<float>(1 << 24) * 10.0f - 5.0f;
  };
  for (uint32_t i = 0; i < triangles; ++i) {
    const float x = next(), y = next(), z = next() * 0.1f + 1.0f;
    const float facet[12] = {0, 0, 1, x, y, z, x + 0.01f, y, z, x, y + 0.01f, z + 0.005f};
    bytes.append(reinterpret_cast<const char*>(facet), sizeof facet);
    bytes.append(2, '\0');
  }
  std::ofstream(path, std::ios::binary) << bytes;
}

// A stop signal while one large mesh file loads (seconds for a million
// triangles) ends the run then, not once the load is over: the loader asks
// for it inside the mesh's read and build, and says where it stopped.
TEST(RunOutputsTest, StopSignalDuringALargeMeshLoadEndsTheRunThere) {
  const fs::path dir = swarmsim::testing::FreshTempDir("swarmsim_outputs", "mesh_signal");
  fs::create_directories(dir);
  WriteScatteredStl(dir / "big.stl", 400000);
  std::ofstream(dir / "world.yaml") << "simulation: {physics: ode, time_step: 0.01}\n"
                                       "obstacles:\n"
                                       "  - {name: rock, shape: mesh, file: big.stl}\n";
  const fs::path out = dir / "out";
  // Its output on a pipe: the note that the mesh file is being read.
  int pipe_fds[2];
  ASSERT_EQ(pipe(pipe_fds), 0);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_adddup2(&actions, pipe_fds[1], STDOUT_FILENO);
  posix_spawn_file_actions_adddup2(&actions, pipe_fds[1], STDERR_FILENO);
  posix_spawn_file_actions_addclose(&actions, pipe_fds[0]);
  std::vector<std::string> args = {SWARMSIM_BINARY, "run", (dir / "world.yaml").string(),
                                   "--steps",       "10",  "--out",
                                   out.string()};
  std::vector<char*> argv;
  for (std::string& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  pid_t pid = 0;
  ASSERT_EQ(posix_spawn(&pid, argv[0], &actions, nullptr, argv.data(), environ), 0);
  posix_spawn_file_actions_destroy(&actions);
  close(pipe_fds[1]);
  FILE* output = fdopen(pipe_fds[0], "r");
  std::string text;
  char line[4096];
  bool signalled = false;
  while (fgets(line, sizeof line, output) != nullptr) {
    text += line;
    if (!signalled && text.find("note: reading mesh file 'big.stl'") != std::string::npos) {
      EXPECT_EQ(kill(pid, SIGTERM), 0);
      signalled = true;
    }
  }
  fclose(output);
  int status = 0;
  ASSERT_EQ(waitpid(pid, &status, 0), pid);
  ASSERT_TRUE(signalled) << "the load never said it read the mesh file:\n" << text;
  ASSERT_TRUE(WIFEXITED(status)) << "killed by signal " << WTERMSIG(status);
  EXPECT_EQ(WEXITSTATUS(status), 128 + SIGTERM) << text;
  // Noticed inside the mesh's load: without the checks there, the load
  // would run to its end and the signal be noticed only after it.
  EXPECT_NE(text.find("error: interrupted by SIGTERM while the world was loading, reading mesh "
                      "file 'big.stl'"),
            std::string::npos)
      << text;
  const auto summary = nlohmann::json::parse(ReadFile(out / "summary.json"));
  EXPECT_EQ(summary["status"], "interrupted");
  fs::remove_all(dir);
}

// A run ended by a script error still reports the Lua memory its scripts held.
TEST(RunOutputsTest, FailedRunReportsItsLuaMemory) {
  const fs::path dir = ProbeWorld("swarmsim_outputs", "failed_memory", "",
                                  "big = string.rep('x', 100000)\n"
                                  "function sysCall_actuation()\n"
                                  "  if sim.getSimulationTime() > 0.15 then error('boom') end\n"
                                  "end\n");
  const auto r = RunProgram("run " + (dir / "world.yaml").string() + " --steps 5 --quiet --out " +
                            (dir / "out").string());
  EXPECT_EQ(r.exit_code, 1) << r.output;
  const auto summary = nlohmann::json::parse(ReadFile(dir / "out" / "summary.json"));
  EXPECT_EQ(summary["status"], "error");
  EXPECT_GT(summary["lua_memory_kib"].get<double>(), 100) << "the 100 kB string at least";
  EXPECT_EQ(summary["robots_per_lua_state"], 1);  // the world does not ask for sharing
  fs::remove_all(dir);
}

// With no instruction budget a plain endless loop is stopped by the watchdog
// too, and the message says why nothing stopped it sooner.
TEST(RunOutputsTest, StuckStepWithoutABudgetSaysTheBudgetIsOff) {
  const fs::path dir =
      ProbeWorld("swarmsim_outputs", "no_budget", "instruction_budget: 0, step_timeout: 1",
                 "function sysCall_actuation() while true do end end\n");
  const auto r = RunProgram("run " + (dir / "world.yaml").string() + " --steps 5 --quiet");
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find("step 1 of 5 did not finish within 1 s"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("simulation.instruction_budget is 0, no limit"), std::string::npos)
      << r.output;
  fs::remove_all(dir);
}

// summary.json names every --set, model parameters included, and shows
// whole-number parameters as integers.
TEST(RunOutputsTest, SummaryListsTheOverridesAndWholeNumbersAsIntegers) {
  const fs::path dir = TempDir("overrides");
  fs::create_directories(dir);
  std::ofstream(dir / "world.yaml") << "simulation: {physics: kinematic, time_step: 0.1}\n"
                                       "parameters: {robots: 2, spacing: 0.5}\n"
                                       "models:\n  - {model: probe.yaml, count: $robots, "
                                       "distribute: {region: {min: [-5, -5], max: [5, 5]}}}\n";
  std::ofstream(dir / "probe.yaml") << "model: probe\n"
                                       "parameters: {speed: {default: 0.1}}\n"
                                       "objects: {name: body, type: dummy}\n";
  const auto r = RunProgram("run " + (dir / "world.yaml").string() +
                            " --steps 1 --quiet --set robots=3 --set probe.speed=0.2 --out " +
                            (dir / "out").string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const auto summary = nlohmann::json::parse(ReadFile(dir / "out" / "summary.json"));
  EXPECT_TRUE(summary["parameters"]["robots"].is_number_integer()) << summary.dump();
  EXPECT_EQ(summary["parameters"]["robots"], 3);
  EXPECT_EQ(summary["parameters"]["spacing"], 0.5);
  EXPECT_EQ(summary["overrides"], nlohmann::json({{"robots", "3"}, {"probe.speed", "0.2"}}));
  fs::remove_all(dir);
}

// A folder with a world of one robot (a dummy) whose script is `lua` (bot.lua).
fs::path OneScriptedRobot(const std::string& name, const std::string& lua) {
  const fs::path dir = TempDir(name);
  fs::create_directories(dir);
  std::ofstream(dir / "world.yaml") << "simulation: {physics: kinematic, time_step: 0.1}\n"
                                       "models:\n  - {model: bot.yaml, position: [0, 0]}\n";
  std::ofstream(dir / "bot.yaml") << "model: bot\n"
                                     "objects: {name: body, type: dummy, script: bot.lua}\n";
  std::ofstream(dir / "bot.lua") << lua;
  return dir;
}

// A run that fails before its first step prints its error, not a table of
// zeros; one that fails later prints the table of what it ran.
// An --out folder an earlier run wrote to: a recorded 2-step run's outputs,
// and a file of the user's (notes.txt) that no run may touch.
void EarlierRunInto(const fs::path& out) {
  const auto r = RunProgram("run " + Data("outputs.yaml") + " --steps 2 --quiet --record --out " +
                            out.string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  ASSERT_TRUE(fs::exists(out / "recording.swrec"));
  ASSERT_TRUE(fs::exists(out / "metrics.csv"));
  std::ofstream(out / "notes.txt") << "mine\n";
}

// --out DIR again: the earlier run's outputs (as its summary.json lists
// them) go, so the folder holds one run, not new metrics beside an old
// recording. Nothing else is touched: files of the user's, paths outside DIR.
TEST(RunOutputsTest, AnOutFolderUsedAgainHoldsTheNewRunAlone) {
  const fs::path out = TempDir("again");
  ASSERT_NO_FATAL_FAILURE(EarlierRunInto(out));
  auto r = RunProgram("run " + Data("outputs.yaml") + " --steps 3 --quiet --out " + out.string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("note: removed the outputs of the earlier run in '" + out.string() +
                          "' (1 recording)"),
            std::string::npos)
      << r.output;
  EXPECT_FALSE(fs::exists(out / "recording.swrec")) << "the earlier run's, not this one's";
  EXPECT_TRUE(fs::exists(out / "notes.txt"));
  EXPECT_NE(ReadFile(out / "summary.json").find("\"steps\": 3"), std::string::npos);
  // A summary.json naming files outside the folder removes none of them.
  const fs::path outside = out.parent_path() / "again_outside.txt";
  std::ofstream(outside) << "not ours\n";
  std::ofstream(out / "summary.json")
      << R"({"outputs": [{"kind": "video", "path": "../again_outside.txt"},)"
      << R"( {"kind": "video", "path": ")" << outside.string() << R"("}]})";
  r = RunProgram("run " + Data("outputs.yaml") + " --steps 1 --quiet --out " + out.string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_TRUE(fs::exists(outside));
  EXPECT_EQ(r.output.find("removed the outputs"), std::string::npos) << r.output;
  fs::remove(outside);
  fs::remove_all(out);
}

// A run whose world does not load replaces the folder's summary.json: the
// earlier run's files went unlisted, and stayed beside the next run's.
TEST(RunOutputsTest, ARunThatDoesNotLoadTakesTheEarlierRunsFilesWithIt) {
  const fs::path out = TempDir("failed_load");
  ASSERT_NO_FATAL_FAILURE(EarlierRunInto(out));
  auto r =
      RunProgram("run " + (out / "no_such_world.yaml").string() + " --quiet --out " + out.string());
  EXPECT_EQ(r.exit_code, 2) << r.output;
  // Its metrics named too (the note named the recording alone).
  EXPECT_NE(r.output.find("note: removed the outputs of the earlier run in '" + out.string() +
                          "' (metrics.csv, 1 recording)"),
            std::string::npos)
      << r.output;
  EXPECT_FALSE(fs::exists(out / "recording.swrec"));
  EXPECT_FALSE(fs::exists(out / "metrics.csv")) << "the earlier run's, beside an error summary";
  EXPECT_TRUE(fs::exists(out / "notes.txt")) << "not a run's";
  EXPECT_NE(ReadFile(out / "summary.json").find("\"status\": \"error\""), std::string::npos);
  fs::remove_all(out);
}

// A run killed before its end (kill -9: summary.json still says running,
// listing nothing) left its recording, video and snapshots to the next run
// into the folder, beside that run's summary.
TEST(RunOutputsTest, AKilledRunsFilesGoBeforeTheNextRunWritesItsOwn) {
  const fs::path out = TempDir("killed");
  fs::create_directories(out / "snapshots");
  std::ofstream(out / "summary.json") << R"({"status": "running", "steps": 0, "outputs": []})";
  std::ofstream(out / "recording.swrec") << "old";
  std::ofstream(out / "video.mp4") << "old";
  std::ofstream(out / "snapshots" / "step_000050.png") << "old";
  std::ofstream(out / "notes.txt") << "mine\n";
  const auto r =
      RunProgram("run " + Data("outputs.yaml") + " --steps 2 --quiet --out " + out.string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("note: removed the outputs of the earlier run in '" + out.string() +
                          "' (1 recording, 1 snapshot, 1 video)"),
            std::string::npos)
      << r.output;
  for (const char* gone : {"recording.swrec", "video.mp4", "snapshots"})
    EXPECT_FALSE(fs::exists(out / gone)) << gone;
  EXPECT_TRUE(fs::exists(out / "notes.txt")) << "not a run's";
  fs::remove_all(out);
}

// Two runs into one folder mixed their metrics and snapshots: the second is
// refused, naming the first; the first goes on.
TEST(RunOutputsTest, ASecondRunIntoAFolderInUseIsRefused) {
  const fs::path out = TempDir("busy");
  const pid_t pid = Spawn(
      {"run", Data("outputs.yaml"), "--steps", "1000000000", "--out", out.string(), "--quiet"});
  ASSERT_GT(pid, 0);
  EXPECT_GT(WaitForRows(out / "metrics.csv"), 0u) << "the run never got going";
  const auto second =
      RunProgram("run " + Data("outputs.yaml") + " --steps 2 --quiet --out " + out.string());
  EXPECT_EQ(second.exit_code, 2) << second.output;
  EXPECT_NE(second.output.find("error: --out: another run (process " + std::to_string(pid) +
                               ") is writing into '" + out.string() + "'"),
            std::string::npos)
      << second.output;
  const nlohmann::json summary = TerminateAndReadSummary(pid, out);
  EXPECT_EQ(summary.value("status", ""), "interrupted") << "the first run's, whole";
  EXPECT_FALSE(fs::exists(out / ".swarmsim-lock")) << "released with the run";
  // --video over the run's own metrics.csv wrote H.264 into it (exit 0).
  const auto clash = RunProgram("run " + Data("outputs.yaml") + " --steps 2 --quiet --out " +
                                out.string() + " --video " + (out / "metrics.csv").string());
  EXPECT_EQ(clash.exit_code, 2) << clash.output;
  EXPECT_NE(clash.output.find("is this run's own metrics.csv"), std::string::npos) << clash.output;
  fs::remove_all(out);
}

TEST(RunOutputsTest, ARunThatNeverSteppedPrintsNoSummaryTable) {
  const fs::path dir =
      OneScriptedRobot("never_stepped", "function sysCall_init() error('no start') end\n");
  auto r = RunProgram("run " + (dir / "world.yaml").string() + " --steps 3");
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find("no start"), std::string::npos) << r.output;
  EXPECT_EQ(r.output.find("robot-ticks/s"), std::string::npos) << r.output;
  std::ofstream(dir / "bot.lua") << "local n = 0\n"
                                    "function sysCall_actuation() n = n + 1\n"
                                    "  if n == 2 then error('second step') end end\n";
  r = RunProgram("run " + (dir / "world.yaml").string() + " --steps 3");
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find("second step"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("robot-ticks/s"), std::string::npos) << r.output;
  fs::remove_all(dir);
}

// The wall time of a run includes starting its world (the robots'
// sysCall_init), which the phases do not: summary.json's start_time and the
// table say how much of it that was.
TEST(RunOutputsTest, TheSummarySaysHowMuchOfTheWallTimeStartedTheWorld) {
  // Three million additions at start, nothing in the step.
  const fs::path dir = OneScriptedRobot("start_time",
                                        "function sysCall_init()\n"
                                        "  local x = 0\n"
                                        "  for i = 1, 3000000 do x = x + i end\n"
                                        "end\n");
  const auto r = RunProgram("run " + (dir / "world.yaml").string() + " --steps 2 --out " +
                            (dir / "out").string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find(" s starting the world"), std::string::npos) << r.output;
  const auto summary = nlohmann::json::parse(ReadFile(dir / "out" / "summary.json"));
  const double start = summary["start_time"], wall = summary["wall_time"];
  double phases = 0;
  for (const auto& [phase, seconds] : summary["phase_seconds"].items())
    phases += seconds.get<double>();
  EXPECT_GT(start, 5 * phases) << summary.dump(2);
  EXPECT_LE(start, wall) << summary.dump(2);
  // Loading (reading the file, building the robot) came before the wall time.
  ASSERT_TRUE(summary.contains("load_time")) << summary.dump(2);
  const double load = summary["load_time"];
  EXPECT_GT(load, 0) << summary.dump(2);
  EXPECT_LT(load, start) << "the one robot loads faster than its init runs";
  EXPECT_NE(r.output.find("load time "), std::string::npos) << r.output;
  fs::remove_all(dir);
}

// The summary's steps line names the substeps a backend takes, and none for
// one that takes the control step in one (planar) or has no engine.
TEST(RunOutputsTest, TheSummaryNamesSubstepsOnlyWhereTheyAreTaken) {
  const fs::path dir = TempDir("substeps");
  fs::create_directories(dir);
  std::ofstream(dir / "bot.yaml") << "model: bot\n"
                                     "objects: {name: body, type: shape, shape: cylinder, "
                                     "radius: 0.05, height: 0.1, dynamic: true}\n";
  for (const std::string physics : {"box2d", "planar", "kinematic"}) {
    std::ofstream(dir / "world.yaml")
        << "simulation: {physics: " << physics << ", time_step: 0.1, physics_substeps: 7}\n"
        << "models:\n  - {model: bot.yaml, position: [0, 0]}\n";
    const auto r = RunProgram("run " + (dir / "world.yaml").string() + " --steps 1 --out " +
                              (dir / "out").string());
    ASSERT_EQ(r.exit_code, 0) << physics << ": " << r.output;
    const bool substeps = physics == "box2d";
    const nlohmann::json summary = nlohmann::json::parse(ReadFile(dir / "out" / "summary.json"));
    if (substeps) {
      EXPECT_EQ(summary["physics_substeps"], 7);
    } else {
      EXPECT_TRUE(summary["physics_substeps"].is_null()) << physics;
    }
    EXPECT_EQ(r.output.find("s, " + physics + ", 7 physics substeps)") != std::string::npos,
              substeps)
        << r.output;
    if (!substeps) {
      EXPECT_NE(r.output.find("s, " + physics + ")"), std::string::npos) << r.output;
    }
  }
  fs::remove_all(dir);
}

}  // namespace
