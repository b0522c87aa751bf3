// Kilobot programs compiled unchanged (swarm/kilobot): `swarmsim kilobot
// build prog.c` as a user runs it, the program on worlds/models/kilobot.yaml
// robots. Globals are each robot's own, kilolib's software generator gives
// kilolib's sequence, the motors move the robot at the published speeds in
// the planar contact mode and in Box2D, compile errors, crashes and endless
// loops end with messages naming the file, the robot and the program, and
// the state hash does not depend on the thread count.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <string>
#include <vector>

#include "framework/registry.h"
#include "framework/scene.h"
#include "framework/world.h"
#include "modules/blobs/leds.h"
#include "modules/builtin.h"
#include "swarm/loader/world_loader.h"
#include "tests/swarm/run_program.h"

namespace swarmsim {
namespace {

namespace fs = std::filesystem;
using testing::CommandResult;
using testing::RunProgram;

constexpr double kPi = 3.14159265358979323846;

// The numbers of each line of `output` that holds `format` (sscanf's, of
// `count` integers, e.g. "uid %ld sum %ld"; the line may start with the
// robot's "[kilobot#3] " prefix): one vector per matching line, in order.
// (Not std::regex: GCC 12 warns inside <regex> under the sanitizers.)
std::vector<std::vector<long>> Matches(const std::string& output, const char* format, int count) {
  const std::string head(format, std::string(format).find(' '));  // the first word
  std::vector<std::vector<long>> out;
  size_t start = 0;
  while (start < output.size()) {
    size_t end = output.find('\n', start);
    if (end == std::string::npos) end = output.size();
    const std::string line = output.substr(start, end - start);
    start = end + 1;
    const size_t at = line.find(head + " ");
    if (at == std::string::npos) continue;
    long v[5] = {};
    if (std::sscanf(line.c_str() + at, format, &v[0], &v[1], &v[2], &v[3], &v[4]) == count)
      out.emplace_back(v, v + count);
  }
  return out;
}

fs::path Dir(const std::string& name) {
  const fs::path dir = testing::FreshTempDir("swarmsim_kilobot", name);
  fs::create_directories(dir);
  return dir;
}

void Write(const fs::path& path, const std::string& text) { std::ofstream(path) << text; }

// Writes NAME.c into `dir` and builds NAME.so with the program.
CommandResult Build(const fs::path& dir, const std::string& name, const std::string& code) {
  Write(dir / (name + ".c"), code);
  return RunProgram("kilobot build " + (dir / (name + ".c")).string());
}

std::string Model() { return std::string(SWARMSIM_SOURCE_DIR) + "/worlds/models/kilobot.yaml"; }

// A world of Kilobots running `program`: `robots` copies spread over a
// square of side `size`, or one robot per entry of `positions`.
std::string World(const std::string& program, const std::string& physics, int robots, double size,
                  const std::string& parameters = "{}") {
  return "plugins: [" + program + "]\nsimulation: {physics: " + physics +
         ", time_step: 0.03125, physics_substeps: 4, seed: 1}\n"
         "arena: {size: " +
         std::to_string(size) +
         ", wall_thickness: 0.05, wall_height: 0.05}\n"
         "models:\n  - model: " +
         Model() + "\n    count: " + std::to_string(robots) +
         "\n    distribute: {region: arena, clearance: 0.01}\n    parameters: " + parameters +
         "\n    native_controller: " + program + "\n";
}

// ---- per-robot globals ----

// Each robot adds (uid + 1) to a global, through a pointer to it and to a
// static, once per loop, and prints them at its own tick uid + 5.
const char* kCounter = R"(#define DEBUG
#include <kilolib.h>
#include <debug.h>

uint32_t counter;           /* .bss */
uint32_t *through = &counter; /* a pointer to a global, in .data */
uint32_t loops = 0;

static uint32_t bump(void) {
  static uint32_t calls = 0; /* a function's static */
  return ++calls;
}

void setup() { counter = 0; }

void loop() {
  *through += kilo_uid + 1;
  ++loops;
  uint32_t calls = bump();
  if (loops == kilo_uid + 5u)
    printf("uid %u loops %u counter %u calls %u\n", kilo_uid, loops, counter, calls);
}

int main() {
  kilo_init();
  kilo_start(setup, loop);
  return 0;
}
)";

TEST(KilobotTest, GlobalsAreEachRobotsOwnAtAnyThreadCount) {
  const fs::path dir = Dir("globals");
  const CommandResult built = Build(dir, "counter", kCounter);
  ASSERT_EQ(built.exit_code, 0) << built.output;
  ASSERT_TRUE(fs::exists(dir / "counter.so"));
  Write(dir / "world.yaml", World("counter", "planar", 150, 1.5));
  for (int threads : {1, 2}) {
    const CommandResult run =
        RunProgram("run " + (dir / "world.yaml").string() + " --steps 200 --quiet --threads " +
                   std::to_string(threads) + " --out " + (dir / "out").string());
    ASSERT_EQ(run.exit_code, 0) << run.output;
    std::set<int> uids;
    for (const std::vector<long>& m :
         Matches(run.output, "uid %ld loops %ld counter %ld calls %ld", 4)) {
      const int uid = static_cast<int>(m[0]);
      const long loops = m[1];
      EXPECT_EQ(loops, uid + 5);
      EXPECT_EQ(m[2], (uid + 1) * loops) << "robot " << uid;
      EXPECT_EQ(m[3], loops) << "robot " << uid;
      uids.insert(uid);
    }
    // kilo_uid is the robot index: 150 distinct ones.
    EXPECT_EQ(uids.size(), 150u) << run.output.substr(0, 2000);
    if (!uids.empty()) {
      EXPECT_EQ(*uids.rbegin(), 149);
    }
  }
  fs::remove_all(dir);
}

// A program written for Kilombo: its USERDATA (mydata) is each robot's own,
// built as for a Kilobot (AVR headers included) and with -DSIMULATOR.
TEST(KilobotTest, KilomboProgramsKeepTheirUserdataPerRobot) {
  const fs::path dir = Dir("kilombo");
  const std::string program = R"(#include <kilombo.h>
#ifdef SIMULATOR
#include <stdio.h>
#else
#include <avr/io.h>
#include <util/delay.h>
#define DEBUG
#include <debug.h>
#endif
typedef struct { uint32_t sum; uint32_t loops; } USERDATA;
REGISTER_USERDATA(USERDATA)
void setup() { mydata->sum = 0; }
void loop() {
  mydata->sum += kilo_uid + 1;
  if (++mydata->loops == 10) printf("uid %u sum %u\n", kilo_uid, mydata->sum);
}
#ifdef SIMULATOR
char *botinfo(void) { return "a Kilombo hook, never called"; }
#endif
int main() { kilo_init(); SET_CALLBACK(botinfo, botinfo); kilo_start(setup, loop); return 0; }
)";
  std::ofstream(dir / "kilombo_avr.c") << program;
  std::ofstream(dir / "kilombo_sim.c") << program;
  const CommandResult avr = RunProgram("kilobot build " + (dir / "kilombo_avr.c").string());
  ASSERT_EQ(avr.exit_code, 0) << avr.output;
  const CommandResult sim =
      RunProgram("kilobot build " + (dir / "kilombo_sim.c").string() + " -- -DSIMULATOR");
  ASSERT_EQ(sim.exit_code, 0) << sim.output;
  for (const std::string name : {"kilombo_avr", "kilombo_sim"}) {
    Write(dir / "world.yaml", World(name, "planar", 30, 1));
    const CommandResult run =
        RunProgram("run " + (dir / "world.yaml").string() +
                   " --steps 12 --quiet --threads 2 --out " + (dir / "out").string());
    ASSERT_EQ(run.exit_code, 0) << run.output;
    int seen = 0;
    for (const std::vector<long>& m : Matches(run.output, "uid %ld sum %ld", 2)) {
      EXPECT_EQ(m[1], 10 * (m[0] + 1)) << name;
      ++seen;
    }
    EXPECT_EQ(seen, 30) << name << ": " << run.output;
  }
  fs::remove_all(dir);
}

