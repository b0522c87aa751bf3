// scripts/diffusion.lua on a foot-bot built in code, with proximity
// readings set by hand.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <memory>
#include <sstream>
#include <string>

#include "framework/world.h"
#include "tests/framework/fakes.h"

namespace swarmsim {
namespace {

constexpr double kWheelRadius = 0.029;  // m

std::shared_ptr<const ScriptSource> DiffusionScript() {
  std::ifstream in(std::string(SWARMSIM_SOURCE_DIR) + "/scripts/diffusion.lua");
  std::stringstream code;
  code << in.rdbuf();
  return std::make_shared<const ScriptSource>(ScriptSource{"scripts/diffusion.lua", code.str()});
}

class DiffusionTest : public ::testing::Test {
 protected:
  DiffusionTest() : registry_(testing::NullRegistry()) {
    WorldSettings settings;
    settings.physics = "null";
    world_ = std::make_unique<World>(settings, registry_);
    Scene& scene = world_->scene();
    // The foot-bot as the model has it: a root shape `body` with the script,
    // two velocity-mode wheel joints and 24 sensors `prox` counter-clockwise
    // from the front.
    body_ = scene.AddShape("body", {}, {}, {});
    JointData motor;
    motor.settings.Edit().mode = JointMode::kVelocity;
    left_ = scene.AddJoint("leftMotor", body_, {{0, 0.07, 0}, {}}, motor);
    right_ = scene.AddJoint("rightMotor", body_, {{0, -0.07, 0}, {}}, motor);
    for (int i = 0; i < 24; ++i) {
      const double angle = 2 * M_PI * i / 24;
      prox_[i] = proximity::AddSensor(&scene, "prox", body_,
                                      {{0.085 * std::cos(angle), 0.085 * std::sin(angle), 0},
                                       Quat::FromRollPitchYaw(0, M_PI / 2, angle)},
                                      {});
    }
    scene.MakeModelInstance(body_, "footbot", "footbot#0");
    scene.AttachScript(body_, DiffusionScript());
  }

  void See(int sensor, double distance) {
    ProximitySensorData& p = proximity::MutableSensor(&world_->scene(), prox_[sensor]);
    p.detected = true;
    p.distance = distance;
  }
  // Wheel targets (rad/s) after one step.
  std::pair<double, double> Step() {
    world_->Step();
    return {world_->scene().joint(left_).target_velocity,
            world_->scene().joint(right_).target_velocity};
  }

  ModuleRegistry registry_;
  std::unique_ptr<World> world_;
  ObjectId body_, left_, right_, prox_[24];
};

TEST_F(DiffusionTest, GoesStraightWhenNothingIsNear) {
  const double speed = 0.05 / kWheelRadius;
  EXPECT_EQ(Step(), std::make_pair(speed, speed));
  See(0, 0.097);  // a faint reading dead ahead stays below delta
  EXPECT_EQ(Step(), std::make_pair(speed, speed));
}

TEST_F(DiffusionTest, TurnsAwayFromObstacles) {
  const double speed = 0.05 / kWheelRadius;
  See(2, 0.05);  // 30 degrees to the left: turn right
  EXPECT_EQ(Step(), std::make_pair(speed, 0.0));
  proximity::MutableSensor(&world_->scene(), prox_[2]).detected = false;
  See(21, 0.05);  // 45 degrees to the right: turn left
  EXPECT_EQ(Step(), std::make_pair(0.0, speed));
}

TEST_F(DiffusionTest, TakesItsParametersFromTheWorld) {
  world_->parameters()["wheel_speed"] = 0.1;
  world_->parameters()["wheel_radius"] = 0.05;
  world_->parameters()["go_straight_angle_deg"] = 40.0;
  See(1, 0.099);  // 15 degrees left, faint: within the wider straight cone
  EXPECT_EQ(Step(), std::make_pair(2.0, 2.0));
}

}  // namespace
}  // namespace swarmsim
