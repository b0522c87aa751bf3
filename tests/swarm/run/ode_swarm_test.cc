// ODE at swarm scale: robots in their own collision sub-spaces, contact
// points found concurrently. Results never depend on the thread count, and
// robots still stand on the floor, meet each other and stop at the walls.
#include <gtest/gtest.h>

#include <string>

#include "tests/swarm/run_program.h"

namespace swarmsim {
namespace {

using testing::RunProgram;

std::string World(const std::string& name) {
  return std::string(SWARMSIM_SOURCE_DIR) + "/worlds/" + name;
}

// The state hash `run` prints, or "" (with the output in the failure).
std::string HashOf(const std::string& args) {
  const auto r = RunProgram("run " + args + " --hash --quiet");
  EXPECT_EQ(r.exit_code, 0) << r.output;
  const size_t at = r.output.find("state-hash: ");
  if (at == std::string::npos) return "";
  return r.output.substr(at + 12, 16);
}

// `args` (ending in --threads) gives one state at 1, 2 and 4 threads.
void ExpectSameHashAtOneTwoAndFourThreads(const std::string& args) {
  const std::string one = HashOf(args + "1");
  ASSERT_FALSE(one.empty());
  EXPECT_EQ(HashOf(args + "2"), one);
  EXPECT_EQ(HashOf(args + "4"), one);
}

// 150 hexapods packed at 0.6 m^2 each: hundreds of foot-floor pairs and
// hexapods bumping into each other, enough pairs to be split over workers.
TEST(OdeSwarmTest, HexapodHashIsTheSameAtOneTwoAndFourThreads) {
  const std::string args =
      World("hexapod.yaml") + " --set robots=150 --set spacing=0.6 --steps 40 --threads ";
  ExpectSameHashAtOneTwoAndFourThreads(args);
}

// Wheeled robots at 3 per m^2 drive into each other and into the walls.
TEST(OdeSwarmTest, WheeledHashIsTheSameAtOneTwoAndFourThreads) {
  const std::string args =
      World("wheeled3d.yaml") + " --set robots=300 --set density=3 --steps 60 --threads ";
  ExpectSameHashAtOneTwoAndFourThreads(args);
}

}  // namespace
}  // namespace swarmsim