// ---- kilolib's software generator ----

// rand() is avr-libc's, 0..0x7FFF, and so is RAND_MAX whichever header comes
// first: it was the host's 2^31 - 1, so that `rand() < RAND_MAX / 2` was
// always true in unchanged programs.
TEST(KilobotTest, RandMaxIsTheOneRandGoesTo) {
  const fs::path dir = Dir("randmax");
  for (const char* order : {"#include <stdlib.h>\n#include <kilolib.h>\n",
                            "#include <kilolib.h>\n#include <stdlib.h>\n"}) {
    const CommandResult built = Build(dir, "randmax", std::string("#define DEBUG\n") + order + R"(
#include <debug.h>
void setup() {
  long below = 0, most = 0, i;
  for (i = 0; i < 10000; i++) {
    int r = rand();
    if (r < RAND_MAX / 2) below++;
    if (r > most) most = r;
  }
  printf("randmax %ld below %ld most %ld\n", (long)RAND_MAX, below, most);
}
void loop() {}
int main() { kilo_init(); kilo_start(setup, loop); return 0; }
)");
    ASSERT_EQ(built.exit_code, 0) << built.output;
    Write(dir / "world.yaml", World("randmax", "planar", 1, 0.5));
    const CommandResult run = RunProgram("run " + (dir / "world.yaml").string() + " --steps 1");
    ASSERT_EQ(run.exit_code, 0) << run.output;
    const auto lines = Matches(run.output, "randmax %ld below %ld most %ld", 3);
    ASSERT_EQ(lines.size(), 1u) << run.output;
    EXPECT_EQ(lines[0][0], 0x7FFF) << order;
    EXPECT_NEAR(lines[0][1], 5000, 300) << order;  // half of them, not all
    EXPECT_LE(lines[0][2], 0x7FFF) << order;
    EXPECT_GT(lines[0][2], 0x7F00) << order;
  }
}

