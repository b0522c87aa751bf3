// Output files written whole: a reader sees the old file or the new one,
// and a failed write (a full disk, a file-size limit) says which file and
// why, leaving the old one as it was.
#include "framework/output_file.h"

#include <gtest/gtest.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <unistd.h>

#include <csignal>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "framework/error.h"

namespace swarmsim {
namespace {

namespace fs = std::filesystem;

fs::path FreshDir(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() /
                       ("swarmsim_output_file_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

std::string Read(const fs::path& path) {
  std::ifstream f(path, std::ios::binary);
  std::stringstream s;
  s << f.rdbuf();
  return s.str();
}

// Files in `dir` other than `keep`.
int OtherFiles(const fs::path& dir, const std::string& keep) {
  int n = 0;
  for (const auto& entry : fs::directory_iterator(dir))
    n += entry.path().filename() != keep ? 1 : 0;
  return n;
}

TEST(OutputFileTest, WritesAndReplacesWholeFilesLeavingNothingElse) {
  const fs::path dir = FreshDir("replace");
  WriteFileAtomically(dir / "summary.json", "{\"a\": 1}\n");
  EXPECT_EQ(Read(dir / "summary.json"), "{\"a\": 1}\n");
  WriteFileAtomically(dir / "summary.json", "{}\n");
  EXPECT_EQ(Read(dir / "summary.json"), "{}\n");
  EXPECT_EQ(OtherFiles(dir, "summary.json"), 0) << "no partial file left behind";
  fs::remove_all(dir);
}

// Written beside its name and renamed over it, the file replaced whatever
// was there: a pipe, a device (--save-state /dev/null), a symbolic link.
TEST(OutputFileTest, PipesAndFoldersAreRefusedAndLinksWrittenThrough) {
  const fs::path dir = FreshDir("special");
  ASSERT_EQ(::mkfifo((dir / "pipe").c_str(), 0600), 0);
  EXPECT_EQ(TryWriteFileAtomically(dir / "pipe", "x"),
            "it is a FIFO (named pipe), not an ordinary file");
  EXPECT_TRUE(fs::is_fifo(dir / "pipe"));
  fs::create_directories(dir / "folder");
  EXPECT_EQ(TryWriteFileAtomically(dir / "folder", "x"), "it is a folder, not an ordinary file");
  fs::create_symlink(dir / "target.json", dir / "link.json");
  EXPECT_EQ(TryWriteFileAtomically(dir / "link.json", "{}\n"), "");
  EXPECT_TRUE(fs::is_symlink(dir / "link.json"));
  EXPECT_EQ(Read(dir / "target.json"), "{}\n");
  fs::create_symlink(dir / "loop_a", dir / "loop_b");
  fs::create_symlink(dir / "loop_b", dir / "loop_a");
  EXPECT_NE(TryWriteFileAtomically(dir / "loop_a", "x"), "");
  EXPECT_TRUE(fs::is_symlink(dir / "loop_a"));
  fs::remove_all(dir);
}

TEST(OutputFileTest, AMissingFolderIsAnErrorNamingTheFile) {
  const fs::path dir = FreshDir("missing");
  try {
    WriteFileAtomically(dir / "no" / "such" / "summary.json", "{}");
    FAIL() << "wrote into a folder that does not exist";
  } catch (const Error& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find((dir / "no" / "such" / "summary.json").string()), std::string::npos)
        << message;
    EXPECT_NE(message.find("No such file or directory"), std::string::npos) << message;
  }
  fs::remove_all(dir);
}

// A write that fails half-way (here a file-size limit, as a full disk would)
// keeps the old file whole and removes the partial one.
TEST(OutputFileTest, AFailedWriteKeepsTheOldFileWhole) {
  const fs::path dir = FreshDir("limit");
  WriteFileAtomically(dir / "graph.csv", "t,x\n0,1\n");
  const auto old_handler = std::signal(SIGXFSZ, SIG_IGN);  // EFBIG instead of death
  rlimit old_limit{};
  ASSERT_EQ(getrlimit(RLIMIT_FSIZE, &old_limit), 0);
  rlimit limit = old_limit;
  limit.rlim_cur = 4096;
  ASSERT_EQ(setrlimit(RLIMIT_FSIZE, &limit), 0);
  const std::string reason = TryWriteFileAtomically(dir / "graph.csv", std::string(100000, 'x'));
  setrlimit(RLIMIT_FSIZE, &old_limit);
  std::signal(SIGXFSZ, old_handler);
  EXPECT_EQ(reason, "File too large");
  EXPECT_EQ(Read(dir / "graph.csv"), "t,x\n0,1\n");
  EXPECT_EQ(OtherFiles(dir, "graph.csv"), 0) << "the partial file is removed";
  fs::remove_all(dir);
}

TEST(OutputFileTest, AReserveHoldsSpaceUntilReleased) {
  const fs::path dir = FreshDir("reserve");
  {
    OutputReserve reserve;
    ASSERT_TRUE(reserve.Reserve(dir, 65536));
    ASSERT_EQ(OtherFiles(dir, ""), 1);
    const fs::path file = fs::directory_iterator(dir)->path();
    EXPECT_EQ(fs::file_size(file), 65536u);
    reserve.Release();
    EXPECT_FALSE(fs::exists(file));
    ASSERT_TRUE(reserve.Reserve(dir, 100));
  }  // the destructor gives it back too
  EXPECT_EQ(OtherFiles(dir, ""), 0);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace swarmsim
