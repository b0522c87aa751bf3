// swarmsim --help, version and modules (swarm/cli/info_commands.cc): what the
// program holds, as a user lists it.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "tests/swarm/run_program.h"

namespace {

namespace fs = std::filesystem;

using Result = swarmsim::testing::CommandResult;
using swarmsim::testing::RunProgram;

TEST(CliTest, HelpVersionAndModules) {
  Result help = RunProgram("--help");
  EXPECT_EQ(help.exit_code, 0);
  EXPECT_NE(help.output.find("run"), std::string::npos);
  EXPECT_NE(help.output.find("bench"), std::string::npos);
  Result version = RunProgram("version");
  EXPECT_EQ(version.exit_code, 0);
  EXPECT_NE(version.output.find("swarmsim "), std::string::npos);
  Result modules = RunProgram("modules");
  EXPECT_EQ(modules.exit_code, 0);
  EXPECT_NE(modules.output.find("box2d"), std::string::npos) << modules.output;
  EXPECT_NE(modules.output.find("proximity"), std::string::npos) << modules.output;
  // Every object type and every registered module has its line: kind, name,
  // version, one line of description.
  for (const char* line :
       {"object type\tjoint\tbuilt-in\t", "object type\tforce_sensor\t", "calculation\tik\t",
        "record\tpaint\t", "record\tgraphs\t", "metric\tcovered_area\t"})
    EXPECT_NE(modules.output.find(line), std::string::npos) << line << "\n" << modules.output;
}

}  // namespace