TEST(KilobotTest, RandSoftGivesKilolibsSequence) {
  const fs::path dir = Dir("rand");
  const CommandResult built = Build(dir, "randsoft", R"(#define DEBUG
#include <kilolib.h>
#include <debug.h>
void setup() {
  int i;
  printf("default");
  for (i = 0; i < 12; i++) printf(" %u", rand_soft());
  printf("\n");
  rand_seed(42);
  printf("seed42");
  for (i = 0; i < 12; i++) printf(" %u", rand_soft());
  printf("\n");
}
void loop() {}
int main() { kilo_init(); kilo_start(setup, loop); return 0; }
)");
  ASSERT_EQ(built.exit_code, 0) << built.output;
  Write(dir / "world.yaml", World("randsoft", "planar", 1, 0.5));
  const CommandResult run = RunProgram("run " + (dir / "world.yaml").string() +
                                       " --steps 1 --quiet --out " + (dir / "out").string());
  ASSERT_EQ(run.exit_code, 0) << run.output;
  // kilolib.c's rand_soft: seed 0xaa, accumulator 0; rand_seed sets the
  // seed only (the accumulator goes on).
  uint8_t seed = 0xaa, accumulator = 0;
  const auto next = [&] {
    seed ^= static_cast<uint8_t>(seed << 3);
    seed ^= static_cast<uint8_t>(seed >> 5);
    seed ^= static_cast<uint8_t>(accumulator++ >> 2);
    return static_cast<int>(seed);
  };
  std::string expected = "default";
  for (int i = 0; i < 12; ++i) expected.append(" ").append(std::to_string(next()));
  expected += "\nseed42";
  seed = 42;
  for (int i = 0; i < 12; ++i) expected.append(" ").append(std::to_string(next()));
  EXPECT_NE(run.output.find(expected), std::string::npos) << run.output << "\nexpected:\n"
                                                          << expected;
  fs::remove_all(dir);
}

// ---- motion ----

// Robot uid 0 goes straight, 1 turns left, 2 turns right, 3 runs both
// motors at twice the straight values, 4 below the stall duty.
const char* kMoves = R"(#include <kilolib.h>
void setup() {
  spinup_motors();
  switch (kilo_uid) {
    case 0: set_motors(kilo_straight_left, kilo_straight_right); break;
    case 1: set_motors(kilo_turn_left, 0); break;
    case 2: set_motors(0, kilo_turn_right); break;
    case 3: set_motors(2 * kilo_straight_left, 2 * kilo_straight_right); break;
    default: set_motors(20, 20); break;
  }
}
void loop() {}
int main() { kilo_init(); kilo_start(setup, loop); return 0; }
)";

struct Pose2 {
  double x, y, yaw;
};

std::vector<Pose2> RunWorld(const fs::path& world, int steps, int threads,
                            uint64_t* hash = nullptr) {
  ModuleRegistry registry;
  RegisterBuiltinModules(&registry);
  LoadOptions options;
  options.threads = threads;
  LoadedWorld w = LoadWorld(world.string(), options, registry);
  w.world->set_log_sink([](std::string_view) {});
  w.world->Start();
  for (int i = 0; i < steps; ++i) w.world->Step();
  std::vector<Pose2> poses;
  for (const ModelInstance& robot : w.world->scene().instances()) {
    const Pose& X_WB = w.world->scene().world_pose(robot.root);
    poses.push_back({X_WB.p.x, X_WB.p.y, X_WB.q.Yaw()});
  }
  if (hash != nullptr) *hash = w.world->StateHash();
  w.world->Stop();
  return poses;
}

double AngleDifference(double a, double b) { return std::remainder(a - b, 2 * kPi); }

class KilobotMotionTest : public ::testing::TestWithParam<std::string> {};

