// Proximity sensor volumes from world files: their keys, errors, scaling,
// what scripts read, and randomized rays that read the same whatever the
// thread count (through the swarmsim program, as a user runs it).
#include <gtest/gtest.h>
#include <unistd.h>

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
#include "tests/swarm/run_program.h"

namespace swarmsim {
namespace {

namespace fs = std::filesystem;

#define EXPECT_CONTAINS(haystack, needle) \
  EXPECT_NE(std::string(haystack).find(needle), std::string::npos) << (haystack)

constexpr double kDeg = M_PI / 180;

// One robot at the origin (a dummy, `scale` given) with sensor `s`
// (`sensor`: its extra keys) looking along +x at 0.1 m height, and a wall
// 1 m ahead.
class ProximityVolumeLoaderTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("swarmsim_volume_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    RegisterBuiltinModules(&registry_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  void Write(const std::string& name, const std::string& text) {
    std::ofstream(dir_ / name) << text;
  }
  void WriteWorld(const std::string& sensor, const std::string& script = "",
                  const std::string& model_entry = "{model: bot.yaml, position: [0, 0]}") {
    Write("bot.yaml",
          "model: bot\n"
          "objects:\n"
          "  name: body\n"
          "  type: dummy\n" +
              (script.empty() ? std::string() : "  script: bot.lua\n") +
              "  children:\n"
              "    - {name: s, type: proximity_sensor, position: [0, 0, 0.1],\n"
              "       orientation_deg: [0, 90, 0], " +
              sensor + "}\n");
    if (!script.empty()) Write("bot.lua", script);
    Write("world.yaml",
          "simulation: {physics: kinematic, time_step: 0.1}\n"
          "obstacles:\n"
          "  - {name: wall, shape: box, size: [0.1, 4, 1], position: [1.05, 0, 0.5]}\n"
          "models:\n"
          "  - " +
              model_entry + "\n");
  }
  LoadedWorld Load(int threads = 1) {
    LoadOptions options;
    options.threads = threads;
    return LoadWorld(dir_ / "world.yaml", options, registry_);
  }
  std::string ErrorOf(const std::string& sensor) {
    WriteWorld(sensor);
    try {
      Load();
    } catch (const Error& e) {
      return e.what();
    }
    return "NO ERROR";
  }

