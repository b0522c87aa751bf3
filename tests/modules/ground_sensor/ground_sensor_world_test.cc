// Ground sensors as a user writes them in model files (modules/ground_sensor):
// readings over a floor image and shapes of the test's own (colour, the
// grey formula, the binary threshold), ground arrays on a ring or at listed
// points, noise and failure against their distributions, scripts reading
// one sensor or a whole set, the same hash at 1 and 2 threads, and each
// mistake a load error naming file:line:column.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "framework/state_hash.h"
#include "modules/ground_sensor/ground_sensor.h"
#include "modules/paint/png_io.h"
#include "tests/swarm/loader/world_dir_test.h"

namespace swarmsim {
namespace {

using ground_sensor::GroundSensorRow;

void ExpectHas(const std::string& message, const std::vector<std::string>& fragments) {
  for (const std::string& fragment : fragments)
    EXPECT_NE(message.find(fragment), std::string::npos)
        << "expected '" << fragment << "' in: " << message;
}

class GroundSensorWorldTest : public testing::WorldDirTest {
 protected:
  std::string ErrorOfWorld(const std::string& world_text) {
    try {
      Load(world_text);
    } catch (const Error& e) {
      return e.what();
    }
    return "(no error)";
  }
  // A 3 x 1 image over x -1.5..1.5, y -0.5..0.5: red, black, white thirds
  // (1 m each); the floor's background is mid grey outside.
  std::string ThirdsWorld(const std::string& robots) {
    paint::WritePng(dir_ / "thirds.png", 3, 1, {255, 0, 0, 0, 0, 0, 255, 255, 255});
    return "simulation: {physics: kinematic}\n"
           "floor:\n"
           "  area: {min: [-2, -1], max: [2, 1]}\n"
           "  resolution: 0.01\n"
           "  background: 0.5\n"
           "  image: {file: thirds.png, min: [-1.5, -0.5], max: [1.5, 0.5]}\n"
           "models:\n" +
           robots;
  }
  // The ground sensor rows of `world`'s objects at `path` (every match, in order).
  const GroundSensorRow& Row(World& world, const std::string& path) {
    return RowOf<GroundSensorRow>(world, path);
  }
};

// One sensor of each mode, at the robot's origin.
const char kEyesModel[] =
    "model: eyes\n"
    "objects:\n"
    "  type: dummy\n"
    "  children:\n"
    "    - {name: c, type: ground_sensor, mode: color}\n"
    "    - {name: g, type: ground_sensor}\n"
    "    - {name: b, type: ground_sensor, mode: binary, threshold: 0.25}\n";

TEST_F(GroundSensorWorldTest, ARobotReadsTheRegionItIsOver) {
  Write("eyes.yaml", kEyesModel);
  LoadedWorld w =
      Load(ThirdsWorld("  - {model: eyes.yaml, position: [-1, 0, 0]}\n"      // red
                       "  - {model: eyes.yaml, position: [0, 0.3, 0]}\n"     // black
                       "  - {model: eyes.yaml, position: [1.2, -0.4, 0]}\n"  // white
                       "  - {model: eyes.yaml, position: [1.8, 0, 0]}\n"));  // the background, 0.5
  w.world->Start();
  w.world->Step();
  struct Expected {
    Vec3 color;
    double grey;
    double binary;
  };
  const double bg = 128 / 255.0;                       // 0.5 stored as a byte
  const Expected expected[] = {{{1, 0, 0}, 0.299, 1},  // 0.299 >= 0.25
                               {{0, 0, 0}, 0, 0},
                               {{1, 1, 1}, 1, 1},
                               {{bg, bg, bg}, bg, 1}};
  for (int i = 0; i < 4; ++i) {
    const std::string robot = "/eyes#" + std::to_string(i);
    const GroundSensorRow& c = Row(*w.world, robot + "/c");
    EXPECT_EQ(c.color.x, expected[i].color.x) << robot;
    EXPECT_EQ(c.color.y, expected[i].color.y) << robot;
    EXPECT_EQ(c.color.z, expected[i].color.z) << robot;
    EXPECT_DOUBLE_EQ(c.value, expected[i].grey) << robot;
    EXPECT_DOUBLE_EQ(Row(*w.world, robot + "/g").value, expected[i].grey) << robot;
    EXPECT_EQ(Row(*w.world, robot + "/b").value, expected[i].binary) << robot;
  }
}

TEST_F(GroundSensorWorldTest, TheGreyLevelIsTheLumaOfTheColour) {
  // Pure colours and a mix: 0.299 r + 0.587 g + 0.114 b.
  Write("eyes.yaml", kEyesModel);
  LoadedWorld w = Load(
      "simulation: {physics: kinematic}\narena: {size: 4}\n"
      "floor:\n"
      "  shapes:\n"
      "    - {type: rectangle, min: [-2, -2], max: [-1, 2], color: [0, 1, 0]}\n"
      "    - {type: rectangle, min: [-1, -2], max: [0, 2], color: [0, 0, 1]}\n"
      "    - {type: rectangle, min: [0, -2], max: [1, 2], color: [0.2, 0.4, 0.6]}\n"
      "models:\n"
      "  - {model: eyes.yaml, position: [-1.5, 0, 0]}\n"
      "  - {model: eyes.yaml, position: [-0.5, 0, 0]}\n"
      "  - {model: eyes.yaml, position: [0.5, 0, 0]}\n");
  w.world->Start();
  w.world->Step();
  const double byte = 1 / 255.0;
  EXPECT_DOUBLE_EQ(Row(*w.world, "/eyes#0/g").value, 0.587);
  EXPECT_DOUBLE_EQ(Row(*w.world, "/eyes#1/g").value, 0.114);
  const double r = std::lround(0.2 * 255) * byte, g = std::lround(0.4 * 255) * byte,
               b = std::lround(0.6 * 255) * byte;
  EXPECT_DOUBLE_EQ(Row(*w.world, "/eyes#2/g").value, 0.299 * r + 0.587 * g + 0.114 * b);
  EXPECT_EQ(Row(*w.world, "/eyes#2/b").value, 1);  // about 0.37 >= 0.25
  // Binary: at the threshold reads 1, just under it 0.
  Write("edge.yaml",
        "model: edge\nobjects:\n  type: dummy\n  children:\n"
        "    - {name: at, type: ground_sensor, mode: binary, threshold: 0.587}\n"
        "    - {name: above, type: ground_sensor, mode: binary, threshold: 0.588}\n");
  LoadedWorld e = Load(
      "simulation: {physics: kinematic}\narena: {size: 4}\n"
      "floor: {background: [0, 1, 0]}\n"
      "models: [{model: edge.yaml, position: [0, 0, 0]}]\n");
  e.world->Start();
  e.world->Step();
  EXPECT_EQ(Row(*e.world, "/edge#0/at").value, 1);
  EXPECT_EQ(Row(*e.world, "/edge#0/above").value, 0);
}

TEST_F(GroundSensorWorldTest, ASensorReadsTheNestToWithinAPixelOfItsEdge) {
  Write("eyes.yaml", kEyesModel);
  // A black nest of radius 0.5 on white, 1 cm pixels: robots 0.49 m and
  // 0.51 m from its centre, on several bearings.
  std::string models;
  for (const double angle : {0.0, 0.7, 2.0, 4.0})
    for (const double d : {0.49, 0.51})
      models += "  - {model: eyes.yaml, position: [" + std::to_string(d * std::cos(angle)) + ", " +
                std::to_string(d * std::sin(angle)) + ", 0]}\n";
  LoadedWorld w = Load(
      "simulation: {physics: kinematic}\narena: {size: 2}\n"
      "floor: {resolution: 0.01, shapes: [{type: circle, center: [0, 0], radius: 0.5, color: 0}]}\n"
      "models:\n" +
      models);
  w.world->Start();
  w.world->Step();
  for (int i = 0; i < 8; ++i)
    EXPECT_EQ(Row(*w.world, "/eyes#" + std::to_string(i) + "/g").value, i % 2 == 0 ? 0 : 1) << i;
}

TEST_F(GroundSensorWorldTest, ArraysPlaceSensorsOnARingOrAtPoints) {
  // The foot-bot's 4 motor ground sensors (ARGoS's positions) and a ring of 8.
  Write("bot.yaml",
        "model: bot\nobjects:\n  type: dummy\n  children:\n"
        "    - {type: ground_array, name: motor, points: [[0.063, 0.0116], [-0.063, 0.0116],\n"
        "       [-0.063, -0.0116], [0.063, -0.0116]]}\n"
        "    - {type: ground_array, name: base, count: 8, radius: 0.08, mode: binary}\n");
  // A white floor with a black half-plane x > 0.
  LoadedWorld w = Load(
      "simulation: {physics: kinematic}\narena: {size: 2}\n"
      "floor: {shapes: [{type: rectangle, min: [0, -1], max: [1, 1], color: 0}]}\n"
      "models: [{model: bot.yaml, position: [0, 0, 0], heading_deg: 90}]\n");
  Scene& scene = w.world->scene();
  // Turned 90 degrees: the robot's +x is the world's +y.
  const Vec3 p0 = scene.world_pose(scene.FindObject("/bot#0/motor[0]")).p;
  EXPECT_NEAR(p0.x, -0.0116, 1e-12);
  EXPECT_NEAR(p0.y, 0.063, 1e-12);
  const Vec3 b2 = scene.world_pose(scene.FindObject("/bot#0/base[2]")).p;  // 90 deg: robot's +y
  EXPECT_NEAR(b2.x, -0.08, 1e-12);
  EXPECT_NEAR(b2.y, 0, 1e-12);
  w.world->Start();
  w.world->Step();
  // Sensors right of the robot (world x > 0) see black.
  EXPECT_EQ(Row(*w.world, "/bot#0/motor[0]").value, 1);  // world x = -0.0116: white
  EXPECT_EQ(Row(*w.world, "/bot#0/motor[2]").value, 0);  // world x = +0.0116: black
  EXPECT_EQ(Row(*w.world, "/bot#0/base[2]").value, 1);
  EXPECT_EQ(Row(*w.world, "/bot#0/base[6]").value, 0);
  // Scripts read the set at once, in the order given.
  Write("reader.lua",
        "function sysCall_sensing()\n"
        "  local h = {}\n"
        "  for i = 0, 7 do h[i + 1] = sim.getObject('./base[' .. i .. ']') end\n"
        "  local v = sim.readGroundSensors(h)\n"
        "  print(table.concat(v, ' '))\n"
        "  local value, r, g, b = sim.readGroundSensor(sim.getObject('./motor[2]'))\n"
        "  print(value, r, g, b)\n"
        "end\n");
  Write("bot2.yaml",
        "model: bot2\nobjects:\n  type: dummy\n  script: reader.lua\n  children:\n"
        "    - {type: ground_array, name: motor, points: [[0.063, 0.0116], [-0.063, 0.0116],\n"
        "       [-0.063, -0.0116], [0.063, -0.0116]]}\n"
        "    - {type: ground_array, name: base, count: 8, radius: 0.08, start_angle_deg: 22.5,\n"
        "       mode: binary}\n");
  LoadedWorld s = Load(
      "simulation: {physics: kinematic}\narena: {size: 2}\n"
      "floor: {shapes: [{type: rectangle, min: [0, -1], max: [1, 1], color: 0}]}\n"
      "models: [{model: bot2.yaml, position: [0, 0, 0], heading_deg: 90}]\n");
  std::vector<std::string> log;
  s.world->set_log_sink([&](std::string_view line) { log.emplace_back(line); });
  s.world->Start();
  s.world->Step();
  ASSERT_EQ(log.size(), 2u);
  // Base sensors at 22.5 + 45 i degrees of the robot, 112.5 + 45 i in the
  // world: on the black half (x > 0) for i = 4..7.
  EXPECT_NE(log[0].find("1.0 1.0 1.0 1.0 0.0 0.0 0.0 0.0"), std::string::npos) << log[0];
  EXPECT_NE(log[1].find("0.0\t0.0\t0.0\t0.0"), std::string::npos) << log[1];
}

class GroundNoiseTest : public GroundSensorWorldTest {
 protected:
  std::vector<double> Samples(const std::string& keys, int steps, int threads = 1,
                              uint64_t* hash = nullptr) {
    Write("noisy.yaml",
          "model: noisy\nobjects:\n  type: dummy\n  children:\n"
          "    - {type: ground_array, name: eye, count: 200, radius: 0.1, " +
              keys + "}\n");
    LoadedWorld w = Load(
        "simulation: {physics: kinematic, seed: 7}\narena: {size: 2}\n"
        "floor: {background: 0.5}\n"
        "models: [{model: noisy.yaml, position: [0, 0, 0]}]\n",
        threads);
    w.world->Start();
    std::vector<double> out;
    Scene& scene = w.world->scene();
    ObjectType type;
    EXPECT_TRUE(ground_sensor::FindSensorType(scene, &type));
    for (int s = 0; s < steps; ++s) {
      w.world->Step();
      for (const GroundSensorRow& row : scene.rows<GroundSensorRow>(type).rows)
        out.push_back(row.value);
    }
    if (hash != nullptr) *hash = w.world->StateHash();
    return out;
  }
  static void MeanAndStdDev(const std::vector<double>& v, double* mean, double* sd) {
    double sum = 0, sum2 = 0;
    for (double x : v) sum += x;
    *mean = sum / v.size();
    for (double x : v) sum2 += (x - *mean) * (x - *mean);
    *sd = std::sqrt(sum2 / (v.size() - 1));
  }
};

TEST_F(GroundNoiseTest, GaussianNoiseHasTheConfiguredSpread) {
  const double grey = 128 / 255.0;
  const std::vector<double> v = Samples("noise: 0.05", 25);  // 5,000 readings
  ASSERT_EQ(v.size(), 5000u);
  double mean, sd;
  MeanAndStdDev(v, &mean, &sd);
  // Mean within 5 standard errors (0.05 / sqrt(5000) = 0.0007); the sample
  // std dev within 5% (its relative standard error is 1 / sqrt(2 n) = 1%).
  EXPECT_NEAR(mean, grey, 5 * 0.05 / std::sqrt(5000.0));
  EXPECT_NEAR(sd, 0.05, 0.05 * 0.05);
  // About 68% within one std dev.
  int within = 0;
  for (double x : v) within += std::abs(x - grey) <= 0.05;
  EXPECT_NEAR(within / 5000.0, 0.6827, 5 * std::sqrt(0.6827 * 0.3173 / 5000));
  // Noiseless sensors read the floor exactly.
  for (double x : Samples("", 2)) ASSERT_EQ(x, grey);
}

TEST_F(GroundNoiseTest, UniformNoiseStaysWithinItsWidth) {
  const double grey = 128 / 255.0;
  const std::vector<double> v = Samples("noise_uniform: 0.1", 25);
  double mean, sd;
  MeanAndStdDev(v, &mean, &sd);
  for (double x : v) ASSERT_LE(std::abs(x - grey), 0.1 + 1e-12);
  EXPECT_NEAR(mean, grey, 5 * 0.1 / std::sqrt(3.0) / std::sqrt(5000.0));
  EXPECT_NEAR(sd, 0.1 / std::sqrt(3.0), 0.05 * 0.1 / std::sqrt(3.0));
}

TEST_F(GroundNoiseTest, FailuresReadZeroAtTheConfiguredRate) {
  const std::vector<double> v = Samples("failure_probability: 0.2", 25);
  int failed = 0;
  for (double x : v) {
    if (x == 0)
      ++failed;
    else
      ASSERT_EQ(x, 128 / 255.0);
  }
  // Binomial(5000, 0.2): mean 1000, std dev 28.3; within 5 of them.
  EXPECT_NEAR(failed, 1000, 5 * std::sqrt(5000 * 0.2 * 0.8));
}

TEST_F(GroundNoiseTest, BinaryNoiseFlipsReadingsNearTheThreshold) {
  // Grey 0.502 against a threshold of 0.5 with noise 0.05: reads 1 with
  // probability Phi(0.0020 / 0.05) = 0.516.
  const double p = 0.5 * std::erfc(-(128 / 255.0 - 0.5) / 0.05 / std::sqrt(2.0));
  const std::vector<double> v = Samples("mode: binary, noise: 0.05", 25);
  int ones = 0;
  for (double x : v) {
    ASSERT_TRUE(x == 0 || x == 1);
    ones += x == 1;
  }
  EXPECT_NEAR(ones, 5000 * p, 5 * std::sqrt(5000 * p * (1 - p)));
}

TEST_F(GroundNoiseTest, NoisyReadingsAreTheSameAtAnyThreadCount) {
  uint64_t h1 = 0, h2 = 0;
  const std::string keys =
      "mode: color, noise: 0.05, noise_uniform: 0.02, failure_probability: 0.1";
  const std::vector<double> one = Samples(keys, 5, 1, &h1);
  const std::vector<double> two = Samples(keys, 5, 2, &h2);
  EXPECT_EQ(one, two);
  EXPECT_EQ(h1, h2);
  // And the noise moves the hash: a run without it differs.
  uint64_t h0 = 0;
  Samples("mode: color", 5, 1, &h0);
  EXPECT_NE(h0, h1);
}

TEST_F(GroundSensorWorldTest, BadSensorsNameTheirPlace) {
  auto error_of = [&](const std::string& child) {
    Write("bad.yaml", "model: bad\nobjects:\n  type: dummy\n  children:\n    - " + child + "\n");
    return ErrorOfWorld(
        "simulation: {physics: kinematic}\n"
        "models: [{model: bad.yaml, position: [0, 0, 0]}]\n");
  };
  ExpectHas(error_of("{name: g, type: ground_sensor, mode: gray}"),
            {"bad.yaml:5:", "did you mean 'grey'"});
  ExpectHas(error_of("{name: g, type: ground_sensor, threshold: 0.3}"),
            {"bad.yaml:5:", "'threshold' is for 'mode: binary'"});
  ExpectHas(error_of("{name: g, type: ground_sensor, mode: binary, threshold: 1.5}"),
            {"bad.yaml:5:", "threshold", "at most 1"});
  ExpectHas(error_of("{name: g, type: ground_sensor, noise: -0.1}"), {"bad.yaml:5:", "noise"});
  ExpectHas(error_of("{name: g, type: ground_sensor, failure_probability: 2}"),
            {"bad.yaml:5:", "failure_probability", "at most 1"});
  ExpectHas(error_of("{name: g, type: ground_array, radius: 0.1}"),
            {"bad.yaml:5:", "'points: [[x, y], ...]' or 'count' and 'radius'"});
  ExpectHas(error_of("{name: g, type: ground_array, count: 2, radius: 0.1, points: [[0, 0]]}"),
            {"bad.yaml:5:", "'points' or 'count'"});
  ExpectHas(error_of("{name: g, type: ground_array, points: [[0, 0, 0]]}"), {"bad.yaml:5:"});
  ExpectHas(error_of("{name: g, type: ground_array, count: 4, radius: 0.1, range: 1}"),
            {"bad.yaml:5:", "range"});
}

TEST_F(GroundSensorWorldTest, AScriptReadingSomethingElseGetsItsLineNamed) {
  Write("bad.lua",
        "function sysCall_sensing()\n"
        "  local h = {sim.getObject('./g'), sim.getObject('.')}\n"
        "  sim.readGroundSensors(h)\n"
        "end\n");
  Write("bot.yaml",
        "model: bot\nobjects:\n  type: dummy\n  script: bad.lua\n"
        "  children: [{name: g, type: ground_sensor}]\n");
  LoadedWorld w = Load(
      "simulation: {physics: kinematic}\n"
      "models: [{model: bot.yaml, position: [0, 0, 0]}]\n");
  w.world->Start();
  std::string message = "(no error)";
  try {
    w.world->Step();
  } catch (const Error& e) {
    message = e.what();
  }
  ExpectHas(message, {"bot#0", "bad.lua:3", "sim.readGroundSensors", "handles[2]", "dummy"});
}

TEST_F(GroundSensorWorldTest, EveryKeyIsDocumented) { ExpectDocumented({"ground_sensor"}); }

}  // namespace
}  // namespace swarmsim
