// Light sensors as a user meets them (modules/light): readings against the
// formula computed by hand for lights the test places, nothing behind the
// sensor or out of range, walls and robots in between, two lights adding
// up, a light switched off or dimmed by a script, the noise keys'
// statistics, and the same readings and state hash at 1 and 2 threads.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "framework/environment.h"
#include "framework/scene.h"
#include "framework/world.h"
#include "modules/light/light.h"
#include "tests/framework/error_of.h"
#include "tests/modules/module_world.h"

namespace swarmsim {
namespace {

using light::LightSensorRow;
using light::LightSensorSettings;
using light::LightSourceRow;

constexpr double kPi = 3.141592653589793;

// The formula of light.h for one light, written out again: intensity / d^2
// times 1 - theta / (fov / 2) for a sensor at the origin looking along +x.
double Expected(const Vec3& light, double intensity, double fov) {
  const double d2 = light.SquaredNorm();
  const double theta = std::acos(light.x / std::sqrt(d2));
  return theta < fov / 2 ? intensity / d2 * (1 - theta / (fov / 2)) : 0.0;
}

class LightWorld : public testing::ModuleWorld {
 public:
  explicit LightWorld(int threads = 1) : ModuleWorld("kinematic", threads) {}
  ObjectId Lamp(const Vec3& p, double intensity = 1, bool on = true, ObjectId parent = {}) {
    LightSourceRow row;
    row.intensity = intensity;
    row.on = on;
    return Add("light_source", "lamp", parent, {p, {}}, &row);
  }
  ObjectId Sensor(ObjectId parent, const Pose& X_PS, const LightSensorSettings& s = {}) {
    LightSensorRow row;
    row.settings = Shared<LightSensorSettings>(s);
    return Add("light_sensor", "eye", parent, X_PS, &row);
  }
  double Reading(ObjectId sensor) { return RowOf<LightSensorRow>("light_sensor", sensor).reading; }
  // One sense phase (a step: the reading is of the lights at its start).
  double SenseOnce(ObjectId sensor) {
    EXPECT_EQ(Run(1), "");
    return Reading(sensor);
  }
};

TEST(LightSensorTest, ReadsIntensityOverSquaredDistanceFallingWithTheAngle) {
  // A light 1 m ahead, 0.5 m to the left and 0.3 m up: d^2 = 1.34, 31.7 deg
  // off the axis; a second sensor with a 120 deg field of view.
  const Vec3 p{1, 0.5, 0.3};
  LightWorld w;
  w.Lamp(p, 2.0);
  const ObjectId wide = w.Sensor({}, {});
  LightSensorSettings narrow_settings;
  narrow_settings.fov = 120 * kPi / 180;
  const ObjectId narrow = w.Sensor({}, {}, narrow_settings);
  ASSERT_EQ(w.Run(1), "");
  const double theta = std::acos(1 / std::sqrt(1.34));
  EXPECT_NEAR(w.Reading(wide), 2.0 / 1.34 * (1 - theta / (kPi / 2)), 1e-12);
  EXPECT_NEAR(w.Reading(narrow), 2.0 / 1.34 * (1 - theta / (kPi / 3)), 1e-12);
  EXPECT_NEAR(w.Reading(wide), Expected(p, 2.0, kPi), 1e-12);
  // Straight ahead at 2 m: intensity / 4, whatever the field of view.
  LightWorld ahead;
  ahead.Lamp({2, 0, 0}, 1.0);
  EXPECT_NEAR(ahead.SenseOnce(ahead.Sensor({}, {})), 0.25, 1e-15);
}

TEST(LightSensorTest, TheSensorsPoseTurnsItsAxis) {
  // A sensor turned 90 deg left (its +x along world +y) on a robot at
  // (1, 1): a light at (1, 3) is straight ahead of it, 2 m away.
  LightWorld w;
  w.Lamp({1, 3, 0.1}, 1.0);
  const ObjectId bot = w.Robot("bot", {{1, 1, 0.1}, Quat::FromYaw(kPi / 2)});
  const ObjectId eye = w.Sensor(bot, {});
  EXPECT_NEAR(w.SenseOnce(eye), 0.25, 1e-12);
}

TEST(LightSensorTest, NothingBehindOrBesideTheFieldOfViewOrOutOfRange) {
  LightWorld w;
  w.Lamp({-1, 0, 0}, 5.0);    // behind
  w.Lamp({0, 1, 0}, 5.0);     // 90 deg off: the edge of 180 deg reads 0
  w.Lamp({0.1, -1, 0}, 5.0);  // 84 deg off: a little
  const ObjectId eye = w.Sensor({}, {});
  LightSensorSettings ranged;
  ranged.range = 0.9;  // the third light is 1.005 m away
  const ObjectId short_eye = w.Sensor({}, {}, ranged);
  ASSERT_EQ(w.Run(1), "");
  EXPECT_NEAR(w.Reading(eye), Expected({0.1, -1, 0}, 5.0, kPi), 1e-12);
  EXPECT_GT(w.Reading(eye), 0);
  EXPECT_EQ(w.Reading(short_eye), 0);

  LightWorld behind;
  behind.Lamp({-2, 0.3, 1}, 100.0);
  EXPECT_EQ(behind.SenseOnce(behind.Sensor({}, {})), 0);
}

TEST(LightSensorTest, TwoLightsAdd) {
  const Vec3 a{1, 0.2, 0}, b{0.5, -0.8, 0.4};
  LightWorld w;
  w.Lamp(a, 1.5);
  w.Lamp(b, 0.7);
  const double both = w.SenseOnce(w.Sensor({}, {}));
  EXPECT_NEAR(both, Expected(a, 1.5, kPi) + Expected(b, 0.7, kPi), 1e-12);
  LightWorld only_a;
  only_a.Lamp(a, 1.5);
  LightWorld only_b;
  only_b.Lamp(b, 0.7);
  EXPECT_NEAR(both,
              only_a.SenseOnce(only_a.Sensor({}, {})) + only_b.SenseOnce(only_b.Sensor({}, {})),
              1e-12);
}

TEST(LightSensorTest, AWallBetweenHidesTheLightUnlessOcclusionIsOff) {
  LightWorld w;
  w.Lamp({2, 0, 0.1}, 1.0);
  w.Box("wall", {}, {{1, 0, 0.5}, {}}, {0.1, 2, 1});  // static: the world's line of sight
  const ObjectId eye = w.Sensor({}, {{0, 0, 0.1}, {}});
  LightSensorSettings see_through;
  see_through.occlusion = false;
  const ObjectId xray = w.Sensor({}, {{0, 0, 0.1}, {}}, see_through);
  // A sensor above the wall sees over it.
  const ObjectId high = w.Sensor({}, {{0, 0, 3}, {}});
  ASSERT_EQ(w.Run(1), "");
  EXPECT_EQ(w.Reading(eye), 0);
  EXPECT_NEAR(w.Reading(xray), 0.25, 1e-12);
  EXPECT_NEAR(w.Reading(high), Expected({2, 0, -2.9}, 1.0, kPi), 1e-12);
}

// The formula for a sensor at p looking along the unit axis a.
double ExpectedAt(const Vec3& p, const Vec3& a, const Vec3& light, double intensity) {
  const Vec3 d = light - p;
  const double theta = std::acos(a.Dot(d) / d.Norm());
  return theta < kPi / 2 ? intensity / d.SquaredNorm() * (1 - theta / (kPi / 2)) : 0.0;
}

TEST(LightSensorTest, AWallShadesSomeSensorsOfARingAndNotOthers) {
  // A robot's ring of 8 sensors (radius 0.1 m) near a wall that reaches
  // from y = 0.05 to 1 m at x = 0.5 m, a light 2 m ahead: the sensor at
  // 45 deg is in the wall's shadow (its line to the light crosses x = 0.5
  // at y = 0.055), those at 0 and -45 deg are not. A second robot far
  // from the wall reads all three.
  LightWorld w;
  const Vec3 light{2, 0, 0.1};
  w.Lamp(light, 1.0);
  w.Box("wall", {}, {{0.5, 0.525, 0.5}, {}}, {0.02, 0.95, 1});
  std::vector<std::vector<ObjectId>> rings;
  for (const double y : {0.0, -3.0}) {
    const ObjectId bot = w.Robot("bot", {{0, y, 0.1}, {}});
    rings.emplace_back();
    for (int k = 0; k < 8; ++k) {
      const double a = k * kPi / 4;
      rings.back().push_back(
          w.Sensor(bot, {{0.1 * std::cos(a), 0.1 * std::sin(a), 0}, Quat::FromYaw(a)}));
    }
  }
  ASSERT_EQ(w.Run(1), "");
  const auto expected = [&](double y, int k) {
    const double a = k * kPi / 4;
    return ExpectedAt({0.1 * std::cos(a), y + 0.1 * std::sin(a), 0.1},
                      {std::cos(a), std::sin(a), 0}, light, 1.0);
  };
  EXPECT_NEAR(w.Reading(rings[0][0]), expected(0, 0), 1e-12);
  EXPECT_GT(w.Reading(rings[0][0]), 0.2);
  EXPECT_EQ(w.Reading(rings[0][1]), 0);  // shaded
  EXPECT_GT(expected(0, 1), 0.1);        // what it would read
  EXPECT_NEAR(w.Reading(rings[0][7]), expected(0, 7), 1e-12);
  for (const int k : {0, 1, 7}) EXPECT_NEAR(w.Reading(rings[1][k]), expected(-3, k), 1e-12) << k;
  for (const int k : {2, 3, 4, 5, 6}) EXPECT_EQ(w.Reading(rings[0][k]), 0) << k;  // facing away
}

TEST(LightSensorTest, TheMapsVoxelsHideTheLight) {
  // A map block across +x between the sensor and a light 2 m ahead; a
  // second light to the left is in clear view.
  LightWorld w;
  w.Lamp({2, 0, 0.1}, 1.0);
  w.Lamp({0.5, 1, 0.1}, 1.0);
  auto map = std::make_shared<EnvironmentMap>();
  map->source = "test";
  map->resolution = 0.05;
  map->boxes.push_back({{1.0, -0.2, 0}, {1.05, 0.2, 0.4}});
  map->lo = map->boxes[0].lo;
  map->hi = map->boxes[0].hi;
  w.scene().set_environment(map);
  const ObjectId eye = w.Sensor({}, {{0, 0, 0.1}, {}});
  LightSensorSettings see_through;
  see_through.occlusion = false;
  const ObjectId xray = w.Sensor({}, {{0, 0, 0.1}, {}}, see_through);
  ASSERT_EQ(w.Run(1), "");
  const double left = Expected({0.5, 1, 0}, 1.0, kPi);
  EXPECT_NEAR(w.Reading(eye), left, 1e-12);
  EXPECT_NEAR(w.Reading(xray), left + 0.25, 1e-12);
}

TEST(LightSensorTest, ALampInsideTheShadeItHangsFromShines) {
  // A lamp inside a static shade (its parent) reads; one inside a static
  // crate it does not hang from is hidden.
  LightWorld w;
  const ObjectId shade = w.Box("shade", {}, {{1, 0, 0.5}, {}}, {0.2, 0.2, 0.2});
  w.Lamp({0, 0, 0}, 1.0, true, shade);  // at (1, 0, 0.5)
  w.Box("crate", {}, {{0, -1, 0.5}, {}}, {0.2, 0.2, 0.2});
  w.Lamp({0, -1, 0.5}, 1.0);
  LightSensorSettings all_round;
  all_round.fov = 2 * kPi;
  const ObjectId eye = w.Sensor({}, {{0, 0, 0.5}, {}}, all_round);
  EXPECT_NEAR(w.SenseOnce(eye), 1.0, 1e-12);
}

TEST(LightSensorTest, OtherRobotsHideTheLightWhenRobotOcclusionIsOn) {
  // Robot A's sensors look at a light 2 m ahead; robot B's body (a box)
  // stands halfway. A's own body, round its sensor, never hides it.
  LightWorld w;
  w.Lamp({2, 0, 0.1}, 1.0);
  const ObjectId a = w.Robot("a", {{0, 0, 0.1}, {}});
  w.Box("a_body", a, {}, {0.3, 0.3, 0.2});
  LightSensorSettings robots;
  robots.robot_occlusion = true;
  const ObjectId blocked = w.Sensor(a, {}, robots);
  const ObjectId plain = w.Sensor(a, {});
  const ObjectId b = w.Robot("b", {{1, 0, 0.1}, {}});
  w.Box("b_body", b, {}, {0.2, 0.2, 0.2});
  ASSERT_EQ(w.Run(1), "");
  EXPECT_EQ(w.Reading(blocked), 0);
  EXPECT_NEAR(w.Reading(plain), 0.25, 1e-12);
  // B moves aside: both read the light.
  w.scene().SetLocalPose(b, {{1, 1, 0.1}, {}});
  ASSERT_EQ(w.Run(1), "");
  EXPECT_NEAR(w.Reading(blocked), 0.25, 1e-12);
}

TEST(LightSensorTest, ARobotDoesNotReadItsOwnLight) {
  LightWorld w;
  const ObjectId bot = w.Robot("bot", {});
  w.Lamp({0.1, 0, 0}, 1.0, true, bot);
  const ObjectId own = w.Sensor(bot, {});
  const ObjectId other = w.Sensor({}, {{-0.9, 0, 0}, {}});
  ASSERT_EQ(w.Run(1), "");
  EXPECT_EQ(w.Reading(own), 0);
  EXPECT_NEAR(w.Reading(other), 1.0, 1e-12);
}

TEST(LightSensorTest, SaturationCapsTheReading) {
  LightWorld w;
  w.Lamp({0.5, 0, 0}, 1.0);  // reads 4
  LightSensorSettings s;
  s.saturation = 1.5;
  EXPECT_EQ(w.SenseOnce(w.Sensor({}, {}, s)), 1.5);
}

TEST(LightSensorTest, ALightSwitchedOffOrDimmedByAScriptReadsSoNextStep) {
  // The scene's script on the lamp: dims it to half in its 3rd step's
  // actuation, switches it off in its 5th and back on in its 7th.
  LightWorld w;
  const ObjectId lamp = w.Lamp({1, 0, 0}, 2.0);
  const ObjectId eye = w.Sensor({}, {});
  w.Script(lamp, R"(
    local n = 0
    function sysCall_actuation()
      n = n + 1
      local me = sim.getObject('.')
      if n == 3 then sim.setLightSourceIntensity(me, 1) end
      if n == 5 then sim.setLightSourceOn(me, false) end
      if n == 7 then sim.setLightSourceOn(me, true) end
      local intensity, on = sim.getLightSource(me)
      print(intensity, on)
    end
  )");
  std::vector<double> readings;
  for (int step = 0; step < 8; ++step) readings.push_back(w.SenseOnce(eye));
  // Step k's reading is sensed before step k's scripts run.
  const std::vector<double> expected = {2, 2, 2, 1, 1, 0, 0, 1};
  EXPECT_EQ(readings, expected);
  ASSERT_GE(w.log().size(), 5u);
  EXPECT_CONTAINS(w.log()[4], "1.0\tfalse");
}

TEST(LightSensorTest, ScriptsReadOneSensorOrAnArrayAndBadArgumentsAreScriptErrors) {
  LightWorld w;
  w.Lamp({1, 0, 0}, 1.0);
  const ObjectId bot = w.Robot("bot", {});
  w.Sensor(bot, {});
  w.Sensor(bot, {{0, 0, 0}, Quat::FromYaw(kPi)});  // looking back
  w.Script(bot, R"(
    local eyes, values = {}, {}
    function sysCall_init()
      eyes[1] = sim.getObject('./eye[0]')
      eyes[2] = sim.getObject('./eye[1]')
    end
    function sysCall_sensing()
      local r = sim.readLightSensors(eyes, values)
      print(sim.readLightSensor(eyes[1]), r == values, values[1], values[2])
    end
  )");
  ASSERT_EQ(w.Run(2), "");
  ASSERT_FALSE(w.log().empty());
  EXPECT_CONTAINS(w.log().back(), "1.0\ttrue\t1.0\t0.0");

  const auto error_of = [](const std::string& line) {
    LightWorld e;
    const ObjectId lamp = e.Lamp({1, 0, 0}, 1.0);
    const ObjectId robot = e.Robot("bot", {});
    e.Sensor(robot, {});
    e.Lamp({0, 0, 0.2}, 1.0, true, robot);  // ./lamp: the robot's own
    e.Script(robot,
             "function sysCall_actuation()\n  local lamp, mine = sim.getObject('/lamp'), "
             "sim.getObject('./lamp')\n  " +
                 line + "\nend\n",
             "bot.lua");
    (void)lamp;
    return e.Run(1);
  };
  EXPECT_CONTAINS(error_of("sim.setLightSourceIntensity(mine, -1)"),
                  "bot.lua:3: sim.setLightSourceIntensity: the intensity must be a finite number "
                  ">= 0 (got -1");
  EXPECT_CONTAINS(error_of("sim.setLightSourceIntensity(mine, 0/0)"), "(got nan)");  // "-nan"
  EXPECT_CONTAINS(error_of("sim.setLightSourceIntensity(mine)"), "bad argument #2");
  EXPECT_EQ(error_of("sim.setLightSourceIntensity(mine, 0.5); sim.setLightSourceOn(mine, false)"),
            "");
  // The scene's lamp is not the robot's to switch.
  EXPECT_CONTAINS(error_of("sim.setLightSourceOn(lamp, false)"), "only its own light sources");
  EXPECT_CONTAINS(error_of("sim.setLightSourceOn(lamp, 1)"), "bot.lua:3:");
  EXPECT_CONTAINS(error_of("sim.readLightSensor(lamp)"), "bot.lua:3:");
  EXPECT_CONTAINS(error_of("sim.readLightSensor(lamp)"), "is a light_source, not a light_sensor");
  EXPECT_CONTAINS(error_of("sim.readLightSensors({sim.getObject('./eye'), 'x'})"),
                  "handles[2] is not an object handle");
  EXPECT_CONTAINS(error_of("sim.getLightSource(sim.getObject('./eye'))"),
                  "is a light_sensor, not a light_source");
  EXPECT_EQ(error_of("sim.getLightSource(lamp)"), "");
}

// Many sensors at one place, 1 m from a light straight ahead (reading 1):
// the noise keys' distributions.
std::vector<double> NoisyReadings(const NoiseSettings& noise, int sensors, int steps) {
  LightWorld w;
  w.Lamp({1, 0, 0}, 1.0);
  LightSensorSettings s;
  s.noise = noise;
  std::vector<ObjectId> eyes;
  for (int i = 0; i < sensors; ++i) eyes.push_back(w.Sensor({}, {}, s));
  std::vector<double> out;
  for (int k = 0; k < steps; ++k) {
    EXPECT_EQ(w.Run(1), "");
    for (const ObjectId e : eyes) out.push_back(w.Reading(e));
  }
  return out;
}

void MeanAndStdDev(const std::vector<double>& v, double* mean, double* sd) {
  double sum = 0, sum2 = 0;
  for (const double x : v) sum += x;
  *mean = sum / static_cast<double>(v.size());
  for (const double x : v) sum2 += (x - *mean) * (x - *mean);
  *sd = std::sqrt(sum2 / static_cast<double>(v.size() - 1));
}

TEST(LightSensorTest, NoiseKeysGiveTheirDistributions) {
  double mean = 0, sd = 0;
  // Gaussian, sd 0.1: n = 20,000, so the mean is within 4 sd / sqrt(n) =
  // 0.003 and the sd within about 3%.
  NoiseSettings gaussian;
  gaussian.gaussian = 0.1;
  const std::vector<double> g = NoisyReadings(gaussian, 200, 100);
  MeanAndStdDev(g, &mean, &sd);
  EXPECT_NEAR(mean, 1.0, 0.003);
  EXPECT_NEAR(sd, 0.1, 0.003);
  // Within one sd: 68.3%.
  int within = 0;
  for (const double x : g) within += std::abs(x - 1) < 0.1;
  EXPECT_NEAR(within / static_cast<double>(g.size()), 0.683, 0.015);
  // Uniform, half width 0.2: every reading in [0.8, 1.2], sd 0.2 / sqrt(3).
  NoiseSettings uniform;
  uniform.uniform = 0.2;
  const std::vector<double> u = NoisyReadings(uniform, 200, 100);
  MeanAndStdDev(u, &mean, &sd);
  EXPECT_NEAR(mean, 1.0, 0.003);
  EXPECT_NEAR(sd, 0.2 / std::sqrt(3.0), 0.003);
  for (const double x : u) ASSERT_TRUE(x >= 0.8 && x <= 1.2) << x;
  // Failure 0.3: 30% of readings are 0, the rest exact.
  NoiseSettings failing;
  failing.failure = 0.3;
  const std::vector<double> f = NoisyReadings(failing, 200, 100);
  int zeros = 0;
  for (const double x : f) {
    ASSERT_TRUE(x == 0 || x == 1.0) << x;
    zeros += x == 0;
  }
  EXPECT_NEAR(zeros / static_cast<double>(f.size()), 0.3, 0.013);  // 4 sd of a binomial
  // Large noise on a small reading: clamped to >= 0.
  NoiseSettings wide;
  wide.gaussian = 5;
  for (const double x : NoisyReadings(wide, 50, 10)) ASSERT_GE(x, 0);
}

TEST(LightSensorTest, NoNoiseKeysNoDraws) {
  // Two steps without noise read the same, and the reading is exact.
  const std::vector<double> r = NoisyReadings(NoiseSettings{}, 3, 2);
  for (const double x : r) EXPECT_EQ(x, 1.0);
}

// A swarm of robots with noisy, robot-occluded sensors round a light, a wall
// and lights on some robots, the light switched by a script: the same
// readings and state hash at 1 and 2 threads.
struct SwarmRun {
  std::vector<double> readings;
  uint64_t hash = 0;
};
SwarmRun RunSwarm(int threads) {
  LightWorld w(threads);
  const ObjectId lamp = w.Lamp({0, 0, 0.5}, 3.0);
  w.Script(lamp, R"(
    local n = 0
    function sysCall_actuation()
      n = n + 1
      sim.setLightSourceOn(sim.getObject('.'), n % 4 ~= 0)
      sim.setLightSourceIntensity(sim.getObject('.'), 2 + n % 3)
    end
  )");
  w.Box("wall", {}, {{1.5, 0, 0.5}, {}}, {0.1, 3, 1});
  LightSensorSettings s;
  s.robot_occlusion = true;
  s.noise.gaussian = 0.05;
  s.noise.failure = 0.1;
  std::vector<ObjectId> eyes;
  for (int i = 0; i < 300; ++i) {
    const double a = 0.37 * i, r = 0.3 + 0.01 * i;
    const ObjectId bot = w.Robot("bot" + std::to_string(i),
                                 {{r * std::cos(a), r * std::sin(a), 0.1}, Quat::FromYaw(0.9 * i)});
    w.Box("body", bot, {}, {0.15, 0.15, 0.15});
    for (int k = 0; k < 8; ++k)
      eyes.push_back(w.Sensor(bot,
                              {{0.08 * std::cos(k * kPi / 4), 0.08 * std::sin(k * kPi / 4), 0},
                               Quat::FromYaw(k * kPi / 4)},
                              s));
    if (i % 10 == 0) w.Lamp({0, 0, 0.1}, 0.5, true, bot);
  }
  SwarmRun run;
  EXPECT_EQ(w.Run(6), "");
  for (const ObjectId e : eyes) run.readings.push_back(w.Reading(e));
  run.hash = w.world().StateHash();
  return run;
}

TEST(LightSensorTest, TheSameAtOneAndTwoThreads) {
  const SwarmRun one = RunSwarm(1), two = RunSwarm(2);
  EXPECT_EQ(one.readings, two.readings);
  EXPECT_EQ(one.hash, two.hash);
  // Some read light, some are in shadows or failed.
  int lit = 0, dark = 0;
  for (const double x : one.readings) (x > 0 ? lit : dark) += 1;
  EXPECT_GT(lit, 300);
  EXPECT_GT(dark, 300);
}

}  // namespace
}  // namespace swarmsim
