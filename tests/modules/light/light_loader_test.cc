// Light sources and light sensors in world files (modules/light): their
// keys and the mistakes in them (file:line:column, exit code 2 from the
// program), the ring of light sensors, settings shared by copies, scaled
// copies, and the docs of every key.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "framework/scene.h"
#include "framework/world.h"
#include "modules/light/light.h"
#include "swarm/loader/world_loader.h"
#include "tests/framework/error_of.h"
#include "tests/swarm/loader/world_dir_test.h"
#include "tests/swarm/run_program.h"

namespace swarmsim {
namespace {

using light::LightSensorRow;
using light::LightSourceRow;
using LightLoaderTest = testing::WorldDirTest;

constexpr double kPi = 3.141592653589793;

TEST_F(LightLoaderTest, BadKeysAreFileLineColumnErrors) {
  EXPECT_CONTAINS(ErrorOf("light_source", "  intensity: -1\n"),
                  "thing.yaml:4:14: 'intensity' must be a non-negative number");
  EXPECT_CONTAINS(ErrorOf("light_source", "  intensity: bright\n"), "thing.yaml:4:14:");
  EXPECT_CONTAINS(ErrorOf("light_source", "  color: [1, 2, 0]\n"), "thing.yaml:4:");
  EXPECT_CONTAINS(ErrorOf("light_source", "  radius: 0\n"), "thing.yaml:4:11:");
  EXPECT_CONTAINS(ErrorOf("light_source", "  on: maybe\n"), "thing.yaml:4:7:");
  EXPECT_CONTAINS(ErrorOf("light_source", "  intensty: 2\n"), "did you mean 'intensity'?");
  EXPECT_CONTAINS(ErrorOf("light_sensor", "  fov_deg: 0\n"),
                  "thing.yaml:4:12: 'fov_deg' must be an angle above 0 and up to 360 degrees "
                  "(got 0)");
  EXPECT_CONTAINS(ErrorOf("light_sensor", "  fov_deg: -30\n"), "thing.yaml:4:12:");
  EXPECT_CONTAINS(ErrorOf("light_sensor", "  fov_deg: 360.5\n"), "up to 360 degrees (got 360.5)");
  EXPECT_CONTAINS(ErrorOf("light_sensor", "  failure_probability: 1.5\n"),
                  "thing.yaml:4:24: 'failure_probability' must be");
  EXPECT_CONTAINS(ErrorOf("light_sensor", "  failure_probability: -0.1\n"), "thing.yaml:4:24:");
  EXPECT_CONTAINS(ErrorOf("light_sensor", "  noise: -1\n"), "thing.yaml:4:10:");
  EXPECT_CONTAINS(ErrorOf("light_sensor", "  noise_uniform: -1\n"), "thing.yaml:4:18:");
  EXPECT_CONTAINS(ErrorOf("light_sensor", "  range: -1\n"), "thing.yaml:4:10:");
  EXPECT_CONTAINS(ErrorOf("light_sensor", "  saturation: -1\n"), "thing.yaml:4:15:");
  EXPECT_CONTAINS(ErrorOf("light_sensor", "  robot_occlusion: 2\n"), "thing.yaml:4:20:");
  EXPECT_EQ(ErrorOf("light_sensor", "  fov_deg: 360\n  failure_probability: 1\n"), "(no error)");
  EXPECT_EQ(ErrorOf("light_source", "  intensity: 0\n  on: false\n"), "(no error)");
}

TEST_F(LightLoaderTest, RingMistakesAreFileLineColumnErrors) {
  const auto ring_error = [&](const std::string& ring) {
    Write("thing.yaml", "model: thing\nobjects:\n  type: dummy\n  children:\n    - " + ring + "\n");
    try {
      Load("simulation: {physics: kinematic}\nmodels: [{model: thing.yaml, position: [0, 0]}]\n");
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string("(no error)");
  };
  EXPECT_CONTAINS(ring_error("{type: light_sensor_ring, name: l, count: 8, radius: 0.1, "
                             "fov_deg: 400}"),
                  "thing.yaml:5:");
  EXPECT_CONTAINS(ring_error("{type: light_sensor_ring, name: l, count: 0, radius: 0.1}"),
                  "thing.yaml:5:");
  EXPECT_CONTAINS(ring_error("{type: light_sensor_ring, name: l, radius: 0.1}"), "'count'");
  EXPECT_CONTAINS(ring_error("{type: light_sensor_ring, name: l, count: 8, radius: 0.1, "
                             "failure_probability: 2}"),
                  "thing.yaml:5:");
  EXPECT_CONTAINS(
      ring_error("{type: light_sensor_ring, name: l, count: 8, radius: 0.1, fov_dg: 9}"),
      "did you mean 'fov_deg'?");
  EXPECT_EQ(ring_error("{type: light_sensor_ring, name: l, count: 8, radius: 0.1, range: 2, "
                       "noise: 0.1, robot_occlusion: true}"),
            "(no error)");
}

TEST_F(LightLoaderTest, TheProgramExitsWithTwoAndNamesTheKey) {
  Write("thing.yaml", "model: thing\nobjects:\n  type: light_source\n  intensity: -3\n");
  Write("world.yaml",
        "simulation: {physics: kinematic}\nmodels: [{model: thing.yaml, position: [0, 0]}]\n");
  const auto r = testing::RunProgram("run " + (dir_ / "world.yaml").string() + " --steps 1");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_CONTAINS(r.output, "thing.yaml:4:14:");
}

// A robot with a ring of 8 light sensors round a 0.1 m body, 0.05 m up,
// and a lamp of the world 2 m ahead of the first copy.
constexpr char kBot[] = R"(model: bot
objects:
  type: dummy
  children:
    - {type: light_sensor_ring, name: light, count: 8, radius: 0.1, height: 0.05,
       fov_deg: 120, range: 5, saturation: 9, noise: 0.01, failure_probability: 0.2}
)";

TEST_F(LightLoaderTest, TheRingPlacesItsSensorsFacingOutwardsAndReadsTheirKeys) {
  Write("bot.yaml", kBot);
  LoadedWorld w = Load(R"(simulation: {physics: kinematic}
objects:
  - {name: lamp, type: light_source, position: [2, 0, 0.05], intensity: 3, on: false,
     color: [1, 0.5, 0], radius: 0.1}
models:
  - {model: bot.yaml, position: [0, 0, 0]}
  - {model: bot.yaml, position: [-3, 0, 0], scale: 2}
)");
  Scene& scene = w.world->scene();
  const LightSourceRow& lamp = RowOf<LightSourceRow>(*w.world, "/lamp");
  EXPECT_EQ(lamp.intensity, 3);
  EXPECT_FALSE(lamp.on);
  EXPECT_EQ(lamp.settings->color, (Vec3{1, 0.5, 0}));
  EXPECT_EQ(lamp.settings->radius, 0.1);
  for (int i = 0; i < 8; ++i) {
    SCOPED_TRACE(i);
    const std::string path = "/bot#0/light[" + std::to_string(i) + "]";
    const ObjectId id = scene.FindObject(path);
    ASSERT_FALSE(id.IsNull());
    const Pose& X_WS = scene.world_pose(id);
    const double a = i * kPi / 4;
    EXPECT_NEAR(X_WS.p.x, 0.1 * std::cos(a), 1e-12);
    EXPECT_NEAR(X_WS.p.y, 0.1 * std::sin(a), 1e-12);
    EXPECT_NEAR(X_WS.p.z, 0.05, 1e-12);
    // Its +x (the axis it reads along) points outwards, level.
    const Vec3 axis = X_WS.q.Rotate({1, 0, 0});
    EXPECT_NEAR(axis.x, std::cos(a), 1e-12);
    EXPECT_NEAR(axis.y, std::sin(a), 1e-12);
    EXPECT_NEAR(axis.z, 0, 1e-12);
    const LightSensorRow& s = RowOf<LightSensorRow>(*w.world, path);
    EXPECT_NEAR(s.settings->fov, 120 * kPi / 180, 1e-15);
    EXPECT_EQ(s.settings->range, 5);
    EXPECT_EQ(s.settings->saturation, 9);
    EXPECT_EQ(s.settings->noise.gaussian, 0.01);
    EXPECT_EQ(s.settings->noise.failure, 0.2);
    // The copies of one entry share one settings block; the scaled copy
    // has its own, its range doubled.
    EXPECT_TRUE(s.settings.SameAs(RowOf<LightSensorRow>(*w.world, "/bot#0/light[0]").settings));
    const LightSensorRow& big =
        RowOf<LightSensorRow>(*w.world, "/bot#1/light[" + std::to_string(i) + "]");
    EXPECT_EQ(big.settings->range, 10);
  }
  EXPECT_EQ(scene.FindObject("/bot#0/light[8]"), ObjectId{});
}

TEST_F(LightLoaderTest, ARingRobotFindsTheLampByItsSensors) {
  // The sensor facing the lamp reads most; the three facing away read 0
  // (fov 120: more than 60 deg off). No noise here.
  Write("bot.yaml", R"(model: bot
objects:
  type: dummy
  children:
    - {type: light_sensor_ring, name: light, count: 8, radius: 0.1, fov_deg: 120}
)");
  LoadedWorld w = Load(R"(simulation: {physics: kinematic}
objects:
  - {name: lamp, type: light_source, position: [0, 2, 0], intensity: 4}
models:
  - {model: bot.yaml, position: [0, 0, 0]}
)");
  w.world->Start();
  w.world->Step();
  std::vector<double> r;
  for (int i = 0; i < 8; ++i)
    r.push_back(RowOf<LightSensorRow>(*w.world, "/bot#0/light[" + std::to_string(i) + "]").reading);
  // light[2] looks along +y: the lamp 1.9 m straight ahead.
  EXPECT_NEAR(r[2], 4 / (1.9 * 1.9), 1e-12);
  for (int i = 0; i < 8; ++i)
    if (i != 2) {
      EXPECT_LT(r[i], r[2]) << i;
    }
  EXPECT_EQ(r[5], 0);
  EXPECT_EQ(r[6], 0);
  EXPECT_EQ(r[7], 0);
  EXPECT_NEAR(r[1], r[3], 1e-12);  // symmetric about +y
}

TEST_F(LightLoaderTest, EveryKeyIsDocumented) {
  ExpectDocumented({"light_source", "light_sensor"});
}

// A name no module's Lua area has is remembered as missing per Lua state
// (framework/lua_api.cc): it stays nil however often it is read, and the
// areas' own functions still resolve before and after such misses.
TEST_F(LightLoaderTest, MissingSimNamesStayNilAndAreaFunctionsStillResolve) {
  Write("bot.yaml",
        "model: bot\nobjects:\n  type: dummy\n  script: bot.lua\n  children:\n"
        "    - {name: eye, type: light_sensor}\n");
  Write("bot.lua",
        "function sysCall_init()\n"
        "  for i = 1, 3 do assert(sim.readLightSensorz == nil) end\n"
        "  assert(type(sim.readLightSensor) == 'function')\n"
        "  assert(sim.readLightSensorz == nil and sim.nothingLikeThis == nil)\n"
        "  assert(type(sim.setLightSourceOn) == 'function')\n"
        "  sim.recordMetric('ok', sim.readLightSensor(sim.getObject('./eye')) + 1)\n"
        "end\n");
  LoadedWorld w =
      Load("simulation: {physics: kinematic}\nmodels: [{model: bot.yaml, position: [0, 0]}]\n");
  w.world->Start();
  const std::vector<MetricSample> metrics = w.world->TakeMetrics();
  ASSERT_EQ(metrics.size(), 1u);
  EXPECT_EQ(metrics[0].name, "ok");
  EXPECT_EQ(metrics[0].value, 1);
}

}  // namespace
}  // namespace swarmsim
