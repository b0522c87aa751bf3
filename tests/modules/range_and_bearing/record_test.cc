// Recordings know who heard whom (swarm/record/FORMAT.md 1.2, "Links
// chunk"): a run of tests/data/viewer/rab_links, recorded, read back with
// RecordingPlayer: at every step after the first sense phase, a heard b, b
// heard a and c, and nothing else; the boards are drawn (pucks).
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "swarm/record/format.h"
#include "swarm/record/reader.h"
#include "tests/swarm/run_program.h"

namespace swarmsim::record {
namespace {

namespace fs = std::filesystem;

TEST(RangeAndBearingRecordTest, EveryStepRecordKnowsWhoHeardWhom) {
  const fs::path out = testing::FreshTempDir("swarmsim_rab_record", "links");
  const auto r = testing::RunProgram("run " + std::string(SWARMSIM_SOURCE_DIR) +
                                     "/tests/data/viewer/rab_links/world.yaml --quiet --record "
                                     "--out " +
                                     out.string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  RecordingPlayer player(out);
  EXPECT_EQ(player.info().version_minor, 2);
  // The boards' recorded ids: each robot's root (a frame), then its board.
  std::vector<uint32_t> board;
  int records = 0;
  while (player.Next()) {
    if (board.empty())
      for (int robot = 0; robot < 4; ++robot) {
        const int64_t root = player.robot_root(robot);
        ASSERT_GE(root, 0);
        board.push_back(static_cast<uint32_t>(root) + 1);
      }
    ++records;
    std::vector<std::pair<uint32_t, uint32_t>> expected;
    if (player.step() > 0)  // heard from the first step's sense phase on
      expected = {{board[0], board[1]}, {board[1], board[0]}, {board[1], board[2]}};
    std::vector<std::pair<uint32_t, uint32_t>> links = player.links();
    std::sort(links.begin(), links.end());
    std::sort(expected.begin(), expected.end());
    EXPECT_EQ(links, expected) << "step " << player.step();
  }
  EXPECT_EQ(records, 6);  // steps 0..5
  fs::remove_all(out);
}

}  // namespace
}  // namespace swarmsim::record