TEST_P(KilobotMotionTest, MotorsMoveAtThePublishedSpeeds) {
  const std::string physics = GetParam();
  const fs::path dir = Dir("moves_" + physics);
  const CommandResult built = Build(dir, "moves_" + physics, kMoves);
  ASSERT_EQ(built.exit_code, 0) << built.output;
  // Five robots far apart, all heading +x; exact calibration.
  std::string world = "plugins: [moves_" + physics + "]\nsimulation: {physics: " + physics +
                      ", time_step: 0.03125, physics_substeps: 4, seed: 3}\nmodels:\n";
  for (int i = 0; i < 5; ++i)
    world += "  - {model: " + Model() + ", position: [" + std::to_string(0.5 * i) +
             ", 0], heading_deg: 0, native_controller: moves_" + physics +
             ", parameters: {duty_spread: 0, calibration_error: 0}}\n";
  Write(dir / "world.yaml", world);
  const int steps = 64;  // 2 s
  const double seconds = steps / 32.0;
  const std::vector<Pose2> start = RunWorld(dir / "world.yaml", 0, 1);
  const std::vector<Pose2> end = RunWorld(dir / "world.yaml", steps, 1);
  ASSERT_EQ(end.size(), 5u);
  // Straight: about 1 cm/s along +x (Rubenstein et al. 2012), no turn.
  EXPECT_NEAR((end[0].x - start[0].x) / seconds, 0.01, 0.001);
  EXPECT_NEAR(end[0].y - start[0].y, 0, 0.001);
  EXPECT_NEAR(AngleDifference(end[0].yaw, start[0].yaw), 0, 0.02);
  // Left: counter-clockwise at about 45 deg/s; right: clockwise.
  const double left = AngleDifference(end[1].yaw, start[1].yaw) / seconds;
  const double right = AngleDifference(end[2].yaw, start[2].yaw) / seconds;
  EXPECT_NEAR(left, kPi / 4, 0.1 * kPi / 4);
  EXPECT_NEAR(right, -kPi / 4, 0.1 * kPi / 4);
  // Twice the duty, twice the speed; below the stall duty, nothing.
  EXPECT_NEAR((end[3].x - start[3].x) / seconds, 0.02, 0.002);
  EXPECT_NEAR(std::hypot(end[4].x - start[4].x, end[4].y - start[4].y), 0, 1e-4);
  fs::remove_all(dir);
}

INSTANTIATE_TEST_SUITE_P(Physics, KilobotMotionTest, ::testing::Values("planar", "box2d"));

// A robot's own calibration: with a duty spread, kilo_straight_* differ
// between robots, and each still goes straight on its own values.
TEST(KilobotTest, EachRobotHasItsOwnCalibrationAndGoesStraightOnIt) {
  const fs::path dir = Dir("calibration");
  const CommandResult built = Build(dir, "calib", R"(#define DEBUG
#include <kilolib.h>
#include <debug.h>
void setup() {
  printf("calibration %u %u %u %u %u\n", kilo_uid, kilo_straight_left, kilo_straight_right,
         kilo_turn_left, kilo_turn_right);
  set_motors(kilo_straight_left, kilo_straight_right);
}
void loop() {}
int main() { kilo_init(); kilo_start(setup, loop); return 0; }
)");
  ASSERT_EQ(built.exit_code, 0) << built.output;
  Write(dir / "world.yaml", World("calib", "planar", 20, 3, "{duty_spread: 0.2}"));
  const CommandResult run = RunProgram("run " + (dir / "world.yaml").string() +
                                       " --steps 1 --quiet --out " + (dir / "out").string());
  ASSERT_EQ(run.exit_code, 0) << run.output;
  std::set<std::pair<int, int>> pairs;
  for (const std::vector<long>& m : Matches(run.output, "calibration %ld %ld %ld %ld %ld", 5)) {
    pairs.insert({static_cast<int>(m[1]), static_cast<int>(m[2])});
    EXPECT_EQ(m[1], m[3]);
    EXPECT_EQ(m[2], m[4]);
  }
  EXPECT_GT(pairs.size(), 10u) << run.output;
  // Straight on its own values: heading kept within rounding (one duty unit
  // in 56..84 turns it at most ~1 deg/s).
  const std::vector<Pose2> start = RunWorld(dir / "world.yaml", 0, 1);
  const std::vector<Pose2> end = RunWorld(dir / "world.yaml", 32, 1);
  for (size_t i = 0; i < start.size(); ++i)
    EXPECT_NEAR(AngleDifference(end[i].yaw, start[i].yaw), 0, 2 * kPi / 180) << "robot " << i;
  fs::remove_all(dir);
}

// ---- LED ----

// set_color's 2-bit channels reach the LED ./led: r/3, g/3, b/3, off for
// RGB(0, 0, 0).
TEST(KilobotTest, SetColorReachesTheLed) {
  const fs::path dir = Dir("color");
  const CommandResult built = Build(dir, "colors", R"(#include <kilolib.h>
void setup() {}
void loop() {
  if (kilo_uid == 0) set_color(RGB(3, 0, 0));
  else if (kilo_uid == 1) set_color(RGB(1, 2, 3));
  else set_color(RGB(0, 0, 0));
}
int main() { kilo_init(); kilo_start(setup, loop); return 0; }
)");
  ASSERT_EQ(built.exit_code, 0) << built.output;
  Write(dir / "world.yaml", World("colors", "planar", 3, 0.5));
  ModuleRegistry registry;
  RegisterBuiltinModules(&registry);
  LoadedWorld w = LoadWorld((dir / "world.yaml").string(), LoadOptions{}, registry);
  w.world->set_log_sink([](std::string_view) {});
  Scene& scene = w.world->scene();
  w.world->Start();
  w.world->Step();
  ObjectType led_type;
  ASSERT_TRUE(scene.FindType(kLedTypeName, &led_type));
  const auto led = [&](int robot) {
    return scene.row<LedRow>(led_type, scene.FindObject("./led", scene.instance(robot).root),
                             "led");
  };
  EXPECT_TRUE(led(0).on);
  EXPECT_EQ(led(0).color.x, 1);
  EXPECT_EQ(led(0).color.y, 0);
  EXPECT_NEAR(led(1).color.x, 1.0 / 3, 1e-12);
  EXPECT_NEAR(led(1).color.y, 2.0 / 3, 1e-12);
  EXPECT_EQ(led(1).color.z, 1);
  EXPECT_FALSE(led(2).on);
  w.world->Stop();
  fs::remove_all(dir);
}

