// Kilobot messaging through the plugin ABI's IR functions (ABI 8: ir_send,
// ir_sent, ir_receive), with a stand-in transceiver (a line of robots 40 mm
// apart that hear each other within 100 mm, or a channel that is always
// busy), so that the runtime's side is tested without the IR module:
// worlds/kilobot/gradient.c forms its gradient, robots transmit about twice
// a second, a busy channel makes them retry within a tick or two, messages
// with a bad CRC or a bootloader type are dropped, and estimate_distance
// gives the distance in mm.
#include <dlfcn.h>
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "framework/plugin_api.h"
#include "tests/swarm/run_program.h"

namespace {

namespace fs = std::filesystem;

constexpr double kSpacing = 0.04;  // m between neighbours on the line
constexpr double kRange = 0.1;     // m: who hears whom

// The stand-in world: N robots, their queued and on-air messages, LEDs.
struct FakeWorld {
  int robots = 0;
  double time = 0;
  bool busy = false;  // the channel is always taken: nothing goes out
  std::vector<std::vector<uint8_t>> queued, on_air, sent_log;
  std::vector<int> sent;  // ir_sent of each robot's transceiver
  std::vector<int> attempts;
  std::vector<std::array<double, 3>> led;
  std::vector<std::vector<uint8_t>> extra;  // messages every robot hears too
};

FakeWorld* g_world = nullptr;

// kilolib's message_crc (avr-libc's _crc_ccitt_update from 0xFFFF over the
// first 10 bytes), to make messages here.
uint16_t Crc(const std::vector<uint8_t>& m) {
  uint16_t crc = 0xFFFF;
  for (int i = 0; i < 10; ++i) {
    uint8_t data = m[i] ^ static_cast<uint8_t>(crc & 0xff);
    data ^= static_cast<uint8_t>(data << 4);
    crc =
        static_cast<uint16_t>(((static_cast<uint16_t>(data) << 8) | (crc >> 8)) ^
                              static_cast<uint8_t>(data >> 4) ^ (static_cast<uint16_t>(data) << 3));
  }
  return crc;
}

std::vector<uint8_t> Message(uint8_t first, uint8_t type, bool good_crc) {
  std::vector<uint8_t> m(12, 0);
  m[0] = first, m[9] = type;
  const uint16_t crc = static_cast<uint16_t>(Crc(m) ^ (good_crc ? 0 : 1));
  m[10] = static_cast<uint8_t>(crc & 0xff), m[11] = static_cast<uint8_t>(crc >> 8);
  return m;
}

int Robot(int64_t object) { return static_cast<int>(object / 8) - 1; }

double Time(void*) { return g_world->time; }
int NumberParameter(void*, int, const char*, double*) { return 0; }
int FindObject(void*, int64_t from, const char* path, int64_t* out) {
  const char* names[] = {"./leftMotor", "./rightMotor", "./led", "./ir"};
  for (int i = 0; i < 4; ++i)
    if (std::strcmp(path, names[i]) == 0) return *out = from * 8 + i + 1, 1;
  return 0;
}
int SetJointTargetVelocity(void*, int, int64_t, double) { return 1; }
double RandomUniform(void*, int robot) { return ((robot * 37) % 100) / 100.0; }
int ReadSensorValue(void*, int64_t, double*) { return -1; }
int SetLed(void*, int robot, int64_t, double r, double g, double b, int on) {
  g_world->led[robot] = {on ? r : 0, on ? g : 0, on ? b : 0};
  return 0;
}
int IrSend(void*, int robot, int64_t, const uint8_t* data, size_t size) {
  if (size != 12) return -1;
  g_world->queued[robot].assign(data, data + size);
  ++g_world->attempts[robot];
  return 0;
}
int IrSent(void*, int64_t ir) { return g_world->sent[Robot(ir)]; }
int IrReceive(void*, int64_t ir, SwarmsimIrMessage* out, int max) {
  const int me = Robot(ir);
  int n = 0;
  for (int j = 0; j < g_world->robots; ++j) {
    const double distance = std::abs(j - me) * kSpacing;
    if (j == me || g_world->on_air[j].empty() || distance > kRange) continue;
    if (n < max) out[n] = {g_world->on_air[j].data(), g_world->on_air[j].size(), distance};
    ++n;
  }
  for (const std::vector<uint8_t>& m : g_world->extra) {
    if (n < max) out[n] = {m.data(), m.size(), 0.05};
    ++n;
  }
  return n;
}

struct Controller {
  SwarmsimControllerInit init = nullptr;
  SwarmsimControllerStep step = nullptr;
  SwarmsimControllerCleanup cleanup = nullptr;
  void* user_data = nullptr;
};
int AddController(void* impl, const char*, const char*, SwarmsimControllerInit init,
                  SwarmsimControllerStep step, SwarmsimControllerCleanup cleanup, void* user_data) {
  *static_cast<Controller*>(impl) = {init, step, cleanup, user_data};
  return 0;
}
void SetInfo(void*, const char*, const char*, const char*) {}

// Builds `source` with the program and loads its controller.
Controller BuildAndLoad(const fs::path& source, const fs::path& output) {
  const auto built =
      swarmsim::testing::RunProgram("kilobot build " + source.string() + " -o " + output.string());
  EXPECT_EQ(built.exit_code, 0) << built.output;
  Controller controller;
  void* library = dlopen(output.c_str(), RTLD_NOW | RTLD_LOCAL);
  EXPECT_NE(library, nullptr) << dlerror();
  if (library == nullptr) return controller;
  auto reg = reinterpret_cast<int (*)(const SwarmsimRegistrar*)>(
      dlsym(library, "swarmsim_plugin_register"));
  SwarmsimRegistrar r{};
  r.impl = &controller;
  r.set_info = SetInfo;
  r.add_controller = AddController;
  EXPECT_EQ(reg(&r), 0);
  return controller;
}

// Runs `steps` steps of 1/32 s: each step's sense phase puts the messages
// queued in the last one on the air (unless the channel is busy), then each
// robot's controller steps.
void RunSteps(const Controller& c, FakeWorld* world, int steps) {
  g_world = world;
  SwarmsimWorldApi api{};
  api.time = Time;
  api.number_parameter = NumberParameter;
  api.find_object = FindObject;
  api.set_joint_target_velocity = SetJointTargetVelocity;
  api.random_uniform = RandomUniform;
  api.read_sensor_value = ReadSensorValue;
  api.set_led = SetLed;
  api.ir_send = IrSend;
  api.ir_sent = IrSent;
  api.ir_receive = IrReceive;
  const int n = world->robots;
  world->queued.assign(n, {});
  world->on_air.assign(n, {});
  world->sent_log.assign(n, {});
  world->sent.assign(n, 0);
  world->attempts.assign(n, 0);
  world->led.assign(n, {0, 0, 0});
  std::vector<void*> states(n);
  char error[1024];
  for (int r = 0; r < n; ++r) {
    const SwarmsimCallContext context{r, r + 1, nullptr, &api};
    ASSERT_EQ(c.init(&context, &states[r], error, sizeof error, c.user_data), 0) << error;
  }
  for (int s = 0; s < steps; ++s) {
    world->time = s / 32.0;
    for (int r = 0; r < n; ++r) {
      world->on_air[r].clear();
      world->sent[r] = 0;
      if (world->queued[r].empty()) continue;
      if (!world->busy) {
        world->on_air[r] = world->queued[r];
        world->sent_log[r] = world->queued[r];
        world->sent[r] = 1;
      }
      world->queued[r].clear();
    }
    for (int r = 0; r < n; ++r) {
      const SwarmsimCallContext context{r, r + 1, nullptr, &api};
      ASSERT_EQ(c.step(&context, states[r], error, sizeof error, c.user_data), 0) << error;
    }
  }
  for (int r = 0; r < n; ++r) {
    const SwarmsimCallContext context{r, r + 1, nullptr, &api};
    c.cleanup(&context, states[r], c.user_data);
  }
}

fs::path Dir(const std::string& name) {
  const fs::path dir = swarmsim::testing::FreshTempDir("swarmsim_kilobot_ir", name);
  fs::create_directories(dir);
  return dir;
}

TEST(KilobotMessagingTest, GradientFormsAndRobotsSendTwiceASecond) {
  const fs::path dir = Dir("gradient");
  const Controller c =
      BuildAndLoad(fs::path(SWARMSIM_SOURCE_DIR) / "worlds/kilobot/gradient.c", dir / "g.so");
  ASSERT_NE(c.step, nullptr);
  FakeWorld world;
  world.robots = 12;
  RunSteps(c, &world, 32 * 20);  // 20 s
  // Robot i is ceil(i / 2) hops from robot 0 (neighbours within 100 mm are
  // 1 or 2 places away); the LED shows the hop count + 1 in base 4 (red
  // ones, green fours, blue sixteens, each channel 0..3 as 0..1).
  for (int i = 0; i < world.robots; ++i) {
    const int code = (i + 1) / 2 + 1;
    const std::array<double, 3> color = {(code & 3) / 3.0, ((code >> 2) & 3) / 3.0,
                                         ((code >> 4) & 3) / 3.0};
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(world.led[i][k], color[k], 1e-12) << "robot " << i;
  }
  // kilo_tx_period 3906 cycles of 8 MHz / 1024: 0.5 s.
  for (int i = 0; i < world.robots; ++i) EXPECT_NEAR(world.attempts[i], 40, 2) << "robot " << i;
  fs::remove_all(dir);
}

// Sends what it heard last: its estimate_distance and the payload byte, and
// counts how many messages reached kilo_message_rx.
const char* kEcho = R"(#include <kilolib.h>
message_t out;
uint8_t heard = 0, last_distance = 0, last_byte = 0, successes = 0;
void rx(message_t *m, distance_measurement_t *d) {
  ++heard;
  last_distance = estimate_distance(d);
  last_byte = m->data[0];
}
message_t *tx() {
  out.data[0] = (uint8_t)kilo_uid;
  out.data[1] = last_distance;
  out.data[2] = last_byte;
  out.data[3] = successes;
  out.data[4] = heard;
  out.type = NORMAL;
  out.crc = message_crc(&out);
  return &out;
}
void success() { ++successes; }
void setup() {}
void loop() {}
int main() {
  kilo_init();
  kilo_message_rx = rx;
  kilo_message_tx = tx;
  kilo_message_tx_success = success;
  kilo_start(setup, loop);
  return 0;
}
)";

