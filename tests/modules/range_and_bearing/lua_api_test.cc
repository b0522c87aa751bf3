// The scripts' side of modules/range_and_bearing: sim.setRangeAndBearingData
// (strings and tables of bytes), sim.getRangeAndBearingData,
// sim.readRangeAndBearing, and the errors naming robot, script and line.
#include <gtest/gtest.h>

#include <memory>
#include <string>
#include <vector>

#include "framework/error.h"
#include "tests/modules/range_and_bearing/rab_world.h"

namespace swarmsim::range_and_bearing {
namespace {

// Robot 0 at the origin facing +x runs `code0`, robot 1 at (0, 1) (due
// left of robot 0, 1 m) runs `code1`; their boards send 4 bytes (an
// e-puck's). Runs `steps` steps; returns what the scripts printed, and the
// error in *error.
std::vector<std::string> RunScripts(const std::string& code0, const std::string& code1, int steps,
                                    std::string* error) {
  RabWorld w;
  RangeAndBearingSettings s;
  s.range = 2;
  s.payload_size = 4;
  const ObjectId a = w.Robot(0, 0, 0, s);
  const ObjectId b = w.Robot(0, 1, 0, s);
  const std::string codes[] = {code0, code1};
  const ObjectId boards[] = {a, b};
  for (int i = 0; i < 2; ++i) {
    const uint32_t slot = w.scene().SlotOf(boards[i]);
    const ObjectId root = w.scene().IdAt(static_cast<uint32_t>(w.scene().parent_at(slot)));
    w.scene().AttachScript(root, std::make_shared<const ScriptSource>(
                                     ScriptSource{"bot" + std::to_string(i) + ".lua", codes[i]}));
  }
  try {
    w.world().Start();
    for (int i = 0; i < steps; ++i) w.world().Step();
  } catch (const Error& e) {
    *error = e.what();
  }
  return w.log();
}

const char* kReader = R"(
function sysCall_init() rab = sim.getObject('./rab') end
function sysCall_sensing()
  local r = sim.readRangeAndBearing(rab)
  local line = #r .. ':'
  for _, m in ipairs(r) do
    line = line .. string.format(' [%s] %.3f %.3f %.3f', table.concat({string.byte(m.data, 1, -1)}, ','),
                                 m.range, m.bearing, m.elevation)
  end
  print(line)
end
)";

TEST(RangeAndBearingLuaTest, ScriptsSetDataAndReadWhatOthersSent) {
  std::string error;
  // Robot 1 sends a string in init, then a table from its second actuation on.
  const auto log = RunScripts(kReader, R"(
    local n = 0
    function sysCall_init()
      rab = sim.getObject('./rab')
      sim.setRangeAndBearingData(rab, 'AB')
      print('get ' .. table.concat({string.byte(sim.getRangeAndBearingData(rab), 1, -1)}, ','))
    end
    function sysCall_actuation()
      n = n + 1
      if n == 2 then sim.setRangeAndBearingData(rab, {7, 0, 255, 1}) end
    end
  )",
                              4, &error);
  EXPECT_EQ(error, "");
  std::vector<std::string> lines;
  for (const std::string& l : log) lines.push_back(l.substr(l.find(']') + 2));
  ASSERT_EQ(lines.size(), 5u) << ::testing::PrintToString(log);
  EXPECT_EQ(lines[0], "get 65,66,0,0");
  // Robot 1 is due left of robot 0: bearing +pi/2; boards at the same height.
  EXPECT_EQ(lines[1], "1: [65,66,0,0] 1.000 1.571 0.000");  // step 1: set in init
  EXPECT_EQ(lines[2], "1: [65,66,0,0] 1.000 1.571 0.000");  // kept
  EXPECT_EQ(lines[3], "1: [7,0,255,1] 1.000 1.571 0.000");  // set at step 2, heard at 3
  EXPECT_EQ(lines[4], "1: [7,0,255,1] 1.000 1.571 0.000");
}

std::string ErrorOf(const std::string& code) {
  std::string error;
  RunScripts("function sysCall_init()\n  rab = sim.getObject('./rab')\n  " + code + "\nend\n", "",
             1, &error);
  return error;
}

TEST(RangeAndBearingLuaTest, MoreBytesThanThePayloadIsAScriptErrorNamingRobotScriptAndLine) {
  const std::string e = ErrorOf("sim.setRangeAndBearingData(rab, 'hello')");
  EXPECT_NE(e.find("bot#0"), std::string::npos) << e;
  EXPECT_NE(e.find("bot0.lua:3:"), std::string::npos) << e;
  EXPECT_NE(e.find("sim.setRangeAndBearingData: the data is 5 bytes, more than the payload_size "
                   "(4 bytes) of '/bot#0/rab'"),
            std::string::npos)
      << e;
  EXPECT_NE(ErrorOf("sim.setRangeAndBearingData(rab, {1, 2, 3, 4, 5, 6})")
                .find("the data is 6 bytes, more than the payload_size (4 bytes)"),
            std::string::npos);
}

TEST(RangeAndBearingLuaTest, OtherMistakesAreScriptErrorsToo) {
  EXPECT_NE(ErrorOf("sim.setRangeAndBearingData(rab, {1, 256})")
                .find("element 2 of the data must be an integer from 0 to 255"),
            std::string::npos);
  EXPECT_NE(ErrorOf("sim.setRangeAndBearingData(rab, {1.5})").find("element 1"), std::string::npos);
  EXPECT_NE(ErrorOf("sim.setRangeAndBearingData(rab, {'a'})").find("element 1"), std::string::npos);
  EXPECT_NE(ErrorOf("sim.setRangeAndBearingData(rab, 12)").find("bad argument #2"),
            std::string::npos);
  // A hole: it sent 1,0,0,0 without a word.
  EXPECT_NE(ErrorOf("sim.setRangeAndBearingData(rab, {1, nil, 3})")
                .find("the data table has key [3] besides its bytes t[1]..t[1]"),
            std::string::npos);
  EXPECT_NE(ErrorOf("sim.setRangeAndBearingData(sim.getObject('/bot#1/rab'), 'x')")
                .find("may set only its own range-and-bearing boards' data ('/bot#1/rab'"),
            std::string::npos);
  const std::string not_a_board = ErrorOf("sim.readRangeAndBearing(sim.getObject('.'))");
  EXPECT_NE(not_a_board.find("object 'bot#0' is a shape, not a range_and_bearing"),
            std::string::npos)
      << not_a_board;
  EXPECT_EQ(ErrorOf("sim.setRangeAndBearingData(rab, 'abcd') sim.setRangeAndBearingData(rab, {})"),
            "");
}

}  // namespace
}  // namespace swarmsim::range_and_bearing
