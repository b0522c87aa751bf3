// The robot models of worlds/models/ against their published figures
// (worlds/README.md, "e-puck" and "foot-bot"): each drives straight and
// turns on the spot at the speed its wheels give, under Box2D and the
// planar contact backend; the e-puck's front IR sensor reads the response
// curve at known distances from a wall, its ground sensors the floor, its
// board and camera the robots they should; the complete foot-bot has its
// optional devices, the bare one none of them.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "framework/world.h"
#include "modules/proximity/proximity_sensor.h"
#include "tests/swarm/loader/world_dir_test.h"

namespace swarmsim {
namespace {

const std::string kModels = std::string(SWARMSIM_SOURCE_DIR) + "/worlds/models/";

class RobotModelsTest : public testing::WorldDirTest {
 protected:
  // A world of `physics` with the robots `models` (model entries, YAML flow
  // maps) whose controller is drive.lua: both wheels at the world's `left`
  // and `right` (m/s at the rim); it records what `record` (Lua
  // statements run in sysCall_sensing) records.
  LoadedWorld LoadRobots(const std::string& physics, const std::string& models,
                         const std::string& extra = "", const std::string& record = "",
                         const std::string& wheels = "{left: 0, right: 0}") {
    Write("drive.lua",
          "function sysCall_init()\n"
          "  local w = sim.getParam('wheel_radius')\n"
          "  sim.setJointTargetVelocity(sim.getObject('./leftMotor'), sim.getParam('left') / w)\n"
          "  sim.setJointTargetVelocity(sim.getObject('./rightMotor'), sim.getParam('right') / w)\n"
          "end\n"
          "function sysCall_sensing()\n" +
              record + "\nend\n");
    LoadedWorld w = Load("simulation: {physics: " + physics +
                         ", time_step: 0.1, physics_substeps: 10, seed: 1}\n"
                         "parameters: " +
                         wheels + "\n" + extra + "models:\n" + models);
    w.world->Start();
    return w;
  }
  std::string Robot(const std::string& model, const std::string& where,
                    const std::string& parameters = "") {
    return "  - {model: " + kModels + model + ", " + where +
           ", parameters: {controller: " + (dir_ / "drive.lua").string() +
           (parameters.empty() ? "" : ", " + parameters) + "}}\n";
  }
  static double Last(const std::vector<MetricSample>& metrics, const std::string& name) {
    double v = NAN;
    for (const MetricSample& m : metrics)
      if (m.name == name) v = m.value;
    return v;
  }

