// Actuation noise on velocity-mode joints (scene.h: JointSettings; worlds/
// README.md, Noise): slip scales the speed driven, a failing motor drives
// nothing, the noise has its configured spread, scripts keep their own
// target, and a wheeled robot under box2d and planar goes as far as the
// noisy speeds say, the same at any thread count.
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
#include "swarm/loader/world_loader.h"

namespace swarmsim {
namespace {

namespace fs = std::filesystem;

class JointNoiseTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("swarmsim_joint_noise_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    RegisterBuiltinModules(&registry_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  // A lone velocity joint turning at 1 rad/s with `keys`, kinematic: its
  // position grows by the speed driven x 0.1 s each step.
  LoadedWorld LoadJoint(const std::string& keys, const std::string& mode = "velocity") {
    std::ofstream(dir_ / "world.yaml")
        << "simulation: {physics: kinematic, time_step: 0.1, seed: 5}\n"
           "objects:\n"
           "  - {name: motor, type: joint, mode: "
        << mode << ", target_velocity: 1, " << keys << "}\n";
    return Start(dir_ / "world.yaml", 1);
  }

  LoadedWorld Start(const fs::path& world, int threads) {
    LoadOptions options;
    options.threads = threads;
    LoadedWorld loaded = LoadWorld(world, options, registry_);
    loaded.world->set_log_sink([](std::string_view) {});
    loaded.world->Start();
    return loaded;
  }

  // The joint's advance in each of `steps` steps (rad).
  static std::vector<double> Increments(LoadedWorld& w, int steps) {
    Scene& scene = w.world->scene();
    const ObjectId motor = scene.FindObject("/motor");
    std::vector<double> out;
    double last = scene.joint(motor).position;
    for (int i = 0; i < steps; ++i) {
      w.world->Step();
      const double q = scene.joint(motor).position;
      out.push_back(q - last);
      last = q;
    }
    return out;
  }

  std::string LoadError(const std::string& keys, const std::string& mode = "velocity") {
    try {
      LoadJoint(keys, mode);
    } catch (const Error& e) {
      return e.what();
    }
    return "no error";
  }

  // Two-wheeled robots (the foot-bot's wheels) whose script drives both
  // wheels at 0.05 m/s for `steps` steps under `physics`; returns how far
  // each robot's body went.
  std::vector<double> Drive(const std::string& physics, const std::string& wheel_keys, int threads,
                            int robots = 1, int steps = 100) {
    std::ofstream(dir_ / "drive.lua") << "function sysCall_init()\n"
                                         "  l = sim.getObject('./leftMotor')\n"
                                         "  r = sim.getObject('./rightMotor')\n"
                                         "end\n"
                                         "function sysCall_actuation()\n"
                                         "  sim.setJointTargetVelocity(l, 0.05 / 0.029)\n"
                                         "  sim.setJointTargetVelocity(r, 0.05 / 0.029)\n"
                                         "end\n";
    const std::string wheel =
        "      type: joint\n      joint: revolute\n      mode: velocity\n      max_force: 10\n" +
        wheel_keys + "      orientation_deg: [-90, 0, 0]\n";
    std::ofstream(dir_ / "bot.yaml")
        << "model: bot\n"
           "objects:\n"
           "  name: body\n"
           "  type: shape\n"
           "  shape: cylinder\n"
           "  radius: 0.085\n"
           "  height: 0.146\n"
           "  dynamic: true\n"
           "  mass: 1.6\n"
           "  script: drive.lua\n"
           "  children:\n"
           "    - name: leftMotor\n"
        << wheel
        << "      position: [0, 0.07, -0.044]\n"
           "      children:\n"
           "        - {name: lw, type: shape, shape: cylinder, radius: 0.029, height: 0.02}\n"
           "    - name: rightMotor\n"
        << wheel
        << "      position: [0, -0.07, -0.044]\n"
           "      children:\n"
           "        - {name: rw, type: shape, shape: cylinder, radius: 0.029, height: 0.02}\n";
    std::ofstream world(dir_ / "drive.yaml");
    world << "simulation: {physics: " << physics
          << ", time_step: 0.1, physics_substeps: 10, seed: 2}\n"
             "models:\n";
    for (int i = 0; i < robots; ++i)
      world << "  - {model: bot.yaml, position: [0, " << i << ", 0.073]}\n";
    world.close();
    LoadedWorld w = Start(dir_ / "drive.yaml", threads);
    for (int i = 0; i < steps; ++i) w.world->Step();
    std::vector<double> out;
    const Scene& scene = w.world->scene();
    for (int i = 0; i < robots; ++i) {
      const Vec3 p = scene.world_pose(scene.instance(i).root).p;
      out.push_back(std::hypot(p.x, p.y - i));
    }
    return out;
  }

  fs::path dir_;
  ModuleRegistry registry_;
};

TEST_F(JointNoiseTest, SlipScalesTheSpeedDrivenButNotTheTarget) {
  LoadedWorld w = LoadJoint("slip: 0.25");
  for (double d : Increments(w, 50)) EXPECT_NEAR(d, 0.075, 1e-12);
  const Scene& scene = w.world->scene();
  EXPECT_EQ(scene.joint(scene.FindObject("/motor")).target_velocity, 1.0);
}

TEST_F(JointNoiseTest, AFailingMotorDrivesNothingAtTheConfiguredRate) {
  LoadedWorld w = LoadJoint("velocity_failure_probability: 0.3");
  int stopped = 0;
  for (double d : Increments(w, 4000)) {
    if (std::abs(d) < 1e-12) {
      ++stopped;
    } else {
      EXPECT_NEAR(d, 0.1, 1e-12);
    }
  }
  EXPECT_NEAR(stopped, 1200, 4 * std::sqrt(4000 * 0.3 * 0.7));
}

TEST_F(JointNoiseTest, NoiseAndNoiseFactorHaveTheirConfiguredSpread) {
  for (const char* keys : {"velocity_noise: 0.2", "velocity_noise_factor: 0.2"}) {
    SCOPED_TRACE(keys);
    LoadedWorld w = LoadJoint(keys);
    const std::vector<double> d = Increments(w, 4000);
    double mean = 0, var = 0;
    for (double x : d) mean += x;
    mean /= 4000;
    for (double x : d) var += (x - mean) * (x - mean);
    const double sd = std::sqrt(var / 3999);
    // Speed 1 +- 0.2 rad/s over 0.1 s: 0.1 +- 0.02 rad a step.
    EXPECT_NEAR(mean, 0.1, 4 * 0.02 / std::sqrt(4000.0));
    EXPECT_NEAR(sd, 0.02, 0.0012);
  }
  LoadedWorld u = LoadJoint("velocity_noise_uniform: 0.5");
  for (double d : Increments(u, 500)) {
    EXPECT_GE(d, 0.05 - 1e-12);
    EXPECT_LE(d, 0.15 + 1e-12);
  }
}

TEST_F(JointNoiseTest, ARobotWithSlippingWheelsGoesThatMuchLess) {
  for (const char* physics : {"box2d", "planar"}) {
    SCOPED_TRACE(physics);
    const double clean = Drive(physics, "", 1)[0];
    EXPECT_NEAR(clean, 0.5, 0.02);  // 0.05 m/s for 10 s
    const double slipping = Drive(physics, "      slip: 0.4\n", 1)[0];
    EXPECT_NEAR(slipping / clean, 0.6, 0.02);
  }
}

TEST_F(JointNoiseTest, NoisyWheelsGiveEachRobotItsOwnPathAtAnyThreadCount) {
  const std::string keys = "      velocity_noise_factor: 0.3\n";
  const std::vector<double> one = Drive("box2d", keys, 1, 6);
  const std::vector<double> two = Drive("box2d", keys, 2, 6);
  EXPECT_EQ(one, two);
  for (size_t i = 1; i < one.size(); ++i) EXPECT_NE(one[i], one[0]) << i;
}

TEST_F(JointNoiseTest, BadActuationKeysNameTheirPlace) {
  EXPECT_NE(LoadError("slip: 1.5").find("world.yaml:3:"), std::string::npos)
      << LoadError("slip: 1.5");
  EXPECT_NE(LoadError("slip: 1.5").find("'slip' must be at most 1"), std::string::npos)
      << LoadError("slip: 1.5");
  EXPECT_NE(LoadError("velocity_noise: -1").find("'velocity_noise' must be a non-negative"),
            std::string::npos)
      << LoadError("velocity_noise: -1");
  EXPECT_NE(LoadError("slip: 0.5", "position")
                .find("'slip' is for velocity-mode joints (mode: velocity)"),
            std::string::npos)
      << LoadError("slip: 0.5", "position");
}

}  // namespace
}  // namespace swarmsim
