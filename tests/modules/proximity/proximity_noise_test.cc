// Noise on proximity sensors (worlds/README.md, Noise): a ray facing a wall
// at a known distance reads that distance with the configured Gaussian or
// uniform noise, loses its detection at the configured rate, never detects
// what is not there, and reads the same draws at any thread count.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "framework/error.h"
#include "framework/registry.h"
#include "framework/world.h"
#include "modules/builtin.h"
#include "modules/proximity/proximity_sensor.h"
#include "swarm/loader/world_loader.h"

namespace swarmsim {
namespace {

namespace fs = std::filesystem;

class ProximityNoiseTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("swarmsim_prox_noise_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    RegisterBuiltinModules(&registry_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  // A robot at the origin whose sensor `ahead` (keys `keys`) looks along +x
  // at a wall whose face is 0.3 m away, and whose sensor `behind` (same
  // keys) looks along -x at nothing. `robots` such robots, 2 m apart in y.
  LoadedWorld Load(const std::string& keys, int threads = 1, int robots = 1) {
    std::ofstream(dir_ / "bot.yaml")
        << "model: bot\n"
           "objects:\n"
           "  name: body\n"
           "  type: dummy\n"
           "  children:\n"
           "    - {name: ahead, type: proximity_sensor, range: 0.5, "
        << keys
        << "\n"
           "       position: [0, 0, 0.1], orientation_deg: [0, 90, 0]}\n"
           "    - {name: behind, type: proximity_sensor, range: 0.5, "
        << keys
        << "\n"
           "       position: [0, 0, 0.1], orientation_deg: [0, -90, 0]}\n";
    std::ofstream world(dir_ / "world.yaml");
    world << "simulation: {physics: kinematic, time_step: 0.1, seed: 3}\n"
             "obstacles:\n"
             "  - {name: wall, shape: box, size: [0.1, 200, 1], position: [0.35, 0, 0.5]}\n"
             "models:\n";
    for (int i = 0; i < robots; ++i)
      world << "  - {model: bot.yaml, position: [0, " << 2 * i << "]}\n";
    world.close();
    LoadOptions options;
    options.threads = threads;
    LoadedWorld loaded = LoadWorld(dir_ / "world.yaml", options, registry_);
    loaded.world->set_log_sink([](std::string_view) {});
    loaded.world->Start();
    return loaded;
  }

  // Steps `steps` times; the distances `ahead` of robot `robot` read (NaN
  // when it detected nothing), and checks that `behind` never detects.
  static std::vector<double> Readings(LoadedWorld& loaded, int steps, int robot = 0) {
    Scene& scene = loaded.world->scene();
    const ObjectId root = scene.instance(robot).root;
    const ObjectId ahead = scene.FindObject("./ahead", root);
    const ObjectId behind = scene.FindObject("./behind", root);
    std::vector<double> out;
    for (int i = 0; i < steps; ++i) {
      loaded.world->Step();
      const ProximitySensorData& a = proximity::Sensor(scene, ahead);
      out.push_back(a.detected ? a.distance : NAN);
      EXPECT_FALSE(proximity::Sensor(scene, behind).detected) << "step " << i;
    }
    return out;
  }

  std::string LoadError(const std::string& keys) {
    try {
      Load(keys);
    } catch (const Error& e) {
      return e.what();
    }
    return "no error";
  }

  fs::path dir_;
  ModuleRegistry registry_;
};

struct Stats {
  double mean = 0, sd = 0, min = INFINITY, max = -INFINITY;
  int n = 0;
};
Stats Of(const std::vector<double>& v) {
  Stats s;
  for (double x : v)
    if (!std::isnan(x)) s.mean += x, ++s.n, s.min = std::min(s.min, x), s.max = std::max(s.max, x);
  s.mean /= s.n;
  for (double x : v)
    if (!std::isnan(x)) s.sd += (x - s.mean) * (x - s.mean);
  s.sd = std::sqrt(s.sd / (s.n - 1));
  return s;
}

TEST_F(ProximityNoiseTest, WithoutNoiseTheDistanceIsExact) {
  LoadedWorld w = Load("");
  for (double d : Readings(w, 20)) EXPECT_NEAR(d, 0.3, 1e-12);
}

TEST_F(ProximityNoiseTest, GaussianNoiseHasTheConfiguredMeanAndSpread) {
  LoadedWorld w = Load("noise: 0.01,");
  const std::vector<double> d = Readings(w, 4000);
  const Stats s = Of(d);
  ASSERT_EQ(s.n, 4000);
  // Mean within 4 standard errors; std dev within 6% (its own standard
  // error is 1.1%); 68.3% within one sigma, 95.4% within two.
  EXPECT_NEAR(s.mean, 0.3, 4 * 0.01 / std::sqrt(4000.0));
  EXPECT_NEAR(s.sd, 0.01, 0.0006);
  int one = 0, two = 0;
  for (double x : d) one += std::abs(x - 0.3) < 0.01, two += std::abs(x - 0.3) < 0.02;
  EXPECT_NEAR(one / 4000.0, 0.6827, 4 * std::sqrt(0.6827 * 0.3173 / 4000));
  EXPECT_NEAR(two / 4000.0, 0.9545, 4 * std::sqrt(0.9545 * 0.0455 / 4000));
  // Successive steps draw anew.
  EXPECT_NE(d[0], d[1]);
}

TEST_F(ProximityNoiseTest, UniformNoiseStaysInItsBandWithItsVariance) {
  LoadedWorld w = Load("noise_uniform: 0.02,");
  const Stats s = Of(Readings(w, 4000));
  ASSERT_EQ(s.n, 4000);
  EXPECT_GE(s.min, 0.28);
  EXPECT_LE(s.max, 0.32);
  EXPECT_LT(s.min, 0.281);  // the band is filled to its edges
  EXPECT_GT(s.max, 0.319);
  EXPECT_NEAR(s.sd, 0.02 / std::sqrt(3.0), 0.0007);
  EXPECT_NEAR(s.mean, 0.3, 4 * 0.0115 / std::sqrt(4000.0));
}

TEST_F(ProximityNoiseTest, NoisyDistancesStayWithinTheRange) {
  // The wall is 0.3 m away, the range 0.5 m: 0.2 m of noise must clamp at
  // 0 and 0.5, never beyond.
  LoadedWorld w = Load("noise: 0.2,");
  const Stats s = Of(Readings(w, 2000));
  EXPECT_GE(s.min, 0.0);
  EXPECT_LE(s.max, 0.5);
  EXPECT_EQ(s.max, 0.5);  // some draws are clamped
}

TEST_F(ProximityNoiseTest, AFailingSensorLosesDetectionsAtTheConfiguredRate) {
  LoadedWorld w = Load("failure_probability: 0.25,");
  const std::vector<double> d = Readings(w, 4000);
  const Stats s = Of(d);
  // Detected in 75% of steps, within 4 binomial standard deviations; the
  // detections themselves are exact.
  EXPECT_NEAR(s.n, 3000, 4 * std::sqrt(4000 * 0.25 * 0.75));
  EXPECT_NEAR(s.min, 0.3, 1e-12);
  EXPECT_NEAR(s.max, 0.3, 1e-12);
}

// 300 robots: more than one task's share (the sense phase hands out 64
// robots a task), so two threads really split them.
TEST_F(ProximityNoiseTest, TheDrawsAreTheSameAtAnyThreadCountAndDifferPerSensor) {
  LoadedWorld one = Load("noise: 0.01,", 1, 300);
  const std::vector<double> a0 = Readings(one, 50, 0), a7 = Readings(one, 50, 7);
  LoadedWorld two = Load("noise: 0.01,", 2, 300);
  const std::vector<double> b0 = Readings(two, 50, 0), b7 = Readings(two, 50, 7);
  EXPECT_EQ(a0, b0);
  EXPECT_EQ(a7, b7);
  EXPECT_NE(a0, a7);  // two sensors at the same distance draw their own noise
}

TEST_F(ProximityNoiseTest, BadNoiseKeysNameTheirPlace) {
  EXPECT_NE(LoadError("noise: -0.01,").find("bot.yaml:6:"), std::string::npos)
      << LoadError("noise: -0.01,");
  EXPECT_NE(LoadError("noise: -0.01,").find("'noise' must be a non-negative number"),
            std::string::npos)
      << LoadError("noise: -0.01,");
  EXPECT_NE(LoadError("failure_probability: 1.5,")
                .find("bot.yaml:6:78: 'failure_probability' must be at most 1"),
            std::string::npos)
      << LoadError("failure_probability: 1.5,");
}

}  // namespace
}  // namespace swarmsim