// ---- delay() ----

// delay(ms) suspends the robot's program for ms of simulated time: an LED
// blinking with delay(500) is red for half a second, then blue; messages
// keep arriving meanwhile (kilolib's interrupts), kilo_ticks goes on, and
// a delay() in setup() (the random start of kilobotics' sync lab) delays
// the first loop().
const char* kBlink = R"(#include <kilolib.h>
uint8_t heard = 0;
uint32_t first_loop = 0;
void rx(message_t *m, distance_measurement_t *d) { ++heard; }
void setup() { delay(250 * kilo_uid); }
void loop() {
  if (first_loop == 0) first_loop = kilo_ticks + 1;
  set_color(RGB(3, 0, 0));
  delay(500);
  set_color(RGB(0, 0, 3));
  delay(500);
}
int main() { kilo_init(); kilo_message_rx = rx; kilo_start(setup, loop); return 0; }
)";

TEST(KilobotTest, DelaySuspendsTheProgramForSimulatedTime) {
  const fs::path dir = Dir("delay");
  const CommandResult built = Build(dir, "blink", kBlink);
  ASSERT_EQ(built.exit_code, 0) << built.output;
  Write(dir / "world.yaml", World("blink", "planar", 2, 0.5));
  ModuleRegistry registry;
  RegisterBuiltinModules(&registry);
  LoadedWorld w = LoadWorld((dir / "world.yaml").string(), LoadOptions{}, registry);
  w.world->set_log_sink([](std::string_view) {});
  Scene& scene = w.world->scene();
  ObjectType led_type;
  ASSERT_TRUE(scene.FindType(kLedTypeName, &led_type));
  const auto red = [&](int robot) {
    const LedRow& led =
        scene.row<LedRow>(led_type, scene.FindObject("./led", scene.instance(robot).root), "led");
    return led.on && led.color.x == 1;
  };
  w.world->Start();
  // Robot 0 (no start delay): red on steps 0..15 (0.5 s at 1/32 s), blue
  // on 16..31, red again from 32; robot 1 waits 250 ms (8 steps) first.
  std::vector<int> switches0, switches1;
  bool was0 = false, was1 = false;
  for (int step = 0; step < 96; ++step) {
    w.world->Step();
    if (red(0) != was0) switches0.push_back(step), was0 = !was0;
    if (red(1) != was1) switches1.push_back(step), was1 = !was1;
  }
  EXPECT_EQ(switches0, (std::vector<int>{0, 16, 32, 48, 64, 80}));
  EXPECT_EQ(switches1, (std::vector<int>{8, 24, 40, 56, 72, 88}));
  w.world->Stop();
  fs::remove_all(dir);
}

// ---- determinism ----

// A random walk: straight or turning for a random number of ticks.
const char* kWalk = R"(#include <kilolib.h>
uint32_t until;
uint8_t mode;
void setup() { rand_seed(rand_hard()); until = 0; }
void loop() {
  if (kilo_ticks >= until) {
    mode = rand_soft() % 3;
    until = kilo_ticks + 8 + rand_soft() % 32;
    if (mode == 0) set_motors(kilo_straight_left, kilo_straight_right);
    else if (mode == 1) set_motors(kilo_turn_left, 0);
    else set_motors(0, kilo_turn_right);
    set_color(RGB(mode, 3 - mode, 0));
  }
}
int main() { kilo_init(); kilo_start(setup, loop); return 0; }
)";

TEST(KilobotTest, SameHashAtOneAndTwoThreadsWhicheverCopyRanARobot) {
  const fs::path dir = Dir("hash");
  const CommandResult built = Build(dir, "walk", kWalk);
  ASSERT_EQ(built.exit_code, 0) << built.output;
  Write(dir / "world.yaml", World("walk", "planar", 400, 1.2));
  uint64_t one = 0, two = 0;
  const std::vector<Pose2> a = RunWorld(dir / "world.yaml", 100, 1, &one);
  const std::vector<Pose2> b = RunWorld(dir / "world.yaml", 100, 2, &two);
  EXPECT_EQ(one, two);
  // They moved, and not all alike.
  const std::vector<Pose2> start = RunWorld(dir / "world.yaml", 0, 1);
  std::set<long> headings;
  for (size_t i = 0; i < a.size(); ++i) {
    EXPECT_GT(std::hypot(a[i].x - start[i].x, a[i].y - start[i].y) +
                  std::fabs(AngleDifference(a[i].yaw, start[i].yaw)),
              1e-3);
    headings.insert(std::lround(AngleDifference(a[i].yaw, start[i].yaw) * 100));
  }
  EXPECT_GT(headings.size(), 50u);
  // The program with one copy (robots one at a time) and with three: the
  // same run.
  std::string hashes[2];
  for (int k = 0; k < 2; ++k) {
    const CommandResult run = testing::RunCommand(
        std::string("SWARMSIM_KILOBOT_COPIES=") + (k == 0 ? "1" : "3") + " " + SWARMSIM_BINARY +
        " run " + (dir / "world.yaml").string() + " --steps 100 --hash --threads " +
        (k == 0 ? "1" : "2") + " --quiet --out " + (dir / "out").string());
    ASSERT_EQ(run.exit_code, 0) << run.output;
    const size_t at = run.output.find("state-hash: ");
    ASSERT_NE(at, std::string::npos) << run.output;
    hashes[k] = run.output.substr(at + 12, 16);
  }
  EXPECT_EQ(hashes[0], hashes[1]);
  fs::remove_all(dir);
}

