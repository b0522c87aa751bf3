// sim.* custom data blocks (framework/lua_api_custom_data.cc).
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

TEST(ScriptControlTest, CustomDataIsSeenNextStepAndCopiedWithTheModel) {
  ScriptWorld w(2);
  // Robot 0 writes a block on its own body and on robot 1's; robot 1 reads both.
  const ObjectId body0 = w.AddRobot("bot#0", R"(
    function sysCall_actuation()
      local t = sim.getSimulationTime()
      sim.writeCustomDataBlock(sim.getObject('.'), 'mood', t < 0.05 and 'calm' or nil)
      sim.writeCustomDataBlock(sim.getObject('/bot#1/body'), 'note', sim.packFloats({t}))
    end
  )");
  w.AddRobot("bot#1", R"(
    function sysCall_actuation()
      local note = sim.readCustomDataBlock(sim.getObject('.'), 'note')
      print(sim.readCustomDataBlock(sim.getObject('/bot#0/body'), 'mood'),
            note and sim.unpackFloats(note)[1])
    end
  )",
             1);
  w.Steps(3);
  EXPECT_EQ(w.log, (std::vector<std::string>{"[bot#1] nil	nil", "[bot#1] calm	0.0",
                                             "[bot#1] nil	0.10000000149012"}));
  // A copy of the model carries the block with it; the original keeps its own.
  w.scene().WriteCustomData(body0, "serial", "A-17");
  const ObjectId root0 = w.scene().parent(body0);
  const ObjectId copy = w.scene().DuplicateSubtree(root0, {});
  const ObjectId copy_body = w.scene().FindObject("./body", copy);
  ASSERT_NE(w.scene().ReadCustomData(copy_body, "serial"), nullptr);
  EXPECT_EQ(*w.scene().ReadCustomData(copy_body, "serial"), "A-17");
  w.scene().WriteCustomData(copy_body, "serial", "");
  EXPECT_EQ(w.scene().ReadCustomData(copy_body, "serial"), nullptr);
  EXPECT_EQ(*w.scene().ReadCustomData(body0, "serial"), "A-17");
}

// Writes to one block in one step: the highest robot index wins, then the
// scene's scripts, whatever the thread count.
TEST(LuaApiCustomDataTest, OneBlockWrittenByManyInOneStepHasOneWinner) {
  for (int threads : {1, 4}) {
    for (bool with_scene : {false, true}) {
      ScriptWorld w(threads);
      const ObjectId board = w.scene().AddDummy("board", {}, {});
      for (int r = 0; r < 6; ++r)
        w.AddRobot("bot#" + std::to_string(r), R"(
          function sysCall_actuation()
            sim.writeCustomDataBlock(sim.getObject('/board'), 'owner', sim.getRobotName())
          end
        )");
      if (with_scene)
        w.scene().AttachScript(board, Source("scripts/board.lua", R"(
          function sysCall_actuation() sim.writeCustomDataBlock(sim.getObject('.'), 'owner', 'scene') end
        )"));
      w.Steps(2);  // step 0's writes are applied when step 1 begins
      const std::string* owner = w.scene().ReadCustomData(board, "owner");
      ASSERT_NE(owner, nullptr);
      EXPECT_EQ(*owner, with_scene ? "scene" : "bot#5") << threads << " threads";
    }
  }
}

TEST(LuaApiCustomDataTest, BlocksKeepEveryByteAndBadHandlesAreErrorsAtTheCall) {
  ScriptWorld w;
  w.AddRobot("bot#0", R"(
    function sysCall_actuation()
      if sim.getSimulationTime() == 0 then
        sim.writeCustomDataBlock(sim.getObject('.'), 'raw', 'a\0b\255')
      else
        local data = sim.readCustomDataBlock(sim.getObject('.'), 'raw')
        print(#data, data:byte(2), data:byte(4))
        print(sim.readCustomDataBlock(sim.getObject('.'), 'other'))
      end
    end
  )");
  w.Steps(2);
  EXPECT_EQ(w.log, (std::vector<std::string>{"[bot#0] 4\t0\t255", "[bot#0] nil"}));
  ScriptWorld v;
  v.AddRobot("bot#0",
             "function sysCall_actuation()\n  sim.writeCustomDataBlock(987654, 't', 'x')\nend");
  EXPECT_CONTAINS(ErrorOf([&] { v.Steps(1); }),
                  "bot#0: scripts/robot.lua:2: sim.writeCustomDataBlock: object handle 987654");
}

}  // namespace
}  // namespace swarmsim
