// A file opened for positioned reads only when it is a regular file: a FIFO
// is refused at once (a reader would otherwise wait on it forever).
#include "framework/regular_file.h"

#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

namespace swarmsim {
namespace {

namespace fs = std::filesystem;

fs::path FreshDir() {
  const fs::path dir =
      fs::temp_directory_path() / ("swarmsim_regular_file_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

TEST(RegularFileTest, ReadsBytesAtAnyOffsetAndStopsAtTheEnd) {
  const fs::path dir = FreshDir();
  std::ofstream(dir / "data") << "0123456789";
  std::string why;
  const auto file = RegularFile::Open(dir / "data", &why);
  ASSERT_NE(file, nullptr) << why;
  EXPECT_EQ(file->CurrentSize(), 10);
  char bytes[4] = {};
  ASSERT_TRUE(file->ReadAt(6, bytes, 4));
  EXPECT_EQ(std::string(bytes, 4), "6789");
  EXPECT_FALSE(file->ReadAt(8, bytes, 4, &why)) << "past the end";
  EXPECT_EQ(why, "") << "the end of the file is no error";
  fs::remove_all(dir);
}

TEST(RegularFileTest, AFifoAFolderAndAMissingFileAreRefusedSayingWhat) {
  const fs::path dir = FreshDir();
  ASSERT_EQ(::mkfifo((dir / "pipe").c_str(), 0600), 0);
  std::string why;
  EXPECT_EQ(RegularFile::Open(dir / "pipe", &why), nullptr);
  EXPECT_EQ(why, "a FIFO (named pipe)");
  EXPECT_EQ(RegularFile::Open(dir, &why), nullptr);
  EXPECT_EQ(why, "a folder");
  EXPECT_EQ(RegularFile::Open(dir / "missing", &why), nullptr);
  EXPECT_EQ(why, "No such file or directory");
  fs::remove_all(dir);
}

// What a writer that renames over a file must not replace (--save-state
// /dev/null made the system's /dev/null a file), named; through links.
TEST(RegularFileTest, WhatIsNoOrdinaryFileIsNamedAndTheRestIsNot) {
  const fs::path dir = FreshDir();
  ASSERT_EQ(::mkfifo((dir / "pipe").c_str(), 0600), 0);
  EXPECT_EQ(NotAnOrdinaryFile(dir / "pipe"), "it is a FIFO (named pipe), not an ordinary file");
  EXPECT_EQ(NotAnOrdinaryFile(dir), "it is a folder, not an ordinary file");
  EXPECT_EQ(NotAnOrdinaryFile("/dev/null"), "it is a character device, not an ordinary file");
  fs::create_symlink("/dev/null", dir / "null");
  EXPECT_EQ(NotAnOrdinaryFile(dir / "null"), "it is a character device, not an ordinary file");
  std::ofstream(dir / "data") << "x";
  EXPECT_EQ(NotAnOrdinaryFile(dir / "data"), "");
  EXPECT_EQ(NotAnOrdinaryFile(dir / "missing"), "");
  fs::remove_all(dir);
}

}  // namespace
}  // namespace swarmsim
