// The scripts' side of modules/mill (lua_api_mill.cc): sim.setMillEnabled,
// sim.readMill, sim.readCuttable, who may switch which mill, and errors.
#include <gtest/gtest.h>

#include <string>

#include "modules/mill/rows.h"
#include "tests/modules/module_world.h"

namespace swarmsim::mill {
namespace {

using testing::ModuleWorld;

// A 10 cm block of 1 cm voxels at the origin; a robot "bot" whose box mill
// (starting disabled) covers the block's upper half; a scene mill "other"
// out of reach; `code` runs on the robot.
struct MillScripts {
  ModuleWorld w;
  ObjectId bot;
  explicit MillScripts(const std::string& code) {
    CuttableRow block;
    block.size = {0.1, 0.1, 0.1};
    block.resolution = 0.01;
    block.nx = block.ny = block.nz = 10;
    block.remaining = 1000;
    w.Add("cuttable", "block", {}, {}, &block);
    bot = w.Robot("bot", {});
    MillRow mill;
    mill.volume.kind = VolumeKind::kBox;
    mill.volume.width = mill.volume.height = 0.1;
    mill.volume.range = 0.05;
    mill.enabled = false;
    w.Add("mill", "cutter", bot, {}, &mill);
    w.Add("mill", "other", {}, {{5, 0, 0}, {}}, &mill);
    w.Script(bot, code);
  }
  std::string Log() const {
    std::string all;
    for (const std::string& line : w.log()) all += line + "\n";
    return all;
  }
};

TEST(LuaApiMillTest, AScriptSwitchesItsMillOnAndReadsTheCut) {
  MillScripts s(R"(
    local step = 0
    function sysCall_sensing()
      step = step + 1
      local removed, total = sim.readMill(sim.getObject('./cutter'))
      local left, start, volume = sim.readCuttable(sim.getObject('/block'))
      print(string.format('step %d removed %.6g total %.6g left %d of %d volume %.6g', step,
                          removed, total, left, start, volume))
      if step == 1 then sim.setMillEnabled(sim.getObject('./cutter'), true) end
    end
  )");
  ASSERT_EQ(s.w.Run(3), "");
  const std::string log = s.Log();
  EXPECT_CONTAINS(log, "step 1 removed 0 total 0 left 1000 of 1000 volume 0.001\n");
  EXPECT_CONTAINS(log, "step 2 removed 0.0005 total 0.0005 left 500 of 1000 volume 0.0005\n");
  EXPECT_CONTAINS(log, "step 3 removed 0 total 0.0005 left 500 of 1000 volume 0.0005\n");
}

std::string ErrorOfLine(const std::string& line) {
  MillScripts s("function sysCall_init()\n" + line + "\nend\n");
  return s.w.Run(1);
}

TEST(LuaApiMillTest, MistakesAreErrorsNamingWhatIsWrong) {
  EXPECT_CONTAINS(ErrorOfLine("sim.setMillEnabled(sim.getObject('/other'), true)"),
                  "a robot's script may switch only its own mills ('/other' belongs to another "
                  "robot or to the scene)");
  EXPECT_CONTAINS(ErrorOfLine("sim.readMill(sim.getObject('/block'))"),
                  "object /block is not a mill");
  EXPECT_CONTAINS(ErrorOfLine("sim.readCuttable(sim.getObject('./cutter'))"),
                  "object /bot/cutter is not a cuttable");
  EXPECT_CONTAINS(ErrorOfLine("sim.setMillEnabled(sim.getObject('./cutter'), 1)"),
                  "bad argument #2");
}

}  // namespace
}  // namespace swarmsim::mill