// ---- bad programs ----

TEST(KilobotTest, CompileErrorShowsTheCompilersFileAndLine) {
  const fs::path dir = Dir("bad");
  const CommandResult built = Build(dir, "broken", R"(#include <kilolib.h>
void setup() {}
void loop() { set_motors(kilo_straight_left, ); }
int main() { kilo_init(); kilo_start(setup, loop); return 0; }
)");
  EXPECT_NE(built.exit_code, 0);
  EXPECT_NE(built.output.find("broken.c:3:"), std::string::npos) << built.output;
  EXPECT_NE(built.output.find("broken.c does not compile"), std::string::npos) << built.output;
  EXPECT_FALSE(fs::exists(dir / "broken.so"));
  // No main(): said so.
  const CommandResult no_main = Build(dir, "nomain", "#include <kilolib.h>\nvoid loop() {}\n");
  EXPECT_NE(no_main.exit_code, 0);
  EXPECT_NE(no_main.output.find("defines no main()"), std::string::npos) << no_main.output;
  // A call to a function nothing defines: refused when it is built (the
  // link), not when a world loads the plugin; no plugin written.
  const CommandResult undefined = Build(dir, "undefined", R"(#include <kilolib.h>
void setup() {}
void loop() { foo(); }
int main() { kilo_init(); kilo_start(setup, loop); return 0; }
)");
  EXPECT_EQ(undefined.exit_code, 2) << undefined.output;
  EXPECT_NE(undefined.output.find("undefined reference to `foo'"), std::string::npos)
      << undefined.output;
  EXPECT_NE(undefined.output.find("undefined.c does not link"), std::string::npos)
      << undefined.output;
  EXPECT_FALSE(fs::exists(dir / "undefined.so"));
  // A missing file.
  const CommandResult missing = RunProgram("kilobot build " + (dir / "none.c").string());
  EXPECT_EQ(missing.exit_code, 2);
  EXPECT_NE(missing.output.find("none.c: no such file"), std::string::npos) << missing.output;
  // A folder ("no such file" too).
  const CommandResult folder = RunProgram("kilobot build " + dir.string());
  EXPECT_EQ(folder.exit_code, 2);
  EXPECT_NE(folder.output.find(": a folder: give the program's .c file"), std::string::npos)
      << folder.output;
  fs::remove_all(dir);
}

// A program that fails on robot 3 only (after a few ticks): the run ends
// with an error naming the program and the robot, exit 1, summary.json
// written with status error.
void ExpectRunFails(const std::string& name, const std::string& body, const std::string& message) {
  const fs::path dir = Dir(name);
  const CommandResult built = Build(
      dir, name,
      "#include <kilolib.h>\n" + body +
          "\nvoid setup() {}\nint main() { kilo_init(); kilo_start(setup, loop); return 0; }\n");
  ASSERT_EQ(built.exit_code, 0) << built.output;
  Write(dir / "world.yaml", World(name, "planar", 8, 0.5, "{program_timeout: 0.5}"));
  const CommandResult run =
      RunProgram("run " + (dir / "world.yaml").string() + " --steps 40 --quiet --threads 2 --out " +
                 (dir / "out").string());
  EXPECT_EQ(run.exit_code, 1) << run.output;
  const std::string expected =
      (dir / (name + ".c")).string() + " (kilobot program '" + name + "'), robot 3: " + message;
  EXPECT_NE(run.output.find(expected), std::string::npos)
      << run.output << "\nexpected: " << expected;
  std::ifstream summary(dir / "out" / "summary.json");
  ASSERT_TRUE(summary.good());
  EXPECT_EQ(nlohmann::json::parse(summary)["status"], "error");
  fs::remove_all(dir);
}

TEST(KilobotTest, SegfaultEndsTheRunNamingRobotAndProgram) {
  ExpectRunFails("segv",
                 "int *volatile nowhere;\n"
                 "void loop() { if (kilo_uid == 3 && kilo_ticks > 4) *nowhere = 1; }",
                 "segmentation fault in loop()");
}

