// Small OctoMap files for the environment module's tests: a fixture that
// writes files into a fresh temporary folder, and hand-made .bt and .ot
// bytes of one voxel (octomap_format_test.cc, octomap_map_test.cc).
#pragma once

#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>

namespace swarmsim::environment::octomap_test {

namespace fs = std::filesystem;

// A file in a fresh temporary folder, removed with the fixture.
class OctomapFileTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("swarmsim_octomap_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string Write(const std::string& name, const std::string& bytes) {
    const fs::path p = dir_ / name;
    std::ofstream(p, std::ios::binary) << bytes;
    return p.string();
  }
  fs::path dir_;
};

inline std::string BinaryHeader(uint64_t size, const std::string& id = "OcTree") {
  return "# Octomap OcTree binary file\n# made by a test\nid " + id + "\nsize " +
         std::to_string(size) + "\nres 0.1\ndata\n";
}

// A .bt of one occupied voxel at key (32768, 32768, 32768), i.e. the cube
// [0, 0.1]^3: the root's child 7, then child 0 at every level below.
inline std::string OneVoxelBinary(unsigned leaf_code = 2) {
  std::string body;
  body += '\0';
  body += static_cast<char>(0xC0);  // root: child 7 is an inner node (code 3 at bits 14-15)
  for (int depth = 1; depth < 15; ++depth) body += "\x03", body += '\0';  // child 0 inner
  body += static_cast<char>(leaf_code), body += '\0';  // depth 15: child 0 is a leaf
  return BinaryHeader(17) + body;
}

// The same voxel as a .ot of `id` with leaf log-odds `leaf_value`.
inline std::string OneVoxelFull(float leaf_value, const std::string& id = "OcTree") {
  std::string out = "# Octomap OcTree file\nid " + id + "\nsize 17\nres 0.1\ndata\n";
  auto node = [&](float value, unsigned char children) {
    char bytes[4];
    std::memcpy(bytes, &value, 4);
    out.append(bytes, 4);
    out += static_cast<char>(children);
  };
  node(0, 0x80);                                           // root: child 7
  for (int depth = 1; depth < 16; ++depth) node(0, 0x01);  // child 0
  node(leaf_value, 0);                                     // the voxel
  return out;
}

}  // namespace swarmsim::environment::octomap_test
