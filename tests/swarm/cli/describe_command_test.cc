// swarmsim describe WORLD (swarm/cli/describe_command.cc): what a world holds,
// said without running it.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "tests/swarm/run_program.h"

namespace {

namespace fs = std::filesystem;

using Result = swarmsim::testing::CommandResult;
using swarmsim::testing::RunProgram;

TEST(CliTest, DescribeNamesTheModulesAWorldGets) {
  // describe names the modules a world gets: every world's, then its own.
  Result describe =
      RunProgram("describe " + std::string(SWARMSIM_SOURCE_DIR) + "/worlds/hexapod.yaml");
  EXPECT_EQ(describe.exit_code, 0) << describe.output;
  EXPECT_NE(describe.output.find(
                "modules: ik paint proximity collision mill paths planning rendering graphs blobs "
                "ground_sensor light range_and_bearing ir_messaging\n"),
            std::string::npos)
      << describe.output;
}

TEST(CliTest, DescribeShowsTheWorldAsSetWithoutRunningIt) {
  const std::string ok = swarmsim::testing::CliData("ok.yaml");
  Result r = RunProgram("describe " + ok + " --set robots=2 --set bot.speed=0.2");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const std::vector<std::string> lines = {"world: ",
                                          "ok.yaml\nphysics: box2d, time step 0.1 s, seed 3\n",
                                          "main script: (default step)\n",
                                          "world parameters:\n  robots = 2\n",
                                          "\nmodel bot (",
                                          "): 2 copies\n",
                                          "bot.lua on :\n",
                                          "  bot.speed = 0.2 m/s  (default 0.05)  forward speed\n"};
  for (const std::string& line : lines)
    EXPECT_NE(r.output.find(line), std::string::npos) << line << "\n" << r.output;
  EXPECT_EQ(r.output.find("robot-ticks/s"), std::string::npos) << "nothing ran";
  // A ratio's unit "1" is not printed after the value (it read as a digit).
  r = RunProgram("describe " + std::string(SWARMSIM_SOURCE_DIR) + "/worlds/diffusion.yaml");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("  footbot.wheel_noise = 0  (default 0)"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("  footbot.prox_noise = 0 m  (default 0)"), std::string::npos)
      << r.output;
  // How its robots' scripts and numbers are laid out (ok.yaml says neither).
  EXPECT_NE(r.output.find("\nLua states: 64 robots a state (simulation.robots_per_lua_state)\n"),
            std::string::npos)
      << r.output;
  EXPECT_NE(r.output.find(": 100 copies, numbered along the region (order: spatial)\n"),
            std::string::npos)
      << r.output;
  EXPECT_EQ(RunProgram("describe " + ok).output.find("Lua states"), std::string::npos);
  EXPECT_EQ(RunProgram("describe " + ok).output.find("numbered along"), std::string::npos);
  // Mistakes are the loader's, named at their place, with exit code 2.
  r = RunProgram("describe " + swarmsim::testing::CliData("typo.yaml"));
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("error: "), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("typo.yaml:4:3: unknown key 'wall_thicknes'"), std::string::npos)
      << r.output;
  r = RunProgram("describe " + ok + " --set bot.sped=1");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("sped"), std::string::npos) << r.output;
}

}  // namespace