  fs::path dir_;
  ModuleRegistry registry_;
};

TEST_F(ProximityVolumeLoaderTest, BadKeysAreErrorsAtTheirPosition) {
  // Line 6 of bot.yaml holds the sensor's keys, from column 24.
  struct Case {
    std::string keys, message;
  };
  const std::vector<Case> cases = {
      {"volume: cone, angle_deg: 90", "must be an angle above 0 and below 90 degrees"},
      {"volume: cone, angle_deg: -5", "must be an angle above 0 and below 90 degrees"},
      {"volume: cone, angle_deg: .nan", "angle_deg"},
      {"volume: pyramid, angle_x_deg: 95", "must be an angle above 0 and below 90 degrees"},
      {"volume: disc, angle_deg: 91", "must be an angle above 0 and up to 90 degrees"},
      {"volume: cone, cylinder_radius: 0.1", "'cylinder_radius' applies to cylinder sensors only"},
      {"angle_deg: 10", "'angle_deg' applies to cone, randomized_ray and disc sensors only"},
      {"volume: cone, range: 1, blind_zone: 1", "must be less than the range"},
      {"volume: cylinder, cylinder_radius: 0", "must be a positive number"},
      {"volume: randomized_ray, ray_count: 0", "ray_count"},
      {"volume: cone, max_detection_angle_deg: 0", "must be an angle above 0 and up to 180"},
      {"volume: cone, detect_front: false, detect_back: false", "would detect nothing"},
      {"volume: cones", "cone"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.keys);
    const std::string message = ErrorOf(c.keys);
    EXPECT_CONTAINS(message, "bot.yaml:7:");
    EXPECT_CONTAINS(message, c.message);
  }
}

TEST_F(ProximityVolumeLoaderTest, ScaleScalesLengthsNotAngles) {
  WriteWorld(
      "volume: cylinder, range: 0.5, cylinder_radius: 0.02, blind_zone: 0.1, "
      "max_detection_angle_deg: 60",
      "", "{model: bot.yaml, position: [0, 0], scale: 2}");
  LoadedWorld loaded = Load();
  const Scene& scene = loaded.world->scene();
  const ProximitySensorData& s =
      proximity::Sensor(scene, scene.FindObject("./s", scene.instance(0).root));
  EXPECT_EQ(s.volume(), ProximityVolume::kCylinder);
  EXPECT_DOUBLE_EQ(s.range(), 1.0);
  EXPECT_DOUBLE_EQ(s.settings->radius, 0.04);
  EXPECT_DOUBLE_EQ(s.settings->blind_zone, 0.2);
  EXPECT_NEAR(s.settings->max_detection_angle, 60 * kDeg, 1e-15);
}

// The wall's face is 1 m ahead (x = 1); a cone of 30 deg sees it at 1 m on
// its axis, the normal pointing back at the sensor; scripts read point,
// object and normal.
TEST_F(ProximityVolumeLoaderTest, ScriptsReadTheVolumesPointAndNormal) {
  WriteWorld("volume: cone, angle_deg: 30, range: 2",
             "function sysCall_sensing()\n"
             "  local r, d, p, o, n = sim.readProximitySensor(sim.getObject('./s'))\n"
             "  print(r, string.format('%.9f %.9f %.9f %.9f', d, p[1], p[2], p[3]),\n"
             "        sim.getObjectName(o), n[1], n[2], n[3])\n"
             "end\n");
  LoadedWorld loaded = Load();
  std::vector<std::string> log;
  loaded.world->set_log_sink([&](std::string_view line) { log.emplace_back(line); });
  loaded.world->Start();
  loaded.world->Step();
  ASSERT_FALSE(log.empty());
  EXPECT_CONTAINS(log.back(), "1\t1.000000000 0.000000000 0.000000000 1.000000000\twall\t");
  EXPECT_CONTAINS(log.back(), "\t-1.0");  // normal (0, 0, -1) in the sensor frame
}

// Randomized rays against a wall at an angle: the reading changes from step
// to step, and 20 steps hash the same on 1 and 2 threads (and a copy of the
// sensor draws its own rays).
TEST_F(ProximityVolumeLoaderTest, RandomizedRaysHashTheSameOnAnyThreadCount) {
  WriteWorld("volume: randomized_ray, angle_deg: 40, ray_count: 8, range: 3",
             "function sysCall_sensing()\n"
             "  local r, d = sim.readProximitySensor(sim.getObject('./s'))\n"
             "  print(r, d)\n"
             "end\n",
             "{model: bot.yaml, position: [0, 0]}\n"
             "  - {model: bot.yaml, position: [-0.5, 0.5], heading_deg: -20}\n"
             "  - {model: bot.yaml, position: [-0.5, -0.5], heading_deg: 30}\n"
             "  - {model: bot.yaml, position: [0.2, 1], heading_deg: -40}\n"
             "  - {model: bot.yaml, position: [0.2, -1], heading_deg: 10}\n"
             "  - {model: bot.yaml, position: [-1, 0], heading_deg: 5}");
  LoadedWorld loaded = Load();
  // Every copy has the model's sensor settings.
  const Scene& scene = loaded.world->scene();
  ASSERT_EQ(proximity::Sensors(scene).rows.size(), 6u);
  for (const ProximitySensorData& s : proximity::Sensors(scene).rows) {
    EXPECT_EQ(s.volume(), ProximityVolume::kRandomizedRay);
    EXPECT_EQ(s.settings->ray_count, 8);
    EXPECT_NEAR(s.settings->angle, 40 * kDeg, 1e-15);
  }
  std::vector<std::string> log;
  loaded.world->set_log_sink([&](std::string_view line) { log.emplace_back(line); });
  loaded.world->Start();
  for (int i = 0; i < 3; ++i) loaded.world->Step();
  ASSERT_GE(log.size(), 18u);
  EXPECT_NE(log[0], log[6]) << "the rays change from step to step";
  auto hash = [&](int threads) {
    const auto r =
        testing::RunProgram("run " + (dir_ / "world.yaml").string() +
                            " --steps 20 --quiet --hash --threads " + std::to_string(threads));
    EXPECT_EQ(r.exit_code, 0) << r.output;
    const size_t at = r.output.find("state-hash: ");
    return at == std::string::npos ? r.output : r.output.substr(at, 28);
  };
  const std::string one = hash(1);
  EXPECT_CONTAINS(one, "state-hash: ");
  EXPECT_EQ(hash(2), one);
}

}  // namespace
}  // namespace swarmsim