TEST(KilobotMessagingTest, DistancesInMillimetresAndBadMessagesDropped) {
  const fs::path dir = Dir("echo");
  std::ofstream(dir / "echo.c") << kEcho;
  const Controller c = BuildAndLoad(dir / "echo.c", dir / "echo.so");
  ASSERT_NE(c.step, nullptr);
  FakeWorld world;
  world.robots = 2;  // 40 mm apart
  // Everyone also hears a message with a bad CRC, and one of the
  // bootloader's types (valid CRC): both dropped.
  world.extra = {Message(200, 0, false), Message(201, 0x80, true)};
  RunSteps(c, &world, 32 * 3);
  for (int r = 0; r < 2; ++r) {
    ASSERT_EQ(world.sent_log[r].size(), 12u);
    const std::vector<uint8_t>& m = world.sent_log[r];
    EXPECT_EQ(m[0], r);
    EXPECT_EQ(m[1], 40) << "robot " << r;  // mm, centre to centre
    EXPECT_EQ(m[2], 1 - r);                // the other's payload, never 200 or 201
    EXPECT_GT(m[3], 0) << "kilo_message_tx_success never called";
    EXPECT_GT(m[4], 0) << "robot " << r << " heard nothing";
  }
  fs::remove_all(dir);
}

TEST(KilobotMessagingTest, BusyChannelMeansRetriesAndNoSuccess) {
  const fs::path dir = Dir("busy");
  std::ofstream(dir / "echo.c") << kEcho;
  const Controller c = BuildAndLoad(dir / "echo.c", dir / "busy.so");
  ASSERT_NE(c.step, nullptr);
  FakeWorld world;
  world.robots = 3;
  world.busy = true;
  RunSteps(c, &world, 32 * 2);
  // Carrier sense: nothing went out, so the robots try again every tick or
  // two (kilolib's random back-off of 0..255 cycles) instead of every 0.5 s.
  for (int r = 0; r < 3; ++r) {
    EXPECT_TRUE(world.sent_log[r].empty());
    EXPECT_GT(world.attempts[r], 20) << "robot " << r;
  }
  fs::remove_all(dir);
}

}  // namespace
