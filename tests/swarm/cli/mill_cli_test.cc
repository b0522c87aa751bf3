// worlds/milling.yaml as a user runs it: the same state hash at 1, 2 and 4
// threads, the removed volume growing in metrics.csv, and mill.csv at the
// end adding up with it.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "tests/swarm/run_program.h"

namespace {

namespace fs = std::filesystem;
using swarmsim::testing::RunProgram;

std::string HashOf(const std::string& output) {
  const size_t at = output.find("state-hash: ");
  return at == std::string::npos ? "" : output.substr(at + 12, 16);
}

std::vector<std::string> Split(const std::string& line) {
  std::vector<std::string> cells;
  std::stringstream s(line);
  std::string cell;
  while (std::getline(s, cell, ',')) cells.push_back(cell);
  if (!line.empty() && line.back() == ',') cells.push_back("");
  return cells;
}

TEST(MillCliTest, MillingRunsTheSameAtAnyThreadCountAndWritesItsVolumes) {
  const std::string world = std::string(SWARMSIM_SOURCE_DIR) + "/worlds/milling.yaml";
  const fs::path out = swarmsim::testing::FreshTempDir("swarmsim_mill_cli", "milling");
  std::string hashes[3];
  const int threads[3] = {1, 2, 4};
  for (int t = 0; t < 3; ++t) {
    const auto r =
        RunProgram("run " + world + " --steps 200 --hash --quiet --threads " +
                   std::to_string(threads[t]) + (t == 0 ? " --out " + out.string() : ""));
    ASSERT_EQ(r.exit_code, 0) << r.output;
    hashes[t] = HashOf(r.output);
    ASSERT_EQ(hashes[t].size(), 16u) << r.output;
  }
  EXPECT_EQ(hashes[1], hashes[0]);
  EXPECT_EQ(hashes[2], hashes[0]);
  // metrics.csv: each robot's `milled` (its script's sim.readMill total)
  // grows; the mills' per-step volumes add up to it.
  std::ifstream metrics(out / "metrics.csv");
  std::string line;
  std::map<std::string, double> milled, summed;
  double first_left = -1, last_left = -1;
  while (std::getline(metrics, line)) {
    const std::vector<std::string> c = Split(line);
    if (c.size() != 5 || c[0] == "step") continue;
    const double v = std::stod(c[4]);
    if (c[3] == "milled") {
      EXPECT_GE(v, milled[c[2]]) << line;
      milled[c[2]] = v;
    } else if (c[3] == "mill.removed") {
      summed[c[2]] += v;
    } else if (c[3] == "block.remaining") {
      if (first_left < 0) first_left = v;
      last_left = v;
    }
  }
  ASSERT_EQ(milled.size(), 4u);
  EXPECT_GT(milled["millbot#0"], 1e-4);
  EXPECT_LT(last_left, first_left);
  // mill.csv: the block's loss is what the four mills removed.
  std::ifstream csv(out / "mill.csv");
  ASSERT_TRUE(csv.good());
  double removed_by_mills = 0, block_removed = -1;
  while (std::getline(csv, line)) {
    const std::vector<std::string> c = Split(line);
    if (c.size() < 3) continue;
    if (c[1] == "mill") removed_by_mills += std::stod(c[2]);
    if (c[0] == "/block") block_removed = std::stod(c[2]);
  }
  EXPECT_GT(removed_by_mills, 4e-4);
  EXPECT_NEAR(removed_by_mills, block_removed, 1e-9);
  // A row describes the state after its step: the script's last total lags
  // the module's sum by the last step's cut at most.
  EXPECT_NEAR(summed["millbot#0"], milled["millbot#0"], 1e-5);
  fs::remove_all(out);
}

}  // namespace
