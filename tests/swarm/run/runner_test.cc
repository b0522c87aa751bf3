// What a run leaves when its disk fills up, a file-size limit stops its
// writes, or a stop signal comes while the world still loads: a message
// naming the file and the reason, a nonzero exit, and a summary.json that is
// either whole (valid JSON) or absent, never empty or cut.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "tests/swarm/run_program.h"

namespace {

namespace fs = std::filesystem;
using swarmsim::testing::CliData;
using swarmsim::testing::FreshTempDir;
using swarmsim::testing::ReadFile;
using swarmsim::testing::RunCommand;
using swarmsim::testing::RunProgram;

// summary.json in `out` parsed; null when absent; fails the test when the
// file is there but not whole JSON.
nlohmann::json SummaryIfAny(const fs::path& out) {
  if (!fs::exists(out / "summary.json")) return nullptr;
  const std::string text = ReadFile(out / "summary.json");
  const nlohmann::json j = nlohmann::json::parse(text, nullptr, /*allow_exceptions=*/false);
  EXPECT_TRUE(j.is_object()) << "summary.json is not valid JSON (" << text.size()
                             << " bytes): " << text.substr(0, 200);
  return j;
}

// No "*.partial" file (an atomic write's aside) left in `dir`.
void ExpectNoPartialFiles(const fs::path& dir) {
  std::error_code ec;
  for (auto it = fs::recursive_directory_iterator(dir, ec); it != fs::end(it); ++it)
    EXPECT_NE(it->path().extension(), ".partial") << it->path();
}

// A file-size limit of 0 (ulimit -f 0): no output can be written at all.
// The run says so and fails instead of exiting 0 with an empty summary.json.
TEST(RunnerTest, NoRoomForTheFirstOutputIsAnErrorNamingTheFile) {
  const fs::path out = FreshTempDir("swarmsim_runner", "fsize0");
  const auto r =
      RunCommand("bash -c 'ulimit -f 0; exec " + std::string(SWARMSIM_BINARY) + " run " +
                 CliData("outputs.yaml") + " --steps 5 --quiet --out " + out.string() + "'");
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find("cannot write '" + (out / "summary.json").string() + "': File too large"),
            std::string::npos)
      << r.output;
  EXPECT_TRUE(SummaryIfAny(out).is_null()) << "a summary.json with nothing in it";
  ExpectNoPartialFiles(out);
  fs::remove_all(out);
}

// A small tmpfs at `dir` (root only); false when this machine does not let
// the test mount one.
bool MountTmpfs(const fs::path& dir, const std::string& size) {
  fs::create_directories(dir);
  return RunCommand("mount -t tmpfs -o size=" + size + " swarmsim_test " + dir.string())
             .exit_code == 0;
}
void Unmount(const fs::path& dir) {
  RunCommand("umount -l " + dir.string());
  fs::remove_all(dir);
}

// Fills the file system of `dir` with one file until it is full.
void FillUp(const fs::path& dir) {
  RunCommand("dd if=/dev/zero of=" + (dir / "filler").string() + " bs=4k 2>/dev/null");
}

TEST(RunnerTest, AFullDiskBeforeTheRunIsAnErrorNotAnEmptySummary) {
  const fs::path disk = FreshTempDir("swarmsim_runner", "full_disk");
  if (!MountTmpfs(disk, "512k")) GTEST_SKIP() << "cannot mount a tmpfs here (needs root)";
  FillUp(disk);
  const fs::path out = disk / "out";
  const auto r =
      RunProgram("run " + CliData("outputs.yaml") + " --steps 5 --quiet --out " + out.string());
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find("No space left on device"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("summary.json"), std::string::npos) << r.output;
  if (fs::exists(out)) {
    SummaryIfAny(out);
    ExpectNoPartialFiles(out);
  }
  Unmount(disk);
}

// The disk fills while the run writes snapshots (or a recording): the run
// stops with the reason, and summary.json is whole and says what happened.
void ExpectFullDiskMidRunReported(const std::string& name, const std::string& outputs) {
  const fs::path disk = FreshTempDir("swarmsim_runner", name);
  if (!MountTmpfs(disk, "3m")) GTEST_SKIP() << "cannot mount a tmpfs here (needs root)";
  const fs::path out = disk / "out";
  const auto r = RunProgram("run " + CliData("outputs.yaml") + " --steps 100000 --quiet --out " +
                            out.string() + " " + outputs);
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find("No space left on device"), std::string::npos) << r.output;
  const nlohmann::json summary = SummaryIfAny(out);
  ASSERT_TRUE(summary.is_object()) << "no summary.json after the disk filled: " << r.output;
  EXPECT_EQ(summary.value("status", ""), "error");
  EXPECT_NE(summary.value("error", "").find("No space left on device"), std::string::npos)
      << summary.dump(2);
  EXPECT_GT(summary.value("steps", 0), 0) << "the steps before the disk filled are counted";
  EXPECT_FALSE(fs::exists(out / ".swarmsim-reserve")) << "the room kept aside is given back";
  ExpectNoPartialFiles(out);
  Unmount(disk);
}

