// swarm/run/output_folder.h: the folder a run writes into, made and checked
// before the run (a pipe in the place of summary.json hung the run), and an
// earlier run's outputs removed, the files it listed inside the folder only.
#include "swarm/run/output_folder.h"

#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "framework/error.h"

namespace swarmsim {
namespace {

namespace fs = std::filesystem;

fs::path FreshDir(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() /
                       ("swarmsim_output_folder_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  return dir;
}

// 'PATH', appended (GCC 12 warns on "'" + std::string chains: -Wrestrict).
std::string Quoted(const fs::path& path) {
  std::string text = "'";
  text += path.string();
  text += "'";
  return text;
}

std::string ErrorOf(const fs::path& dir) {
  try {
    CreateOutputFolder(dir);
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

TEST(OutputFolderTest, TheRunsOwnFilesMustBeOrdinaryFiles) {
  const fs::path dir = FreshDir("own");
  EXPECT_EQ(ErrorOf(dir / "out"), "");
  EXPECT_TRUE(fs::is_directory(dir / "out"));
  ASSERT_EQ(::mkfifo((dir / "out" / "metrics.csv").c_str(), 0600), 0);
  EXPECT_EQ(ErrorOf(dir / "out"), Quoted(dir / "out" / "metrics.csv") +
                                      ": it is a FIFO (named pipe), not an ordinary file, and "
                                      "the run writes its metrics.csv there; remove it or pass "
                                      "another folder");
  fs::remove(dir / "out" / "metrics.csv");
  fs::create_directories(dir / "out" / "summary.json");
  EXPECT_NE(ErrorOf(dir / "out").find("summary.json': it is a folder"), std::string::npos);
  // A loop of links (it said the link's target "does not exist").
  fs::create_symlink(dir / "b", dir / "a");
  fs::create_symlink(dir / "a", dir / "b");
  EXPECT_EQ(ErrorOf(dir / "a"), Quoted(dir / "a") + " is a loop of symbolic links; pass a folder");
  fs::remove_all(dir);
}

TEST(OutputFolderTest, AnEarlierRunsListedOutputsGoAndNothingOutsideTheFolder) {
  const fs::path dir = FreshDir("earlier");
  fs::create_directories(dir / "out" / "snapshots");
  std::ofstream(dir / "out" / "snapshots" / "step_000000.png") << "png";
  std::ofstream(dir / "out" / "video.mp4") << "mp4";
  std::ofstream(dir / "outside.txt") << "keep";
  std::ofstream(dir / "out" / "summary.json")
      << R"({"status": "ok", "outputs": [{"path": "snapshots/step_000000.png", "kind": "snapshot"},
            {"path": "video.mp4", "kind": "video"}, {"path": "../outside.txt", "kind": "x"}]})";
  EXPECT_EQ(RemoveEarlierOutputs(dir / "out"),
            "removed the outputs of the earlier run in '" + (dir / "out").string() +
                "' (1 snapshot, 1 video), so that the folder holds this run's alone");
  EXPECT_FALSE(fs::exists(dir / "out" / "video.mp4"));
  EXPECT_FALSE(fs::exists(dir / "out" / "snapshots")) << "emptied, removed";
  EXPECT_TRUE(fs::exists(dir / "outside.txt"));
  // A pipe where summary.json was: nothing read (the read would wait for a writer).
  fs::remove(dir / "out" / "summary.json");
  ASSERT_EQ(::mkfifo((dir / "out" / "summary.json").c_str(), 0600), 0);
  EXPECT_EQ(RemoveEarlierOutputs(dir / "out"), "");
  fs::remove_all(dir);
}

TEST(OutputFolderTest, TheLastLineOfAFailedRunCountsTheFinishedSteps) {
  EXPECT_EQ(OutputsOfFinishedSteps(0, "d"), "outputs (no step finished) are in d");
  EXPECT_EQ(OutputsOfFinishedSteps(1, "d"), "outputs of the 1 step that finished are in d");
  EXPECT_EQ(OutputsOfFinishedSteps(3, "d"), "outputs of the 3 steps that finished are in d");
}

}  // namespace
}  // namespace swarmsim
