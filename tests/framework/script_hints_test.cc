// Hints for the sysCall_* names a script defines (framework/script_hints.cc):
// a name the host never calls is warned once, with the nearest real one.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "framework/error.h"
#include "framework/world.h"
#include "tests/framework/error_of.h"
#include "tests/framework/fakes.h"
#include "tests/framework/script_world.h"

namespace swarmsim {
namespace {

using namespace script_test;  // script_world.h

using testing::ErrorOf;

TEST(ScriptControlTest, MainScriptWithoutSysCallStepSuggestsAMisspeltOne) {
  WorldSettings settings;
  settings.main_script = Source("main.lua",
                                "function sysCall_init() end\n"
                                "function sysCall_stpe()\n  sim.handleDynamics()\nend\n");
  ScriptWorld w(1, settings);
  const std::string error = ErrorOf([&] { w.world().Start(); });
  EXPECT_CONTAINS(error, "main: main.lua: the main script must define sysCall_step()");
  EXPECT_CONTAINS(error, "main.lua:2 defines sysCall_stpe: did you mean sysCall_step?");
}

TEST(ScriptControlTest, UnknownSysCallNamesAreWarnedOncePerScriptFile) {
  ScriptWorld w(2);
  for (int r = 0; r < 1000; ++r)
    w.AddRobot("bot#" + std::to_string(r), R"(
      function sysCall_actuate() end
      function sysCall_beforeSimulation() end
      function sysCall_step() end
      sysCall_frobnicate = 3
      function sysCall_actuation() end
    )",
               r);
  w.world().Start();
  w.Steps(1);
  const std::vector<std::string> expected = {
      "warning: scripts/robot.lua:2: defines sysCall_actuate, which swarmsim never calls (did you "
      "mean sysCall_actuation?)",
      "warning: scripts/robot.lua:3: defines sysCall_beforeSimulation, which swarmsim never calls "
      "(it is CoppeliaSim's; put its code in sysCall_init)",
      "warning: scripts/robot.lua:4: defines sysCall_step, which swarmsim never calls (only the "
      "world's main script, simulation.main_script, has a sysCall_step)",
      "warning: scripts/robot.lua defines sysCall_frobnicate, which swarmsim never calls "
      "(it calls sysCall_init, sysCall_sensing, sysCall_actuation, sysCall_cleanup and "
      "sysCall_thread)"};
  EXPECT_EQ(w.log, expected);
}

TEST(ScriptControlTest, UnknownSysCallNamesOfOneFileAreWarnedInLineOrder) {
  ScriptWorld w;
  w.AddRobot("bot#0",
             "function sysCall_beforeSimulation() end\n"
             "function sysCall_Init() end\n"
             "function sysCall_b() end function sysCall_a() end\n"
             "sysCall_zzz = 1\n");
  w.world().Start();
  ASSERT_EQ(w.log.size(), 5u);
  EXPECT_CONTAINS(w.log[0], "robot.lua:1: defines sysCall_beforeSimulation,");
  EXPECT_CONTAINS(w.log[1], "robot.lua:2: defines sysCall_Init,");
  EXPECT_CONTAINS(w.log[2], "robot.lua:3: defines sysCall_a,");  // same line: by name
  EXPECT_CONTAINS(w.log[3], "robot.lua:3: defines sysCall_b,");
  EXPECT_CONTAINS(w.log[4], "robot.lua defines sysCall_zzz,");  // no line: last
}

}  // namespace
}  // namespace swarmsim