TEST(RunnerTest, ADiskFullOfSnapshotsEndsTheRunWithAWholeSummary) {
  ExpectFullDiskMidRunReported("snapshots", "--snapshot-every 1");
}

TEST(RunnerTest, ADiskFullOfRecordingEndsTheRunWithAWholeSummary) {
  ExpectFullDiskMidRunReported("recording", "--record");
}

// The chunk the disk had no room for is cut off again: the recording ends
// with whole chunks and its end chunk (it ended inside a chunk, like a
// killed run's), and summary.json counts the step records it holds (it
// counted those handed to the writer: 51 for 43).
TEST(RunnerTest, ARecordingCutShortByAFullDiskEndsWholeAndCountsWhatItHolds) {
  const fs::path disk = FreshTempDir("swarmsim_runner", "recording_whole");
  if (!MountTmpfs(disk, "3m")) GTEST_SKIP() << "cannot mount a tmpfs here (needs root)";
  const fs::path out = disk / "out";
  const auto r = RunProgram("run " + CliData("outputs.yaml") + " --steps 100000 --quiet --out " +
                            out.string() + " --record");
  EXPECT_EQ(r.exit_code, 1) << r.output;
  const auto info = RunProgram("record-info " + (out / "recording.swrec").string());
  EXPECT_NE(info.output.find("the run ended (error"), std::string::npos) << info.output;
  EXPECT_EQ(info.output.find("inside a chunk"), std::string::npos) << info.output;
  const nlohmann::json summary = SummaryIfAny(out);
  std::string described;
  for (const nlohmann::json& o : summary.value("outputs", nlohmann::json::array()))
    if (o.value("kind", "") == "recording") described = o.value("description", "");
  const size_t records = described.find(" step records");
  ASSERT_NE(records, std::string::npos) << summary.dump(2);
  EXPECT_NE(info.output.find(described.substr(0, records) + " step records"), std::string::npos)
      << described << "\n"
      << info.output;
  Unmount(disk);
}

// A stop signal while the world loads ends the load, says so, and leaves
// an "interrupted" summary.json. The signal is made pending before the
// program starts (blocked, then raised): the program takes it as soon as it
// listens for signals, before the first model copy, with no race.
TEST(RunnerTest, ASignalWhileTheWorldLoadsEndsItWithASummary) {
  const fs::path out = FreshTempDir("swarmsim_runner", "load_signal");
  fs::create_directories(out);
  const fs::path log = out / "stderr.txt";
  const pid_t pid = fork();
  ASSERT_GE(pid, 0);
  if (pid == 0) {
    sigset_t mask;
    sigemptyset(&mask);
    sigaddset(&mask, SIGTERM);
    sigprocmask(SIG_BLOCK, &mask, nullptr);
    raise(SIGTERM);  // pending across exec
    const int fd = open(log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    dup2(fd, STDERR_FILENO);
    const std::string world = CliData("outputs.yaml");
    const std::string dir = out.string();
    execl(SWARMSIM_BINARY, SWARMSIM_BINARY, "run", world.c_str(), "--steps", "5", "--quiet",
          "--out", dir.c_str(), static_cast<char*>(nullptr));
    _exit(127);
  }
  int status = 0;
  ASSERT_EQ(waitpid(pid, &status, 0), pid);
  const std::string stderr_text = ReadFile(log);
  ASSERT_TRUE(WIFEXITED(status)) << "killed by signal " << WTERMSIG(status);
  EXPECT_EQ(WEXITSTATUS(status), 128 + SIGTERM) << stderr_text;
  EXPECT_NE(stderr_text.find("error: interrupted by SIGTERM while the world was loading"),
            std::string::npos)
      << stderr_text;
  const nlohmann::json summary = SummaryIfAny(out);
  ASSERT_TRUE(summary.is_object()) << "no summary.json";
  EXPECT_EQ(summary.value("status", ""), "interrupted");
  EXPECT_NE(summary.value("error", "").find("while the world was loading"), std::string::npos);
  fs::remove_all(out);
}

}  // namespace
