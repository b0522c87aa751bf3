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

// The solver steps islands on every thread on this platform: ODE calls the
// program's dRandInt and its island contexts have the layout the solver
// threads adjust (modules/dynamics/ode/ode_threading.h). Either failing would
// silently put the solver back on one thread (or on ODE's costlier
// multi-threaded island path); `swarmsim modules` says which.
TEST(OdeSwarmTest, ModulesSaysTheSolverStepsIslandsOnEveryThread) {
  const auto r = RunProgram("modules");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const size_t ode = r.output.find("dynamics\tode\t");
  ASSERT_NE(ode, std::string::npos) << r.output;
  const std::string line = r.output.substr(ode, r.output.find('\n', ode) - ode);
  EXPECT_TRUE(line.ends_with("; islands solved concurrently on the run's threads")) << line;
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
