// Paths in messages (framework/display_path.cc): relative to the current
// folder when the file is below it, so messages name "worlds/x.yaml" as the
// user typed it, not a long absolute path.
#include "framework/display_path.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <string>

namespace swarmsim {
namespace {

namespace fs = std::filesystem;

TEST(DisplayPathTest, RelativePathsAreNormalisedAndKeptRelative) {
  EXPECT_EQ(DisplayPath("worlds/./models/../models/footbot.yaml"), "worlds/models/footbot.yaml");
  EXPECT_EQ(DisplayPath("worlds//arena.yaml"), "worlds/arena.yaml");
  // Above the current folder: still as given, normalised.
  EXPECT_EQ(DisplayPath("../other/./w.yaml"), "../other/w.yaml");
}

TEST(DisplayPathTest, AbsolutePathsBelowTheCurrentFolderBecomeRelative) {
  const fs::path cwd = fs::current_path();
  EXPECT_EQ(DisplayPath(cwd / "worlds" / "arena.yaml"), "worlds/arena.yaml");
  EXPECT_EQ(DisplayPath(cwd / "worlds" / "." / "models" / ".." / "arena.yaml"),
            "worlds/arena.yaml");
}

TEST(DisplayPathTest, AbsolutePathsElsewhereStayAbsolute) {
  const fs::path cwd = fs::current_path();
  ASSERT_TRUE(cwd.has_parent_path());
  const fs::path beside = cwd.parent_path() / "elsewhere" / "w.yaml";
  EXPECT_EQ(DisplayPath(beside), beside.lexically_normal().generic_string());
  EXPECT_EQ(DisplayPath(beside).front(), '/');
  // A path that only starts with the same letters as the current folder is
  // not below it.
  const fs::path sibling = cwd.string() + "_other/w.yaml";
  EXPECT_EQ(DisplayPath(sibling), sibling.generic_string());
}

}  // namespace
}  // namespace swarmsim
