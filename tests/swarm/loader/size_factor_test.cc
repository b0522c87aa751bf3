// Size factor (V-REP's): models placed scaled (`scale:` on a models entry)
// and rescaled at run time by sim.setObjectSizeFactor.
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

namespace swarmsim {
namespace {

namespace fs = std::filesystem;

#define EXPECT_CONTAINS(haystack, needle) \
  EXPECT_NE(std::string(haystack).find(needle), std::string::npos) << (haystack)

const std::string kFootbot = std::string(SWARMSIM_SOURCE_DIR) + "/worlds/models/footbot.yaml";

class SizeFactorTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("swarmsim_size_factor_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    RegisterBuiltinModules(&registry_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  void Write(const std::string& name, const std::string& text) {
    std::ofstream(dir_ / name) << text;
  }
  LoadedWorld Load(const std::string& world, int threads = 1) {
    Write("world.yaml", world);
    LoadOptions options;
    options.threads = threads;
    LoadedWorld loaded = LoadWorld(dir_ / "world.yaml", options, registry_);
    loaded.world->set_log_sink([this](std::string_view line) { log_.emplace_back(line); });
    return loaded;
  }
  std::string ErrorOf(const std::string& world) {
    try {
      Load(world);
    } catch (const Error& e) {
      return e.what();
    }
    return "NO ERROR";
  }
  // Two foot-bots, 5 m apart, the first at `scale_a`, the second at `scale_b`.
  std::string TwoFootbots(double scale_a, double scale_b) const {
    return "simulation: {physics: box2d, time_step: 0.1, physics_substeps: 10}\n"
           "models:\n"
           "  - {model: " +
           kFootbot + ", position: [0, 0], scale: " + std::to_string(scale_a) +
           "}\n"
           "  - {model: " +
           kFootbot + ", position: [0, 5], scale: " + std::to_string(scale_b) + "}\n";
  }
  fs::path dir_;
  ModuleRegistry registry_;
  std::vector<std::string> log_;
};

TEST_F(SizeFactorTest, ScaledFootbotHasScaledSensorsWheelsBodyAndMass) {
  LoadedWorld loaded = Load(TwoFootbots(1, 2));
  const Scene& scene = loaded.world->scene();
  const ObjectId small = scene.instance(0).root, big = scene.instance(1).root;
  EXPECT_DOUBLE_EQ(scene.size_factor(small), 1);
  EXPECT_DOUBLE_EQ(scene.size_factor(big), 2);
  // Body radius and height x 2, mass x 8.
  EXPECT_DOUBLE_EQ(scene.shape(big).size.x, 2 * scene.shape(small).size.x);
  EXPECT_DOUBLE_EQ(scene.shape(big).size.z, 2 * scene.shape(small).size.z);
  EXPECT_DOUBLE_EQ(scene.shape(big).mass, 8 * scene.shape(small).mass);
  // Wheel radius x 2; every descendant has the size factor.
  const ObjectId wheel_small = scene.FindObject("./leftMotor/leftWheel", small);
  const ObjectId wheel_big = scene.FindObject("./leftMotor/leftWheel", big);
  EXPECT_DOUBLE_EQ(scene.shape(wheel_big).size.x, 2 * scene.shape(wheel_small).size.x);
  EXPECT_DOUBLE_EQ(scene.size_factor(wheel_big), 2);
  // Sensor ranges x 2, sensor ring radius x 2.
  for (int i : {0, 7}) {
    const std::string path = "./prox[" + std::to_string(i) + "]";
    const ObjectId s_small = scene.FindObject(path, small), s_big = scene.FindObject(path, big);
    EXPECT_DOUBLE_EQ(proximity::Sensor(scene, s_big).range(),
                     2 * proximity::Sensor(scene, s_small).range());
    EXPECT_NEAR(scene.local_pose(s_big).p.Norm(), 2 * scene.local_pose(s_small).p.Norm(), 1e-12);
  }
  // Both stand on the ground: the scaled body's centre twice as high.
  EXPECT_NEAR(scene.world_pose(big).p.z, 2 * scene.world_pose(small).p.z, 1e-12);
  EXPECT_NEAR(scene.world_pose(wheel_big).p.z, scene.shape(wheel_big).size.x, 1e-12);
}

TEST_F(SizeFactorTest, ScriptsReadTheSizeFactor) {
  Write("probe.yaml",
        "model: probe\n"
        "objects: {name: body, type: shape, shape: cylinder, radius: 0.1, height: 0.1,\n"
        "          script: probe.lua}\n");
  Write("probe.lua",
        "function sysCall_init() print('sf', sim.getObjectSizeFactor(sim.getObject('.'))) end\n");
  LoadedWorld loaded = Load(
      "simulation: {physics: box2d}\n"
      "models:\n"
      "  - {model: probe.yaml, position: [0, 0], scale: 2}\n");
  loaded.world->Start();
  ASSERT_EQ(log_.size(), 1u);
  EXPECT_CONTAINS(log_[0], "sf\t2.0");
}

TEST_F(SizeFactorTest, ScaledRobotDrivesTwiceAsFarAtTheSameWheelSpeed) {
  // The diffusion controller turns wheel_speed / wheel_radius (parameters,
  // not the scaled geometry) into the same rad/s for both robots.
  LoadedWorld loaded = Load(TwoFootbots(1, 2));
  World& world = *loaded.world;
  const Scene& scene = world.scene();
  const Vec3 start_small = scene.world_pose(scene.instance(0).root).p;
  const Vec3 start_big = scene.world_pose(scene.instance(1).root).p;
  for (int i = 0; i < 50; ++i) world.Step();  // 5 s
  const double small = (scene.world_pose(scene.instance(0).root).p - start_small).Norm();
  const double big = (scene.world_pose(scene.instance(1).root).p - start_big).Norm();
  EXPECT_GT(small, 0.2);  // 0.05 m/s for 5 s, less the start
  EXPECT_NEAR(big / small, 2, 0.05);
}

TEST_F(SizeFactorTest, RuntimeRescaleTakesEffectNextStep) {
  Write("grower.yaml",
        "model: grower\n"
        "objects:\n"
        "  name: body\n"
        "  type: shape\n"
        "  shape: cylinder\n"
        "  radius: 0.1\n"
        "  height: 0.1\n"
        "  dynamic: true\n"
        "  mass: 1\n"
        "  script: grower.lua\n"
        "  children:\n"
        "    - {name: eye, type: proximity_sensor, position: [0.1, 0, 0], range: 0.2}\n");
  Write("grower.lua",
        "local steps = 0\n"
        "function sysCall_actuation()\n"
        "  steps = steps + 1\n"
        "  local me = sim.getObject('.')\n"
        "  print(steps, sim.getObjectSizeFactor(me))\n"
        "  if steps == 1 then sim.setObjectSizeFactor(me, 3) end\n"
        "end\n");
  LoadedWorld loaded = Load(
      "simulation: {physics: box2d}\n"
      "models:\n"
      "  - {model: grower.yaml, position: [0, 0]}\n");
  World& world = *loaded.world;
  const Scene& scene = world.scene();
  const ObjectId root = scene.instance(0).root;
  const ObjectId eye = scene.FindObject("./eye", root);
  const uint64_t version = scene.structure_version();
  world.Step();
  // Applied after the control phase: the script read 1, the scene now has 3.
  EXPECT_DOUBLE_EQ(scene.size_factor(root), 3);
  EXPECT_DOUBLE_EQ(scene.size_factor(eye), 3);
  EXPECT_NEAR(proximity::Sensor(scene, eye).range(), 0.6, 1e-12);
  EXPECT_NEAR(scene.shape(root).size.x, 0.3, 1e-12);
  EXPECT_NEAR(scene.shape(root).mass, 27, 1e-9);
  EXPECT_NEAR(scene.local_pose(eye).p.x, 0.3, 1e-12);
  EXPECT_GT(scene.structure_version(), version);
  world.Step();
  ASSERT_EQ(log_.size(), 2u);
  EXPECT_CONTAINS(log_[0], "1\t1.0");
  EXPECT_CONTAINS(log_[1], "2\t3.0");
}

TEST_F(SizeFactorTest, RobotsCannotRescaleOtherRobots) {
  Write("bully.yaml",
        "model: bully\n"
        "objects: {name: body, type: dummy, script: bully.lua}\n");
  Write("bully.lua",
        "function sysCall_actuation()\n"
        "  local other = sim.getObject('/bully#1', {noError = true})\n"
        "  if other ~= -1 and other ~= sim.getObject('.') then sim.setObjectSizeFactor(other, 2) "
        "end\n"
        "end\n");
  LoadedWorld loaded = Load(
      "simulation: {physics: box2d}\n"
      "models:\n"
      "  - {model: bully.yaml, position: [0, 0]}\n"
      "  - {model: bully.yaml, position: [3, 0]}\n");
  try {
    loaded.world->Step();
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_CONTAINS(e.what(), "can rescale only their own robot");
  }
}

// What a script may ask of the engines: size factors from 0.001 to 1000
// and positions within +-1e6 m (beyond, ODE aborted and Box2D asserted).
TEST_F(SizeFactorTest, ScriptsCannotRescaleOrMoveBeyondWhatTheEnginesHandle) {
  Write("mover.yaml",
        "model: mover\n"
        "objects: {name: body, type: shape, shape: cylinder, radius: 0.1, height: 0.1, "
        "dynamic: true, mass: 1, script: mover.lua}\n");
  for (const char* call : {"sim.setObjectSizeFactor(sim.getObject('.'), 1e-300)",
                           "sim.setObjectSizeFactor(sim.getObject('.'), 0/0)",
                           "sim.setObjectPosition(sim.getObject('.'), {1e9, 0, 0.1})",
                           "sim.setObjectPose(sim.getObject('.'), {0, 0, -3e38, 0, 0, 0, 1})"}) {
    Write("mover.lua", std::string("function sysCall_actuation()\n  ") + call + "\nend\n");
    LoadedWorld loaded = Load(
        "simulation: {physics: ode}\n"
        "models:\n  - {model: mover.yaml, position: [0, 0]}\n");
    try {
      loaded.world->Step();
      ADD_FAILURE() << "expected an error for " << call;
    } catch (const Error& e) {
      EXPECT_CONTAINS(e.what(), "mover.lua:2:");
      EXPECT_TRUE(std::string(e.what()).find("from 0.001 to 1000") != std::string::npos ||
                  std::string(e.what()).find("beyond +-1e6 m") != std::string::npos)
          << e.what();
    }
  }
}

TEST_F(SizeFactorTest, ScaledWorldHashIsIndependentOfThreadCount) {
  const std::string world =
      "simulation: {physics: box2d, time_step: 0.1, physics_substeps: 10, seed: 3}\n"
      "arena: {size: 6, wall_thickness: 0.1, wall_height: 0.2}\n"
      "models:\n"
      "  - model: " +
      kFootbot +
      "\n"
      "    count: 30\n"
      "    scale: 1.5\n"
      "    distribute: {region: arena, clearance: 0.02}\n";
  auto run = [&](int threads) {
    LoadedWorld loaded = Load(world, threads);
    for (int i = 0; i < 100; ++i) loaded.world->Step();
    EXPECT_DOUBLE_EQ(loaded.world->scene().size_factor(loaded.world->scene().instance(29).root),
                     1.5);
    return loaded.world->StateHash();
  };
  EXPECT_EQ(run(1), run(2));
}

TEST_F(SizeFactorTest, PlacementUsesTheScaledFootprint) {
  // A foot-bot (radius 0.085 m) fits a 0.3 m region; at scale 2 it does not.
  const std::string base =
      "simulation: {physics: box2d}\n"
      "models:\n"
      "  - model: " +
      kFootbot +
      "\n"
      "    count: 1\n"
      "    distribute: {region: {min: [0, 0], max: [0.3, 0.3]}}\n";
  EXPECT_NO_THROW(Load(base));
  const std::string message = ErrorOf(base + "    scale: 2\n");
  EXPECT_CONTAINS(message, "the region is too small");
  EXPECT_CONTAINS(message, "footprint radius 0.170");
  // Fixed copies: overlap checks use the scaled radius too.
  const std::string pair =
      "simulation: {physics: box2d}\n"
      "models:\n"
      "  - {model: " +
      kFootbot +
      ", position: [0, 0]}\n"
      "  - {model: " +
      kFootbot + ", position: [0.3, 0], scale: SCALE}\n";
  auto with = [&](const std::string& s) {
    std::string text = pair;
    text.replace(text.find("SCALE"), 5, s);
    return text;
  };
  EXPECT_NO_THROW(Load(with("1")));
  EXPECT_CONTAINS(ErrorOf(with("3")), "overlaps");
}

TEST_F(SizeFactorTest, BadScaleIsAnErrorWithItsPosition) {
  for (const char* bad : {"0", "-1", ".nan", "abc", "1e9"}) {
    const std::string message = ErrorOf(
        "simulation: {physics: box2d}\n"
        "models:\n"
        "  - model: " +
        kFootbot +
        "\n"
        "    position: [0, 0]\n"
        "    scale: " +
        std::string(bad) + "\n");
    EXPECT_CONTAINS(message, "world.yaml:5:12");
    EXPECT_CONTAINS(message, "'scale' must be");
  }
}

}  // namespace
}  // namespace swarmsim
