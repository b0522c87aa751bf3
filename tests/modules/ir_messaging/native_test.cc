// The plugin world API of ABI 8 (framework/plugin_api.h: read_sensor_value,
// set_led, ir_send, ir_sent, ir_receive) from a native controller:
// plugins/ir_relay_plugin.cc relays IR messages along a chain of robots,
// reads a light and a ground sensor and sets an LED.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include "framework/world.h"
#include "modules/blobs/leds.h"
#include "modules/ground_sensor/ground_sensor.h"
#include "modules/ir_messaging/ir_messaging.h"
#include "modules/light/light.h"
#include "swarm/loader/world_loader.h"
#include "tests/framework/error_of.h"
#include "tests/swarm/loader/world_dir_test.h"

namespace swarmsim::ir_messaging {
namespace {

class IrNativeTest : public testing::WorldDirTest {
 protected:
  void SetUp() override {
    WorldDirTest::SetUp();
    std::filesystem::copy_file(IR_RELAY_PLUGIN,
                               dir_ / std::filesystem::path(IR_RELAY_PLUGIN).filename());
  }
};

// Three robots 8 cm apart on x (robot 0 and 2 out of each other's 10 cm),
// a lamp above, a grey floor; the light sensors look up.
constexpr const char* kBot =
    "model: irbot\nobjects:\n  type: dummy\n  children:\n"
    "    - {name: ir, type: ir_transceiver, distance_noise: 0}\n"
    "    - {name: light, type: light_sensor, position: [0, 0, 0.03], orientation_deg: [0, -90, "
    "0]}\n"
    "    - {name: ground, type: ground_sensor}\n"
    "    - {name: led, type: led, color: [0, 0, 0]}\n";

std::string ChainWorld() {
  std::string text =
      "plugins: [ir_relay_plugin]\nsimulation: {physics: kinematic, time_step: 0.03125}\n"
      "floor: {background: 0.5, area: {min: [-1, -1], max: [1, 1]}}\n"
      "objects:\n  - {name: lamp, type: light_source, position: [0, 0, 1], intensity: 2}\n"
      "models:\n";
  for (int i = 0; i < 3; ++i)
    text += "  - {model: bot.yaml, position: [" + std::to_string(0.08 * i) +
            ", 0], native_controller: ir_relay}\n";
  return text;
}

TEST_F(IrNativeTest, ControllersRelayReadSensorsAndSetLeds) {
  Write("bot.yaml", kBot);
  LoadedWorld w = Load(ChainWorld());
  World& world = *w.world;
  world.Start();
  Scene& scene = world.scene();
  ObjectType ir_type;
  ASSERT_TRUE(scene.FindType(kTypeName, &ir_type));
  bool relayed = false;
  for (int i = 0; i < 8; ++i) {
    world.Step();
    // Robot 2 hears only robot 1, which relays robot 0's message: hops 2,
    // then robot 0's light and ground readings, as the sensors read them.
    const IrTransceiverRow& far = RowOf<IrTransceiverRow>(world, "/irbot#2/ir");
    for (const IrReceived& m : far.inbox) {
      ASSERT_EQ(m.data_size, 3u);
      const uint8_t* data = far.received.data() + m.data_offset;
      EXPECT_EQ(data[0], 2);
      const double light = RowOf<light::LightSensorRow>(world, "/irbot#0/light").reading;
      EXPECT_GT(light, 1);  // a lamp of 2 about 1 m above
      EXPECT_EQ(data[1], std::lround(std::fmin(255, light * 100)));
      EXPECT_EQ(data[2], 50);  // the grey floor: 0.5
      EXPECT_NEAR(m.distance, 0.08, 1e-9);
      relayed = true;
    }
  }
  EXPECT_TRUE(relayed);
  // Robot 1's LED: red (2, clamped to 1) if it heard something at the
  // last step; green: its light reading is above 0.
  const LedRow& led = RowOf<LedRow>(world, "/irbot#1/led");
  EXPECT_TRUE(led.on);
  EXPECT_EQ(led.color.y, 1);
  EXPECT_EQ(led.color.x, RowOf<IrTransceiverRow>(world, "/irbot#1/ir").inbox.empty() ? 0 : 1);
  EXPECT_EQ(led.color.z, 0);
}

}  // namespace
}  // namespace swarmsim::ir_messaging
