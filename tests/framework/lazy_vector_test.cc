// LazyVector (framework/lazy_vector.h): 8 bytes until used, and then the
// std::vector calls per-robot code makes, with the same results.
#include "framework/lazy_vector.h"

#include <gtest/gtest.h>

#include <string>
#include <vector>

namespace swarmsim {
namespace {

TEST(LazyVectorTest, EmptyUntilUsedThenAVector) {
  static_assert(sizeof(LazyVector<std::string>) == sizeof(void*));
  LazyVector<std::string> lines;
  EXPECT_TRUE(lines.empty());
  EXPECT_EQ(lines.size(), 0u);
  EXPECT_EQ(lines.begin(), lines.end());
  int visited = 0;
  for (const std::string& line : lines) visited += !line.empty();
  EXPECT_EQ(visited, 0);
  lines.clear();  // nothing to clear: still nothing allocated
  EXPECT_TRUE(lines.empty());

  lines.push_back("a");
  lines.emplace_back(3, 'b');
  ASSERT_EQ(lines.size(), 2u);
  EXPECT_EQ(lines[0], "a");
  EXPECT_EQ(lines.back(), "bbb");
  std::vector<std::string> copied(lines.begin(), lines.end());
  EXPECT_EQ(copied, (std::vector<std::string>{"a", "bbb"}));
  lines.pop_back();
  EXPECT_EQ(lines.size(), 1u);
  lines.get().insert(lines.get().begin(), "first");
  EXPECT_EQ(lines[0], "first");

  // Copies are deep, moves leave the source empty.
  LazyVector<std::string> copy = lines;
  copy.push_back("more");
  EXPECT_EQ(lines.size(), 2u);
  EXPECT_EQ(copy.size(), 3u);
  LazyVector<std::string> moved = std::move(copy);
  EXPECT_EQ(moved.size(), 3u);
  lines = {};
  EXPECT_TRUE(lines.empty());
  lines = moved;
  EXPECT_EQ(lines.size(), 3u);
  lines.clear();
  EXPECT_TRUE(lines.empty());
}

}  // namespace
}  // namespace swarmsim
