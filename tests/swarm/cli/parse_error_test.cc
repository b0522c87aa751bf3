// What the command line parser rejects, in this program's words
// (swarm/cli/parse_error.cc): the nearest known option or command for a typo,
// and the repeat-the-option hint for a second value after --set.
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

std::string Data(const std::string& name) { return swarmsim::testing::CliData(name); }

TEST(CliTest, UnknownFlagIsAClearErrorWithNonzeroExit) {
  Result r = RunProgram("run " + Data("ok.yaml") + " --stpes 10");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.output.find("error: unknown option '--stpes' for 'run' (did you mean '--steps'?)"),
            std::string::npos)
      << r.output;
  Result with_value = RunProgram("run " + Data("ok.yaml") + " --stpes=10");
  EXPECT_NE(with_value.output.find("unknown option '--stpes' for 'run' (did you mean '--steps'?)"),
            std::string::npos)
      << with_value.output;
  Result bad_set = RunProgram("run " + Data("ok.yaml") + " --set robots");
  EXPECT_NE(bad_set.exit_code, 0);
  EXPECT_NE(bad_set.output.find("name=value"), std::string::npos) << bad_set.output;
}

// An option given twice, or with no value at the end of the line: said
// plainly, not in CLI11's words ("At Most 1 required but received 2").
TEST(CliTest, AnOptionTwiceOrWithoutItsValueIsSaidPlainly) {
  Result twice = RunProgram("run " + Data("ok.yaml") + " --steps 5 --steps 6");
  EXPECT_EQ(twice.exit_code, 2) << twice.output;
  EXPECT_NE(twice.output.find("error: --steps given 2 times; it takes one value (give it once)\n"),
            std::string::npos)
      << twice.output;
  Result bare = RunProgram("run " + Data("ok.yaml") + " --steps");
  EXPECT_EQ(bare.exit_code, 2) << bare.output;
  EXPECT_NE(bare.output.find("error: --steps needs a value ("), std::string::npos) << bare.output;
  EXPECT_EQ(bare.output.find("missing"), std::string::npos) << bare.output;
}

TEST(CliTest, UnknownCommandSuggestsTheNearestAndListsThem) {
  Result r = RunProgram("runn " + Data("ok.yaml"));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.output.find("error: unknown command 'runn' (did you mean 'run'?)"), std::string::npos)
      << r.output;
  EXPECT_NE(r.output.find("commands: run, bench, sweep"), std::string::npos) << r.output;
}

TEST(CliTest, SetTakesOneNameEqualsValueEach) {
  Result help = RunProgram("run --help");
  EXPECT_NE(help.output.find("--set NAME=VALUE"), std::string::npos) << help.output;
  EXPECT_EQ(help.output.find("--set TEXT"), std::string::npos) << help.output;
  // Two values after one --set, with the world before them or after them.
  for (const std::string& args :
       {"run " + Data("ok.yaml") + " --steps 1 --set robots=2 bot.speed=0.1",
        "run --steps 1 --set robots=2 bot.speed=0.1 " + Data("ok.yaml")}) {
    Result r = RunProgram(args);
    EXPECT_EQ(r.exit_code, 2) << r.output;
    EXPECT_NE(r.output.find("each --set takes one NAME=VALUE; repeat --set for more"),
              std::string::npos)
        << r.output;
  }
  Result repeated = RunProgram("run " + Data("ok.yaml") +
                               " --steps 1 --quiet --set robots=2 --set bot.speed=0.1");
  EXPECT_EQ(repeated.exit_code, 0) << repeated.output;
}

}  // namespace
