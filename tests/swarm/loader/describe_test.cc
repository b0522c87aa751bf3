// What `swarmsim describe` and Python's World.describe() print of a loaded
// world (swarm/loader/describe.cc): settings, world parameters, and each
// models entry with its copies, scripts and parameters (unit, default,
// range), and the copies' own values.
#include "swarm/loader/describe.h"

#include <gtest/gtest.h>

#include <sstream>
#include <string>

#include "tests/swarm/loader/world_dir_test.h"

namespace swarmsim {
namespace {

class DescribeTest : public testing::WorldDirTest {};

TEST_F(DescribeTest, SaysTheSettingsAndEachModelsCopiesScriptsAndParameters) {
  Write("bot.lua", "function sysCall_init() end\n");
  Write("bot.yaml",
        "model: bot\n"
        "parameters:\n"
        "  speed: {default: 0.05, unit: m/s, range: [0, 0.2], description: cruising speed}\n"
        "objects: {name: body, type: dummy, script: bot.lua}\n");
  LoadedWorld w = Load(
      "simulation: {physics: kinematic, time_step: 0.05, seed: 9}\n"
      "parameters: {n: 3}\n"
      "models:\n"
      "  - model: bot.yaml\n"
      "    count: $n\n"
      "    distribute: {region: {min: [0, 0], max: [5, 5]}}\n"
      "    instances: [{index: 2, parameters: {speed: 0.1}}]\n");
  std::ostringstream out;
  PrintDescription(w, out);
  const std::string text = out.str();
  EXPECT_NE(text.find("physics: kinematic, time step 0.05 s, seed 9\n"), std::string::npos) << text;
  EXPECT_NE(text.find("world parameters:\n  n = 3\n"), std::string::npos) << text;
  EXPECT_NE(text.find("/bot.yaml): 3 copies\n"), std::string::npos) << text;
  EXPECT_NE(text.find("\nmodel bot ("), std::string::npos) << text;
  EXPECT_NE(text.find("  script: "), std::string::npos) << text;
  EXPECT_NE(text.find("  bot.speed = 0.05 m/s  (default 0.05, range [0, 0.2])  cruising speed\n"),
            std::string::npos)
      << text;
  EXPECT_NE(text.find("  copy 2 of this entry: speed=0.1"), std::string::npos) << text;
}

}  // namespace
}  // namespace swarmsim