TEST(KilobotTest, EndlessLoopEndsTheRunAfterTheTimeout) {
  ExpectRunFails("spin",
                 "volatile int x;\n"
                 "void loop() { if (kilo_uid == 3 && kilo_ticks > 4) for (;;) x++; }",
                 "loop() did not return within 0.5 s");
}

TEST(KilobotTest, StackOverflowEndsTheRunNamingIt) {
  ExpectRunFails("deep",
                 "volatile int sink;\n"
                 "int down(int n) { volatile char pad[512]; pad[n & 511] = (char)n;\n"
                 "  return n < 0 ? 0 : down(n + 1) + pad[(n * 7) & 511]; }\n"
                 "void loop() { if (kilo_uid == 3 && kilo_ticks > 4) sink = down(0); }",
                 "segmentation fault (stack overflow) in loop()");
}

TEST(KilobotTest, DivisionByZeroEndsTheRunNamingIt) {
  ExpectRunFails("divide",
                 "volatile int zero;\n"
                 "void loop() { if (kilo_uid == 3 && kilo_ticks > 4) zero = 10 / zero; }",
                 "arithmetic exception");
}

// A program that sends a bad CRC is warned of once, with the parameter that
// keeps such messages; with crc_check: 0 they are heard and nothing is said.
TEST(KilobotTest, ABadCrcIsWarnedOfUnlessReceiversKeepIt) {
  const fs::path dir = Dir("badcrc");
  const CommandResult built = Build(dir, "badcrc", R"(#define DEBUG
#include <kilolib.h>
#include <debug.h>
message_t out;
long heard = 0;
message_t *tx() { return &out; }
void rx(message_t *m, distance_measurement_t *d) { (void)m; (void)d; heard++; }
void setup() {
  out.type = NORMAL;
  out.data[0] = 1;
  out.crc = message_crc(&out) ^ 1;
}
void loop() { if (kilo_ticks == 60) printf("heard %ld\n", heard); }
int main() {
  kilo_init();
  kilo_message_tx = tx;
  kilo_message_rx = rx;
  kilo_start(setup, loop);
  return 0;
}
)");
  ASSERT_EQ(built.exit_code, 0) << built.output;
  Write(dir / "world.yaml", World("badcrc", "planar", 2, 0.12));
  const std::string command = "run " + (dir / "world.yaml").string() + " --steps 70";
  const CommandResult checked = RunProgram(command);
  ASSERT_EQ(checked.exit_code, 0) << checked.output;
  EXPECT_NE(checked.output.find("sends a message whose crc is not message_crc(&msg): receivers "
                                "drop it (parameter crc_check: 0 keeps it; warned once)"),
            std::string::npos)
      << checked.output;
  for (const auto& line : Matches(checked.output, "heard %ld", 1)) EXPECT_EQ(line[0], 0);
  const CommandResult kept = RunProgram(command + " --set kilobot.crc_check=0");
  ASSERT_EQ(kept.exit_code, 0) << kept.output;
  EXPECT_EQ(kept.output.find("warning"), std::string::npos) << kept.output;
  const auto heard = Matches(kept.output, "heard %ld", 1);
  ASSERT_EQ(heard.size(), 2u) << kept.output;
  for (const auto& line : heard) EXPECT_GT(line[0], 0) << kept.output;
  fs::remove_all(dir);
}

// A main() that never returns: one timeout for the run, not one per robot
// (8 robots took 8 timeouts; 300 at the default 5 s, 25 minutes). Kept
// going with on_script_error: disable_script, every robot is disabled, the
// others for robot 0's hang.
TEST(KilobotTest, AMainThatHangsCostsOneTimeout) {
  const fs::path dir = Dir("hangmain");
  const CommandResult built = Build(dir, "hangmain",
                                    "#include <kilolib.h>\nvolatile int x;\n"
                                    "void setup() {}\nvoid loop() {}\n"
                                    "int main() { kilo_init(); for (;;) x++; return 0; }\n");
  ASSERT_EQ(built.exit_code, 0) << built.output;
  std::string world = World("hangmain", "planar", 8, 0.5, "{program_timeout: 0.5}");
  world.replace(world.find("seed: 1}"), 8, "seed: 1, on_script_error: disable_script}");
  Write(dir / "world.yaml", world);
  const CommandResult run =
      RunProgram("run " + (dir / "world.yaml").string() + " --steps 2 --quiet --threads 1 --out " +
                 (dir / "out").string());
  EXPECT_EQ(run.exit_code, 0) << run.output;
  std::ifstream summary(dir / "out" / "summary.json");
  const auto disabled = nlohmann::json::parse(summary)["disabled_scripts"];
  ASSERT_EQ(disabled.size(), 8u) << disabled.dump();
  const std::string program =
      (dir / "hangmain.c").string() + " (kilobot program 'hangmain'), robot ";
  EXPECT_NE(disabled[0].get<std::string>().find(program + "0: main() did not return within 0.5 s"),
            std::string::npos)
      << disabled[0];
  for (size_t i = 1; i < 8; ++i)
    EXPECT_NE(disabled[i].get<std::string>().find(program + std::to_string(i) +
                                                  ": main() not called: on robot 0 it did not "
                                                  "return within 0.5 s"),
              std::string::npos)
        << disabled[i];
  fs::remove_all(dir);
}

