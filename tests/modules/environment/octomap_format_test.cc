// The OctoMap file formats checked before the library reads them
// (octomap_format.cc), through ReadOctomap: every kind of bad header or body
// must be a clear error (never a crash or an abort); trailing bytes are a
// warning.

#include <gtest/gtest.h>
#include <unistd.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>
#include <vector>

#include "framework/error.h"
#include "modules/environment/octomap_map.h"
#include "tests/framework/error_of.h"
#include "tests/modules/environment/octomap_files.h"
#include "tests/shared_maps.h"

namespace swarmsim::environment {
namespace {

namespace fs = std::filesystem;
using swarmsim::testing::ErrorOf;

std::string ReadAll(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

using octomap_test::BinaryHeader;
using octomap_test::OctomapFileTest;
using octomap_test::OneVoxelBinary;
using octomap_test::OneVoxelFull;

TEST_F(OctomapFileTest, AWrongFirstLineIsNotAnOctomapFile) {
  const std::string file = Write("x.bt", "hello world\nid OcTree\nsize 1\nres 0.1\ndata\n\0\0");
  EXPECT_CONTAINS(ErrorOf([&] { ReadOctomap(file, "x.bt", {}); }),
                  "octomap x.bt: not an OctoMap file: its first line is \"hello world\"");
}

TEST_F(OctomapFileTest, AHeaderWithoutDataOrResIsAnError) {
  EXPECT_CONTAINS(ErrorOf([&] {
                    ReadOctomap(Write("a.bt", "# Octomap OcTree binary file\nid OcTree\nsize 3\n"),
                                "a.bt", {});
                  }),
                  "no 'data' line");
  EXPECT_CONTAINS(ErrorOf([&] {
                    ReadOctomap(
                        Write("b.bt", "# Octomap OcTree binary file\nid OcTree\nsize 3\ndata\n"),
                        "b.bt", {});
                  }),
                  "no 'res'");
  EXPECT_CONTAINS(ErrorOf([&] {
                    ReadOctomap(Write("c.bt",
                                      "# Octomap OcTree binary file\nid OcTree\nsize "
                                      "3\nres -1\ndata\n"),
                                "c.bt", {});
                  }),
                  "'res -1' is not a positive resolution");
  // A cell so large the tree reaches past the world's 1e6 m (1e30 was read).
  EXPECT_CONTAINS(ErrorOf([&] {
                    ReadOctomap(Write("d.bt",
                                      "# Octomap OcTree binary file\nid OcTree\nsize "
                                      "3\nres 1e30\ndata\n"),
                                "d.bt", {});
                  }),
                  "'res 1e30' is more than 30.5 m");
}

TEST_F(OctomapFileTest, ATruncatedBodyIsAnErrorAtEveryLength) {
  const std::string whole = OneVoxelBinary();
  const size_t header = BinaryHeader(17).size();
  for (size_t cut = header; cut < whole.size(); ++cut) {
    const std::string error =
        ErrorOf([&] { ReadOctomap(Write("t.bt", whole.substr(0, cut)), "t.bt", {}); });
    EXPECT_CONTAINS(error, "octomap t.bt: truncated") << cut;
  }
}

TEST_F(OctomapFileTest, ATruncatedOtIsAnErrorAtEveryLength) {
  const std::string whole = OneVoxelFull(2.0f);
  const size_t header = whole.find("data\n") + 5;
  for (size_t cut = header; cut < whole.size(); ++cut) {
    const std::string error =
        ErrorOf([&] { ReadOctomap(Write("t.ot", whole.substr(0, cut)), "t.ot", {}); });
    EXPECT_CONTAINS(error, "octomap t.ot: truncated") << cut;
  }
}

TEST_F(OctomapFileTest, ATruncatedCopyOfTheSharedMapIsAnError) {
  SWARMSIM_NEED_SHARED_MAP(path, "geb079.bt");
  const std::string whole = ReadAll(path);
  for (size_t cut : {whole.size() / 3, whole.size() - 1}) {
    const std::string error =
        ErrorOf([&] { ReadOctomap(Write("t.bt", whole.substr(0, cut)), "t.bt", {}); });
    EXPECT_CONTAINS(error, "truncated");
    EXPECT_CONTAINS(error, "size 532566");
  }
}

TEST_F(OctomapFileTest, AWrongSizeOrAnInnerNodeTooDeepIsCorrupt) {
  std::string wrong = OneVoxelBinary();
  wrong.replace(wrong.find("size 17"), 7, "size 16");
  EXPECT_CONTAINS(ErrorOf([&] { ReadOctomap(Write("w.bt", wrong), "w.bt", {}); }),
                  "more nodes than the header's 'size 16'");
  std::string deep = OneVoxelBinary(3);  // the voxel claims children
  EXPECT_CONTAINS(ErrorOf([&] { ReadOctomap(Write("d.bt", deep), "d.bt", {}); }),
                  "corrupt: an inner node at depth 16");
}

TEST_F(OctomapFileTest, AnOtOfAnotherTreeTypeIsRefused) {
  EXPECT_CONTAINS(
      ErrorOf([&] { ReadOctomap(Write("c.ot", OneVoxelFull(2.0f, "ColorOcTree")), "c.ot", {}); }),
      "a .ot map of type ColorOcTree");
}

TEST_F(OctomapFileTest, AMapTooLargeForMemoryIsRefusedFromItsHeader) {
  // The header promises 4e9 nodes; the body is absent: refused before reading it.
  const std::string error =
      ErrorOf([&] { ReadOctomap(Write("big.bt", BinaryHeader(4000000000u)), "big.bt", {}); });
  EXPECT_CONTAINS(error, "too large: its header says 4000000000 nodes");
  EXPECT_CONTAINS(error, "max_memory_mb");
}

TEST_F(OctomapFileTest, TrailingBytesAreAWarning) {
  OctomapReport report;
  ReadOctomap(Write("tail.bt", OneVoxelBinary() + "xyz"), "tail.bt", {}, &report);
  ASSERT_EQ(report.warnings.size(), 1u);
  EXPECT_CONTAINS(report.warnings[0], "3 bytes after the tree's last node");
}

}  // namespace
}  // namespace swarmsim::environment