  // The speed (m/s) and turn rate (rad/s) of `model` with both wheels at
  // `left` and `right` m/s, measured between steps 10 and 30 (after any
  // start-up transient).
  void Measure(const std::string& physics, const std::string& model, double left, double right,
               double* speed, double* turn_rate) {
    LoadedWorld w =
        LoadRobots(physics, Robot(model, "position: [0, 0]"), "", "",
                   "{left: " + std::to_string(left) + ", right: " + std::to_string(right) + "}");
    const ObjectId root = w.world->scene().instance(0).root;
    for (int i = 0; i < 10; ++i) w.world->Step();
    const Pose start = w.world->scene().world_pose(root);
    double turned = 0, yaw = start.q.Yaw();
    for (int i = 0; i < 20; ++i) {
      w.world->Step();
      const double now = w.world->scene().world_pose(root).q.Yaw();
      turned += std::remainder(now - yaw, 2 * M_PI);
      yaw = now;
    }
    const Pose end = w.world->scene().world_pose(root);
    *speed = std::hypot(end.p.x - start.p.x, end.p.y - start.p.y) / 2.0;
    *turn_rate = turned / 2.0;
  }
};

// e-puck: 1000 steps/s = one wheel turn a second, 2 pi 0.0205 = 0.1288 m/s;
// on the spot at v the body turns at 2 v / 0.053 rad/s (wheel base 53 mm).
TEST_F(RobotModelsTest, TheEpuckDrivesAndTurnsAtItsPublishedSpeeds) {
  for (const char* physics : {"box2d", "planar"}) {
    double speed, rate;
    Measure(physics, "epuck.yaml", 0.1288, 0.1288, &speed, &rate);
    EXPECT_NEAR(speed, 0.1288, 0.1288 * 0.02) << physics;
    EXPECT_NEAR(rate, 0, 0.01) << physics;
    Measure(physics, "epuck.yaml", -0.05, 0.05, &speed, &rate);
    EXPECT_NEAR(rate, 2 * 0.05 / 0.053, 2 * 0.05 / 0.053 * 0.03) << physics;
    EXPECT_LT(speed, 0.005) << physics;
  }
}

// foot-bot: ARGoS's wheel base 0.14 m.
TEST_F(RobotModelsTest, TheFootbotDrivesAndTurnsAtItsWheelSpeeds) {
  for (const char* physics : {"box2d", "planar"}) {
    double speed, rate;
    Measure(physics, "footbot.yaml", 0.1, 0.1, &speed, &rate);
    EXPECT_NEAR(speed, 0.1, 0.002) << physics;
    Measure(physics, "footbot.yaml", -0.1, 0.1, &speed, &rate);
    EXPECT_NEAR(rate, 2 * 0.1 / 0.14, 2 * 0.1 / 0.14 * 0.03) << physics;
  }
}

// The e-puck turned by 17.2 deg so that IR0 (at -17.2 deg) faces a wall
// whose face is `gap` m from the body: IR0 reads the curve at `gap`
// (worlds/models/epuck.yaml: Webots's table, distances from the body).
TEST_F(RobotModelsTest, TheEpucksFrontIrReadsTheCurveAtKnownDistancesFromAWall) {
  struct Case {
    double gap, value;
  };
  for (const char* physics : {"box2d", "planar"}) {
    for (const Case c : {Case{0.002, 4095 + (2133.33 - 4095) * 0.4}, Case{0.01, 1465.73},
                         Case{0.03, 234.93}, Case{0.045, (158.03 + 120) / 2}, Case{0.1, 67.19}}) {
      LoadedWorld w =
          LoadRobots(physics, Robot("epuck.yaml", "position: [0, 0], heading_deg: 17.2"),
                     "obstacles: [{shape: box, size: [0.1, 2, 0.2], position: [" +
                         std::to_string(0.035 + c.gap + 0.05 + 1e-6) + ", 0, 0.1]}]\n",
                     "sim.recordMetric('ir0', sim.readProximityValue(sim.getObject('./ir[0]')))\n"
                     "sim.recordMetric('ir3', sim.readProximityValue(sim.getObject('./ir[3]')))");
      w.world->Step();
      w.world->Step();
      const std::vector<MetricSample> m = w.world->TakeMetrics();
      // Within 0.1% (the model's positions are rounded to 10 um, and the
      // curve falls by 390 per mm near contact).
      EXPECT_NEAR(Last(m, "ir0"), c.value, std::max(1.0, 1e-3 * c.value))
          << physics << " gap " << c.gap;
      EXPECT_NEAR(Last(m, "ir3"), 67.19, 1e-3) << physics << ": IR3 looks back at nothing";
    }
  }
}

TEST_F(RobotModelsTest, TheEpucksGroundSensorsReadTheFloorUnderTheirFront) {
  LoadedWorld w = LoadRobots(
      "planar", Robot("epuck.yaml", "position: [0, 0]") + Robot("epuck.yaml", "position: [1, 0]"),
      "floor: {area: {min: [-2, -2], max: [2, 2]}, background: 1, resolution: 0.005,\n"
      "        shapes: [{type: circle, center: [0, 0], radius: 0.2, color: 0}]}\n",
      "local g = sim.readGroundSensors({sim.getObject('./ground[0]'), "
      "sim.getObject('./ground[1]'), sim.getObject('./ground[2]')})\n"
      "sim.recordMetric('ground', g[1] + g[2] + g[3])");
  w.world->Step();
  std::vector<double> sums;
  for (const MetricSample& m : w.world->TakeMetrics())
    if (m.name == "ground") sums.push_back(m.value);
  ASSERT_EQ(sums.size(), 2u);
  EXPECT_NEAR(sums[0], 0, 1e-9);  // over the black disc
  EXPECT_NEAR(sums[1], 3, 1e-9);  // over the white floor
}

// The range-and-bearing board (0.8 m) hears e-pucks 0.5 and 0.6 m away, not
// 1.1 m away; the camera (48 deg wide, 1 m) sees the 8 lit LEDs of the one
// 0.5 m ahead and none of the one 0.6 m behind.
TEST_F(RobotModelsTest, TheEpucksBoardAndCameraSeeWhatTheyShould) {
  const std::string record =
      "for i = 0, 7 do sim.setLedOn(sim.getObject('./led[' .. i .. ']'), true) end\n"
      "sim.recordMetric('heard', #sim.readRangeAndBearing(sim.getObject('./rab')))\n"
      "sim.recordMetric('blobs', #sim.readBlobCamera(sim.getObject('./camera')))";
  LoadedWorld w = LoadRobots("planar",
                             Robot("epuck.yaml", "position: [0, 0]") +
                                 Robot("epuck.yaml", "position: [0.5, 0]") +
                                 Robot("epuck.yaml", "position: [-0.6, 0]"),
                             "", record);
  for (int i = 0; i < 3; ++i) w.world->Step();
  const std::vector<MetricSample> metrics = w.world->TakeMetrics();
  auto of = [&](const std::string& name, int robot) {
    double v = NAN;
    for (const MetricSample& m : metrics)
      if (m.name == name && m.instance == robot) v = m.value;
    return v;
  };
  EXPECT_EQ(of("heard", 0), 2);  // 0.5 m and 0.6 m
  EXPECT_EQ(of("heard", 1), 1);  // robot 0; robot 2 is 1.1 m away
  EXPECT_EQ(of("heard", 2), 1);  // robot 0
  EXPECT_EQ(of("blobs", 0), 8);  // robot 1's ring; robot 2 is behind
  EXPECT_EQ(of("blobs", 1), 0);  // it faces +x: nobody ahead
}

// The bare foot-bot has no optional device; `complete: true` has them all;
// `with_rab: true` the board only.
TEST_F(RobotModelsTest, TheFootbotsOptionalDevicesAreThereOnlyWhenAskedFor) {
  const char* devices[] = {"rab",         "base_ground[7]", "motor_ground[3]", "light[23]",
                           "omni_camera", "led[11]",        "beacon"};
  LoadedWorld bare = LoadRobots("planar", Robot("footbot.yaml", "position: [0, 0]"));
  LoadedWorld full =
      LoadRobots("planar", Robot("footbot.yaml", "position: [0, 0]", "complete: true"));
  LoadedWorld rab =
      LoadRobots("planar", Robot("footbot.yaml", "position: [0, 0]", "with_rab: true"));
  for (const char* device : devices) {
    const std::string path = std::string("/footbot#0/") + device;
    EXPECT_TRUE(bare.world->scene().FindObject(path).IsNull()) << path;
    EXPECT_FALSE(full.world->scene().FindObject(path).IsNull()) << path;
    EXPECT_EQ(rab.world->scene().FindObject(path).IsNull(), std::string(device) != "rab") << path;
  }
  // The bare one is the diffusion worlds' 29 objects (body, 2 joints, 2 wheels, 24 rays).
  EXPECT_EQ(bare.world->scene().object_count(), 29u);
  // 29 + rab + 12 ground + 24 light + camera + 12 LEDs + beacon.
  EXPECT_EQ(full.world->scene().object_count(), 29u + 1 + 12 + 24 + 1 + 12 + 1);
}

// Two complete foot-bots 2 m apart hear each other (3 m board); the
// omnidirectional camera sees a lit LED ring 0.5 m away all around, not 2 m away.
TEST_F(RobotModelsTest, TheCompleteFootbotsBoardAndCameraWork) {
  const std::string record =
      "for i = 0, 11 do sim.setLedOn(sim.getObject('./led[' .. i .. ']'), true) end\n"
      "sim.recordMetric('heard', #sim.readRangeAndBearing(sim.getObject('./rab')))\n"
      "sim.recordMetric('blobs', #sim.readBlobCamera(sim.getObject('./omni_camera')))";
  LoadedWorld w = LoadRobots("planar",
                             Robot("footbot.yaml", "position: [0, 0]", "complete: true") +
                                 Robot("footbot.yaml", "position: [0, 0.5]", "complete: true") +
                                 Robot("footbot.yaml", "position: [2.0, 0]", "complete: true"),
                             "", record);
  for (int i = 0; i < 3; ++i) w.world->Step();
  auto of = [&](const std::vector<MetricSample>& metrics, const std::string& name, int robot) {
    double v = NAN;
    for (const MetricSample& m : metrics)
      if (m.name == name && m.instance == robot) v = m.value;
    return v;
  };
  const std::vector<MetricSample> m = w.world->TakeMetrics();
  EXPECT_EQ(of(m, "heard", 0), 2);
  EXPECT_EQ(of(m, "heard", 2), 2);  // 2 m and 2.06 m: within 3 m
  EXPECT_GT(of(m, "blobs", 0), 0);  // robot 1's ring, 0.5 m away
  EXPECT_EQ(of(m, "blobs", 2), 0);  // the others are 2 m away
}

}  // namespace
}  // namespace swarmsim
