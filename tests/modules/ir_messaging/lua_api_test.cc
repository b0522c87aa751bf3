// IR transceivers in world files and scripts: the keys and their errors,
// sim.sendIrMessage / sim.readIrMessages / sim.getIrSent, and
// worlds/ir_gradient.yaml (a hop-count gradient) settling on every robot's
// number of hops from the seed.
#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <queue>
#include <string>
#include <vector>

#include "framework/error.h"
#include "framework/registry.h"
#include "framework/world.h"
#include "modules/builtin.h"
#include "modules/ir_messaging/ir_messaging.h"
#include "swarm/loader/world_loader.h"
#include "tests/framework/error_of.h"
#include "tests/swarm/loader/world_dir_test.h"

namespace swarmsim::ir_messaging {
namespace {

class IrMessagingLuaTest : public testing::WorldDirTest {
 protected:
  // Two robots 5 cm apart, each a dummy with a transceiver and `script`.
  LoadedWorld TwoRobots(const std::string& script, const std::string& keys = "") {
    Write("bot.lua", script);
    Write("bot.yaml",
          "model: bot\nobjects:\n  type: dummy\n  script: bot.lua\n  children:\n"
          "    - {name: ir, type: ir_transceiver, distance_noise: 0" +
              keys + "}\n");
    return Load(
        "simulation: {physics: kinematic, time_step: 0.03125}\nmodels:\n"
        "  - {model: bot.yaml, position: [0, 0]}\n  - {model: bot.yaml, position: [0.05, 0]}\n");
  }
};

TEST_F(IrMessagingLuaTest, KeysAreDocumented) { ExpectDocumented({kTypeName}); }

TEST_F(IrMessagingLuaTest, KeysReachTheSettings) {
  Write("bot.yaml",
        "model: bot\nobjects:\n  type: dummy\n  children:\n"
        "    - {name: ir, type: ir_transceiver, range: 0.07, payload_size: 9, packet_time: 0.002,"
        " distance_noise: 0.003, loss_probability: 0.1, failure_probability: 0.2,"
        " carrier_sense: false, collisions: false}\n");
  LoadedWorld w =
      Load("simulation: {physics: kinematic}\nmodels: [{model: bot.yaml, position: [0, 0]}]\n");
  const IrSettings& s = *RowOf<IrTransceiverRow>(*w.world, "/bot#0/ir").settings;
  EXPECT_EQ(s.range, 0.07);
  EXPECT_EQ(s.payload_size, 9u);
  EXPECT_EQ(s.packet_time, 0.002);
  EXPECT_EQ(s.distance_noise, 0.003);
  EXPECT_EQ(s.loss_probability, 0.1);
  EXPECT_EQ(s.failure_probability, 0.2);
  EXPECT_FALSE(s.carrier_sense);
  EXPECT_FALSE(s.collisions);
}

TEST_F(IrMessagingLuaTest, BadKeysAndValuesNameFileAndLine) {
  std::string e = ErrorOf("ir_transceiver", "  rnage: 0.1\n");
  EXPECT_CONTAINS(e, "thing.yaml:");
  EXPECT_CONTAINS(e, "rnage");
  EXPECT_CONTAINS(e, "range");  // the suggestion
  e = ErrorOf("ir_transceiver", "  payload_size: 0\n");
  EXPECT_CONTAINS(e, "thing.yaml:");
  EXPECT_CONTAINS(e, "payload_size");
  e = ErrorOf("ir_transceiver", "  range: -0.1\n");
  EXPECT_CONTAINS(e, "thing.yaml:");
  EXPECT_CONTAINS(e, "range");
  e = ErrorOf("ir_transceiver", "  loss_probability: 2\n");
  EXPECT_CONTAINS(e, "loss_probability");
  e = ErrorOf("ir_transceiver", "  carrier_sense: maybe\n");
  EXPECT_CONTAINS(e, "carrier_sense");
  e = ErrorOf("ir_transceiver", "  packet_time: 0\n");
  EXPECT_CONTAINS(e, "packet_time");
}

// Each robot sends its index every step and keeps what it heard.
constexpr const char* kEcho = R"(
local ir
heard, sent = {}, 0
function sysCall_init() ir = sim.getObject('./ir') end
function sysCall_actuation()
  if sim.getIrSent(ir) then sent = sent + 1 end
  for _, m in ipairs(sim.readIrMessages(ir)) do
    heard[#heard + 1] = string.byte(m.data, 1)
    assert(math.abs(m.distance - 0.05) < 1e-9, 'distance ' .. m.distance)
  end
  if sim.getSimulationTime() > 0.3 then
    print('heard ' .. #heard .. ' first ' .. tostring(heard[1]) .. ' sent ' .. sent)
  end
  sim.sendIrMessage(ir, {sim.getRobotIndex() + 10, 0, 0})
end
)";

TEST_F(IrMessagingLuaTest, ScriptsSendReadAndSeeWhatWentOut) {
  LoadedWorld w = TwoRobots(kEcho);
  std::vector<std::string> log;
  w.world->set_log_sink([&](std::string_view line) { log.emplace_back(line); });
  w.world->Start();
  for (int i = 0; i < 12; ++i) w.world->Step();
  // Every step each queues; with carrier sense some go out later, but both
  // robots sent and heard the other's index.
  std::map<std::string, std::string> last;
  for (const std::string& line : log) last[line.substr(0, line.find(']') + 1)] = line;
  ASSERT_EQ(last.size(), 2u) << (log.empty() ? "" : log.back());
  EXPECT_CONTAINS(last["[bot#0]"], "first 11");
  EXPECT_CONTAINS(last["[bot#1]"], "first 10");
  for (const auto& [robot, line] : last) EXPECT_EQ(line.find("sent 0"), std::string::npos) << line;
}

TEST_F(IrMessagingLuaTest, AMessageOverThePayloadIsRefusedNamingTheLimit) {
  LoadedWorld w = TwoRobots(
      "function sysCall_init()\n"
      "  sim.sendIrMessage(sim.getObject('./ir'), string.rep('x', 13))\n"
      "end\n");
  const std::string error = testing::ErrorOf([&] { w.world->Start(); });
  EXPECT_CONTAINS(error, "at most 12 bytes");
  EXPECT_CONTAINS(error, "a Kilobot message carries at most 12 bytes");
  EXPECT_CONTAINS(error, "bot.lua:2");
}

// A table with a hole sent its bytes up to the hole, without a word; a shape
// passed as the transceiver was "a ir_transceiver".
TEST_F(IrMessagingLuaTest, AHoleInTheMessageAndAWrongObjectAreNamed) {
  LoadedWorld holed = TwoRobots(
      "function sysCall_init()\n"
      "  sim.sendIrMessage(sim.getObject('./ir'), {1, nil, 3})\n"
      "end\n");
  const std::string hole = testing::ErrorOf([&] { holed.world->Start(); });
  EXPECT_CONTAINS(hole, "bot.lua:2");
  EXPECT_CONTAINS(hole, "the message table has key [3] besides its bytes t[1]..t[1]");
  LoadedWorld shape = TwoRobots(
      "function sysCall_init()\n"
      "  sim.sendIrMessage(sim.getObject('.'), 'x')\n"
      "end\n");
  EXPECT_CONTAINS(testing::ErrorOf([&] { shape.world->Start(); }),
                  "is a dummy, not an ir_transceiver");
}

TEST_F(IrMessagingLuaTest, AMessageOverASmallerPayloadNamesItsSize) {
  LoadedWorld w = TwoRobots(
      "function sysCall_init()\n"
      "  sim.sendIrMessage(sim.getObject('./ir'), {1, 2, 3, 4, 5})\n"
      "end\n",
      ", payload_size: 4");
  const std::string error = testing::ErrorOf([&] { w.world->Start(); });
  EXPECT_CONTAINS(error, "at most 4 bytes");
  EXPECT_CONTAINS(error, "bot.lua:2");
}

TEST_F(IrMessagingLuaTest, ARobotCannotSendFromAnotherRobotsTransceiver) {
  LoadedWorld w = TwoRobots(
      "function sysCall_init()\n"
      "  if sim.getRobotIndex() == 0 then sim.sendIrMessage(sim.getObject('/bot#1/ir'), 'x') end\n"
      "end\n");
  const std::string error = testing::ErrorOf([&] { w.world->Start(); });
  EXPECT_CONTAINS(error, "only from its own IR transceivers");
}

// worlds/ir_gradient.yaml: after its 10 s every robot printed its hop count
// last, and that is its distance in hops from the seed over the graph of
// robots within the transceivers' range.
std::vector<int> ExpectedHops(World& world, int seed) {
  Scene& scene = world.scene();
  const int n = world.robot_count();
  std::vector<Vec3> p;
  for (int i = 0; i < n; ++i) p.push_back(scene.world_pose(scene.instance(i).root).p);
  const ObjectId ir = scene.FindObject("./ir", scene.instance(0).root);
  const double range = static_cast<IrTransceiverRow*>(scene.row_data(ir))->settings->range;
  std::vector<int> hops(static_cast<size_t>(n), -1);
  std::queue<int> open;
  hops[static_cast<size_t>(seed)] = 0;
  open.push(seed);
  while (!open.empty()) {
    const int a = open.front();
    open.pop();
    for (int b = 0; b < n; ++b)
      if (hops[static_cast<size_t>(b)] < 0 &&
          (p[static_cast<size_t>(a)] - p[static_cast<size_t>(b)]).Norm() <= range) {
        hops[static_cast<size_t>(b)] = hops[static_cast<size_t>(a)] + 1;
        open.push(b);
      }
  }
  return hops;
}

void ExpectGradient(ModuleRegistry& registry, const std::string& name, const std::string& value,
                    int seed) {
  LoadOptions options;
  options.threads = 1;
  if (!name.empty()) options.overrides.emplace_back(name, value);
  LoadedWorld w =
      LoadWorld(std::string(SWARMSIM_SOURCE_DIR) + "/worlds/ir_gradient.yaml", options, registry);
  std::map<std::string, int> last;
  w.world->set_log_sink([&](std::string_view line) {
    const std::string text(line);
    const size_t at = text.find("] hops ");
    if (at != std::string::npos) last[text.substr(1, at - 1)] = std::stoi(text.substr(at + 7));
  });
  w.world->Start();
  ASSERT_TRUE(w.steps.has_value());
  for (int64_t i = 0; i < *w.steps; ++i) w.world->Step();
  const std::vector<int> expected = ExpectedHops(*w.world, seed);
  ASSERT_EQ(expected.size(), 25u);
  for (int i = 0; i < 25; ++i) {
    const std::string name = "irbot#" + std::to_string(i);
    ASSERT_TRUE(last.count(name)) << name << " never had a value";
    EXPECT_EQ(last[name], expected[static_cast<size_t>(i)]) << name;
  }
  // Not trivial: values up to several hops.
  EXPECT_GE(*std::max_element(expected.begin(), expected.end()), 2);
}

TEST(IrGradientTest, EveryRobotSettlesOnItsHopCount) {
  ModuleRegistry registry;
  RegisterBuiltinModules(&registry);
  ExpectGradient(registry, "", "", 0);
}

TEST(IrGradientTest, FromTheCentreWithAShorterRange) {
  ModuleRegistry registry;
  RegisterBuiltinModules(&registry);
  ExpectGradient(registry, "seed_robot", "12", 12);
  ExpectGradient(registry, "irbot.ir_range", "0.07", 0);
}

}  // namespace
}  // namespace swarmsim::ir_messaging
