// Results do not move by accident: every example world's state hash after a
// fixed number of steps, for two seeds and 1 and 2 threads, equals the one
// checked in (tests/data/golden_hashes.tsv). A change that means to move
// results rewrites the table with tools/golden_hashes.sh and says why in its
// commit.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "tests/swarm/run_program.h"

namespace swarmsim {
namespace {

namespace fs = std::filesystem;
using testing::RunProgram;

struct GoldenRow {
  std::string world;
  std::string seed, steps, threads, hash;
};

std::vector<GoldenRow> ReadTable() {
  std::ifstream in(std::string(SWARMSIM_SOURCE_DIR) + "/tests/data/golden_hashes.tsv");
  std::vector<GoldenRow> rows;
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream fields(line);
    GoldenRow row;
    std::getline(fields, row.world, '\t');
    std::getline(fields, row.seed, '\t');
    std::getline(fields, row.steps, '\t');
    std::getline(fields, row.threads, '\t');
    std::getline(fields, row.hash, '\t');
    rows.push_back(row);
  }
  return rows;
}

// A map file that `world` names beside the repository (../../shared/maps/,
// e.g. worlds/octomap_corridor.yaml's geb079.bt: maps stay out of the
// repository) and that is not there, or "" if it names none or has them all.
std::string MissingSharedMap(const std::string& world) {
  const fs::path file = fs::path(SWARMSIM_SOURCE_DIR) / world;
  std::ifstream in(file);
  const std::string text((std::istreambuf_iterator<char>(in)), {});
  const std::string marker = "../../shared/maps/";
  for (size_t at = text.find(marker); at != std::string::npos; at = text.find(marker, at + 1)) {
    const size_t end = text.find_first_of(" \t\r\n\"'#,}]", at);
    const std::string relative = text.substr(at, end == std::string::npos ? end : end - at);
    if (!fs::exists(file.parent_path() / relative)) return relative;
  }
  return "";
}

TEST(GoldenHashesTest, EveryExampleWorldHasItsCheckedInHash) {
  const std::vector<GoldenRow> rows = ReadTable();
  ASSERT_GE(rows.size(), 52u) << "tests/data/golden_hashes.tsv is missing or short";
  for (const GoldenRow& row : rows) {
    // A checkout without the shared maps beside it (CI elsewhere) cannot run
    // the worlds that read them: said, not failed.
    if (const std::string map = MissingSharedMap(row.world); !map.empty()) {
      std::printf("skipped %s --seed %s --threads %s: its map %s is not beside the repository\n",
                  row.world.c_str(), row.seed.c_str(), row.threads.c_str(), map.c_str());
      continue;
    }
    const auto r = RunProgram("run " + std::string(SWARMSIM_SOURCE_DIR) + "/" + row.world +
                              " --seed " + row.seed + " --steps " + row.steps + " --threads " +
                              row.threads + " --hash --quiet");
    const std::string expected = "state-hash: " + row.hash;
    EXPECT_NE(r.output.find(expected), std::string::npos)
        << row.world << " --seed " << row.seed << " --steps " << row.steps << " --threads "
        << row.threads << ": the state hash moved (expected " << row.hash << ", got\n"
        << r.output
        << ").\nIf the change of results is intended, run tools/golden_hashes.sh and say why in "
           "the commit.";
  }
}

// A new example world (or golden_*.yaml coverage world) cannot skip the table.
TEST(GoldenHashesTest, TheTableCoversEveryExampleWorld) {
  std::set<std::string> listed;
  for (const GoldenRow& row : ReadTable()) listed.insert(row.world);
  for (const char* folder :
       {"worlds", "worlds/experiments", "worlds/kilobot", "bench/worlds", "tests/data/worlds"}) {
    for (const auto& entry : fs::directory_iterator(fs::path(SWARMSIM_SOURCE_DIR) / folder)) {
      if (entry.path().extension() != ".yaml") continue;
      if (std::string(folder) == "tests/data/worlds" &&
          !entry.path().filename().string().starts_with("golden_"))
        continue;
      const std::string world = std::string(folder) + "/" + entry.path().filename().string();
      EXPECT_TRUE(listed.contains(world))
          << world << " has no row in tests/data/golden_hashes.tsv: run tools/golden_hashes.sh";
    }
  }
}

}  // namespace
}  // namespace swarmsim