// The same faults in a program that calls delay() (it runs on a stack of
// its own): named the same way.
TEST(KilobotTest, FaultsAfterADelayEndTheRunNamingThem) {
  ExpectRunFails("segv_delay",
                 "int *volatile nowhere;\n"
                 "void loop() { delay(40); if (kilo_uid == 3 && kilo_ticks > 4) *nowhere = 1; }",
                 "segmentation fault in loop()");
  ExpectRunFails("deep_delay",
                 "volatile int sink;\n"
                 "int down(int n) { volatile char pad[512]; pad[n & 511] = (char)n;\n"
                 "  return n < 0 ? 0 : down(n + 1) + pad[(n * 7) & 511]; }\n"
                 "void loop() { delay(40); if (kilo_uid == 3 && kilo_ticks > 4) sink = down(0); }",
                 "segmentation fault (stack overflow) in loop()");
  ExpectRunFails("array_delay",
                 "volatile int sink;\n"
                 "void loop() { delay(40); if (kilo_uid == 3 && kilo_ticks > 4) {\n"
                 "  volatile char big[100000]; big[0] = 1; sink = big[0]; } }",
                 "segmentation fault (stack overflow) in loop()");
  ExpectRunFails("spin_delay",
                 "volatile int x;\n"
                 "void loop() { delay(40); if (kilo_uid == 3 && kilo_ticks > 4) for (;;) x++; }",
                 "loop() did not return within 0.5 s");
}

// A kilo_uid the uint16_t cannot hold is refused at start, not wrapped.
TEST(KilobotTest, AKiloUidOutOfRangeIsRefused) {
  const fs::path dir = Dir("uid");
  const CommandResult built =
      Build(dir, "uid",
            "#include <kilolib.h>\nvoid setup() {}\nvoid loop() {}\n"
            "int main() { kilo_init(); kilo_start(setup, loop); return 0; }\n");
  ASSERT_EQ(built.exit_code, 0) << built.output;
  Write(dir / "world.yaml", World("uid", "planar", 2, 0.5));
  // Out of the model's range: refused as the world loads, naming the value (exit 2).
  for (const char* bad : {"70000", "-5"}) {
    const CommandResult run = RunProgram("run " + (dir / "world.yaml").string() +
                                         " --steps 2 --quiet --set kilobot.kilo_uid=" + bad);
    EXPECT_EQ(run.exit_code, 2) << bad;
    EXPECT_NE(run.output.find(std::string("parameter 'kilo_uid' of model 'kilobot' must be within "
                                          "[-1, 65535] (got ") +
                              bad + ")"),
              std::string::npos)
        << run.output;
  }
  // Within it but not whole: the controller's start says so.
  const CommandResult half = RunProgram("run " + (dir / "world.yaml").string() +
                                        " --steps 2 --quiet --set kilobot.kilo_uid=1.5");
  EXPECT_NE(half.exit_code, 0);
  EXPECT_NE(half.output.find("parameter kilo_uid is 1.5: a kilo_uid is a whole number 0..65535"),
            std::string::npos)
      << half.output;
  const CommandResult ok = RunProgram("run " + (dir / "world.yaml").string() +
                                      " --steps 2 --quiet --set kilobot.kilo_uid=65535");
  EXPECT_EQ(ok.exit_code, 0) << ok.output;
  fs::remove_all(dir);
}

// A handler a program installs would be the whole process's: resetting
// SIGSEGV killed swarmsim (exit 139, summary.json "running").
TEST(KilobotTest, SignalHandlersAreRefusedNamingTheCall) {
  ExpectRunFails("sighack",
                 "#include <signal.h>\nint *volatile nowhere;\n"
                 "void loop() { if (kilo_uid == 3 && kilo_ticks > 4) {\n"
                 "  signal(SIGSEGV, SIG_DFL); *nowhere = 1; } }",
                 "signal() called in loop(): a Kilobot program may not handle signals");
  ExpectRunFails("sigact",
                 "#include <signal.h>\n#include <string.h>\n"
                 "void loop() { if (kilo_uid == 3) { struct sigaction a;\n"
                 "  memset(&a, 0, sizeof a); a.sa_handler = SIG_IGN; sigaction(SIGINT, &a, 0); } }",
                 "sigaction() called in loop()");
}

// exit() in a program would end swarmsim itself: it ends the run instead,
// naming the robot, the program and the status.
TEST(KilobotTest, ExitEndsTheRunNamingTheRobot) {
  ExpectRunFails("quits", "#include <stdlib.h>\nvoid loop() { if (kilo_uid == 3) exit(3); }",
                 "exit(3) called in loop()");
}

}  // namespace
}  // namespace swarmsim
