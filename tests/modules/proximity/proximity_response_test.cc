// A proximity sensor's response curve (`response:`, worlds/README.md,
// proximity_sensor): a ray facing a wall reads the curve's value at the
// distance (interpolated), the far end's when it sees nothing, less above
// the far end when the wall is seen at an angle (Lambertian), noise on the
// value within the curve's values; Lua reads it with sim.readProximityValue
// and sim.readProximityValues; bad curves are errors naming file:line.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "framework/error.h"
#include "framework/world.h"
#include "modules/proximity/proximity_sensor.h"
#include "tests/framework/error_of.h"
#include "tests/swarm/loader/world_dir_test.h"

namespace swarmsim {
namespace {

// The e-puck's curve (worlds/models/epuck.yaml).
constexpr char kCurve[] =
    "[[0, 4095], [0.005, 2133.33], [0.01, 1465.73], [0.015, 601.46], [0.02, 383.84], "
    "[0.03, 234.93], [0.04, 158.03], [0.05, 120], [0.06, 104.09], [0.07, 67.19]]";

class ProximityResponseTest : public testing::WorldDirTest {
 protected:
  // A robot at the origin with a sensor `ir` (keys `keys`) looking along
  // +x, turned by `yaw_deg`, at a wall whose face is `gap` m ahead of it
  // (x = gap), and a sensor `back` looking at nothing. Its script records
  // the Lua readers' values as metrics `ir` and `both` (the array reader's
  // two entries summed).
  LoadedWorld LoadAt(double gap, const std::string& keys, double yaw_deg = 0) {
    Write("probe.lua",
          "local ir, back, out\n"
          "function sysCall_init() ir = sim.getObject('./ir'); back = sim.getObject('./back');\n"
          "  out = {} end\n"
          "function sysCall_sensing()\n"
          "  sim.recordMetric('ir', sim.readProximityValue(ir))\n"
          "  local v = sim.readProximityValues({ir, back}, out)\n"
          "  sim.recordMetric('both', v[1] + v[2])\n"
          "end\n");
    Write("bot.yaml",
          "model: bot\nobjects:\n  name: body\n  type: dummy\n  script: probe.lua\n"
          "  children:\n"
          "    - {name: ir, type: proximity_sensor, response: " +
              std::string(kCurve) + ", " + keys + (keys.empty() ? "" : ",") +
              "\n       position: [0, 0, 0.1], orientation_deg: [0, 90, " +
              std::to_string(yaw_deg) +
              "]}\n"
              "    - {name: back, type: proximity_sensor, response: " +
              kCurve + ", position: [0, 0, 0.1], orientation_deg: [0, -90, 0]}\n");
    LoadedWorld w = Load(
        "simulation: {physics: kinematic, seed: 3}\n"
        "obstacles:\n"
        "  - {name: wall, shape: box, size: [0.2, 20, 1], position: [" +
        std::to_string(gap + 0.1) +
        ", 0, 0.5]}\n"
        "models: [{model: bot.yaml, position: [0, 0]}]\n");
    w.world->Start();
    return w;
  }
  // The value `ir` reads after one step, as the row holds it and as Lua
  // read it (checked equal), and what Lua's array reader gave for both.
  static double ValueAfterStep(LoadedWorld& w, double* both = nullptr) {
    w.world->Step();
    w.world->Step();  // the script's sensing of the second step sees the first's reading
    const std::vector<MetricSample> metrics = w.world->TakeMetrics();
    double lua = NAN, sum = NAN;
    for (const MetricSample& m : metrics) {
      if (m.name == "ir") lua = m.value;
      if (m.name == "both") sum = m.value;
    }
    if (both != nullptr) *both = sum;
    return lua;
  }
};

TEST_F(ProximityResponseTest, AWallReadsTheCurveAtItsDistance) {
  struct Case {
    double gap, value;
  };
  // Table points and midpoints (linear interpolation).
  for (const Case c :
       {Case{0.005, 2133.33}, Case{0.0125, (1465.73 + 601.46) / 2}, Case{0.02, 383.84},
        Case{0.035, (234.93 + 158.03) / 2}, Case{0.065, (104.09 + 67.19) / 2}}) {
    LoadedWorld w = LoadAt(c.gap, "");
    double both = 0;
    EXPECT_NEAR(ValueAfterStep(w, &both), c.value, 0.01) << c.gap << " m";
    // The sensor looking away reads the far end (nothing detected).
    EXPECT_NEAR(both, c.value + 67.19, 0.01) << c.gap << " m";
  }
}

TEST_F(ProximityResponseTest, NothingInRangeReadsTheFarEndAndTheRangeIsTheTablesEnd) {
  LoadedWorld w = LoadAt(0.08, "");  // beyond 0.07 m, the curve's last distance
  EXPECT_NEAR(ValueAfterStep(w), 67.19, 1e-4);
  const ProximitySensorData& ir = RowOf<ProximitySensorData>(*w.world, "/bot#0/ir");
  EXPECT_FALSE(ir.detected);
  EXPECT_DOUBLE_EQ(ir.range(), 0.07);
}

// Lambertian incidence: a wall seen 60 degrees off its normal returns half
// as much above the far end (at the distance along the ray); `none` does not.
TEST_F(ProximityResponseTest, AWallSeenAtAnAngleReadsLessAboveTheFarEnd) {
  const double along = 0.02 / std::cos(M_PI / 3);  // 0.04 m along the ray
  LoadedWorld slanted = LoadAt(0.02, "", 60);
  EXPECT_NEAR(ValueAfterStep(slanted), 67.19 + (158.03 - 67.19) * 0.5, 0.05) << along;
  LoadedWorld flat = LoadAt(0.02, "response_incidence: none", 60);
  EXPECT_NEAR(ValueAfterStep(flat), 158.03, 0.05);
}

// Noise perturbs the value (not the distance), within the curve's values.
TEST_F(ProximityResponseTest, NoiseMovesTheValueWithinTheCurve) {
  LoadedWorld w = LoadAt(0.02, "noise: 50");
  double sum = 0, sum2 = 0;
  const int n = 200;
  for (int i = 0; i < n; ++i) {
    w.world->Step();
    const ProximitySensorData& ir = RowOf<ProximitySensorData>(*w.world, "/bot#0/ir");
    ASSERT_TRUE(ir.detected);
    EXPECT_NEAR(ir.distance, 0.02, 1e-9);  // the distance is not perturbed
    EXPECT_GE(ir.value, 67.19f);
    EXPECT_LE(ir.value, 4095.f);
    sum += ir.value, sum2 += double(ir.value) * ir.value;
  }
  const double mean = sum / n, sd = std::sqrt(sum2 / n - mean * mean);
  EXPECT_NEAR(mean, 383.84, 15);
  EXPECT_NEAR(sd, 50, 10);
}

TEST_F(ProximityResponseTest, AProximityRingTakesACurve) {
  Write("ring.yaml",
        "model: ring\nobjects:\n  name: body\n  type: dummy\n  children:\n"
        "    - {type: proximity_ring, name: p, count: 4, radius: 0, height: 0.1,\n"
        "       response: [[0, 1000], [0.2, 10]]}\n");
  LoadedWorld w = Load(
      "simulation: {physics: kinematic}\n"
      "obstacles: [{shape: box, size: [0.2, 20, 1], position: [0.2, 0, 0.5]}]\n"
      "models: [{model: ring.yaml, position: [0, 0]}]\n");
  w.world->Start();
  w.world->Step();
  const ProximitySensorData& ahead = RowOf<ProximitySensorData>(*w.world, "/ring#0/p[0]");
  ASSERT_TRUE(ahead.detected);
  EXPECT_NEAR(ahead.value, 1000 + (10 - 1000) * 0.5, 0.01);  // 0.1 m: halfway
  EXPECT_DOUBLE_EQ(ahead.range(), 0.2);
}

TEST_F(ProximityResponseTest, BadCurvesAreErrorsNamingTheLine) {
  auto error = [&](const std::string& keys) {
    return ErrorOf("proximity_sensor", "  " + keys + "\n");
  };
  EXPECT_NE(error("response: [[0, 10], [0.1, 5], [0.05, 1]]").find("increase strictly"),
            std::string::npos);
  EXPECT_NE(error("response: [[0, 10]]").find("2 to 1024"), std::string::npos);
  EXPECT_NE(error("response: [[0, 10], [0.1]]").find("thing.yaml:"), std::string::npos);
  EXPECT_NE(error("response: [[-0.1, 10], [0.1, 5]]").find("non-negative"), std::string::npos);
  EXPECT_NE(error("response_incidence: none").find("needs a 'response'"), std::string::npos);
  EXPECT_NE(error("response: [[0, 10], [0.1, 5]]\n  response_incidence: cos").find("lambertian"),
            std::string::npos);
  EXPECT_EQ(error("response: [[0, 10], [0.1, 5]]"), "(no error)");
}

// A sensor without a curve has no value: the Lua reader says so, naming it.
TEST_F(ProximityResponseTest, ReadingTheValueOfASensorWithoutACurveIsAScriptError) {
  Write("s.lua",
        "function sysCall_sensing() sim.readProximityValue(sim.getObject('./plain')) end\n");
  Write("bot.yaml",
        "model: bot\nobjects:\n  name: body\n  type: dummy\n  script: s.lua\n"
        "  children: [{name: plain, type: proximity_sensor}]\n");
  LoadedWorld w =
      Load("simulation: {physics: kinematic}\nmodels: [{model: bot.yaml, position: [0, 0]}]\n");
  w.world->Start();
  const std::string message = testing::ErrorOf([&] { w.world->Step(); });
  EXPECT_CONTAINS(message,
                  "s.lua:1: sim.readProximityValue: proximity sensor /bot#0/plain has "
                  "no 'response' curve");
}

TEST_F(ProximityResponseTest, EveryKeyIsDocumented) { ExpectDocumented({"proximity_sensor"}); }

}  // namespace
}  // namespace swarmsim
