// Range-and-bearing boards from native controllers (framework/plugin_api.h,
// ABI 7: set_range_and_bearing_data, read_range_and_bearing), and a plugin
// built for ABI 6 still loading and running.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>
#include <vector>

#include "framework/error.h"
#include "framework/world.h"
#include "modules/range_and_bearing/range_and_bearing.h"
#include "swarm/loader/world_loader.h"
#include "tests/framework/error_of.h"
#include "tests/swarm/loader/world_dir_test.h"

namespace swarmsim::range_and_bearing {
namespace {

// A world may load plugins from its own folder: the tests' plugins are copied there.
class RangeAndBearingNativeTest : public testing::WorldDirTest {
 protected:
  void SetUp() override {
    WorldDirTest::SetUp();
    for (const char* plugin : {RAB_ECHO_PLUGIN, ABI6_PLUGIN})
      std::filesystem::copy_file(plugin, dir_ / std::filesystem::path(plugin).filename());
  }
};

// Three robots 1 m apart on x, each running the rab_echo controller
// (plugins/rab_echo_plugin.cc): it sends {its robot index, how many it
// heard, the first byte of the nearest reading}.
std::string EchoWorld() {
  std::string text = "plugins: [rab_echo_plugin]\nsimulation: {physics: kinematic}\nmodels:\n";
  for (int i = 0; i < 3; ++i)
    text += "  - {model: bot.yaml, position: [" + std::to_string(i) +
            ", 0], native_controller: rab_echo}\n";
  return text;
}

const char* kBot =
    "model: bot\nobjects:\n  type: dummy\n  children:\n"
    "    - {name: rab, type: range_and_bearing, position: [0, 0, 0.1], range: 3}\n";

TEST_F(RangeAndBearingNativeTest, ControllersSetDataAndReadWhatOthersSent) {
  Write("bot.yaml", kBot);
  LoadedWorld w = Load(EchoWorld());
  World& world = *w.world;
  world.Start();
  for (int i = 0; i < 3; ++i) world.Step();
  Scene& scene = world.scene();
  ObjectType type;
  ASSERT_TRUE(scene.FindType(kTypeName, &type));
  const auto& rows = scene.rows<RangeAndBearingRow>(type);
  const auto reading = [&](int robot, size_t k) {
    const RangeAndBearingRow& row = rows.rows[scene.row_at(
        scene.SlotOf(scene.FindObject("./rab", scene.instance(robot).root)))];
    EXPECT_LT(k, row.readings.size());
    const RangeAndBearingReading& r = row.readings.at(k);
    return std::vector<int>(row.received.begin() + r.data_offset,
                            row.received.begin() + r.data_offset + 3);
  };
  // Robot 0 hears robot 1 (1 m) then robot 2 (2 m): each heard two, robot
  // 2's nearest is robot 1.
  EXPECT_EQ(reading(0, 0), (std::vector<int>{1, 2, 0}));
  EXPECT_EQ(reading(0, 1), (std::vector<int>{2, 2, 1}));
  EXPECT_EQ(reading(2, 0), (std::vector<int>{1, 2, 0}));
}

TEST_F(RangeAndBearingNativeTest, DataLongerThanThePayloadIsRefused) {
  Write("bot.yaml", kBot);
  LoadedWorld w = Load("parameters: {too_long: 1}\n" + EchoWorld());
  const std::string error = testing::ErrorOf([&] {
    w.world->Start();
    w.world->Step();
  });
  EXPECT_NE(error.find("set_range_and_bearing_data refused"), std::string::npos) << error;
  EXPECT_NE(error.find("bot#0"), std::string::npos) << error;  // the robot
}

TEST_F(RangeAndBearingNativeTest, APluginBuiltForAbi6StillLoadsAndRuns) {
  Write("bot.yaml", "model: bot\nobjects:\n  type: dummy\n  script: bot.lua\n");
  Write("bot.lua", "function sysCall_actuation() print('time ' .. sim.abi6Time()) end\n");
  LoadedWorld w = Load(
      "plugins: [abi6_plugin]\nsimulation: {physics: kinematic, time_step: 0.1}\n"
      "models: [{model: bot.yaml, position: [0, 0]}]\n");
  std::vector<std::string> log;
  w.world->set_log_sink([&](std::string_view line) { log.emplace_back(line); });
  w.world->Start();
  w.world->Step();
  w.world->Step();
  ASSERT_EQ(log.size(), 2u);
  EXPECT_NE(log[1].find("time 0.1"), std::string::npos) << log[1];
}

}  // namespace
}  // namespace swarmsim::range_and_bearing
