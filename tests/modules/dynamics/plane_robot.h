// Scenes for the planar engines' tests (box2d, planar): a differential-drive
// robot, walls and a floor, built directly in a Scene.
#pragma once

#include <cmath>
#include <string>

#include "framework/scene.h"

namespace swarmsim::plane_test {

// A differential-drive robot, e-puck/footbot-like: a cylinder body standing
// on the floor, two wheels mirror-mounted (left axis +y, right axis -y).
struct RobotSpec {
  double radius = 0.085;        // m
  double height = 0.1;          // m
  double mass = 1.6;            // kg
  double half_axle = 0.07;      // m, wheel offset from the centre line
  double wheel_radius = 0.029;  // m
};

struct Robot {
  ObjectId body, left, right;
  RobotSpec spec;
};

inline Robot AddRobot(Scene* scene, const std::string& name, double x, double y, double yaw,
                      const RobotSpec& spec = {}) {
  Robot robot;
  robot.spec = spec;
  ShapeData body;
  body.kind = ShapeKind::kCylinder;
  body.size = {spec.radius, 0, spec.height};
  body.dynamic = true;
  body.mass = spec.mass;
  robot.body = scene->AddShape(name, {}, {{x, y, spec.height / 2}, Quat::FromYaw(yaw)}, body);
  scene->MakeModelInstance(robot.body, "robot", name);
  // Joint z axis along the body's +y (left) or -y (right).
  const double wheel_z = spec.wheel_radius - spec.height / 2;
  JointData motor;
  motor.settings.Edit().type = JointType::kRevolute;
  motor.settings.Edit().mode = JointMode::kVelocity;
  robot.left = scene->AddJoint(
      "leftMotor", robot.body,
      {{0, spec.half_axle, wheel_z}, Quat::FromAxisAngle({1, 0, 0}, -M_PI / 2)}, motor);
  robot.right = scene->AddJoint(
      "rightMotor", robot.body,
      {{0, -spec.half_axle, wheel_z}, Quat::FromAxisAngle({1, 0, 0}, M_PI / 2)}, motor);
  ShapeData wheel;
  wheel.kind = ShapeKind::kCylinder;
  wheel.size = {spec.wheel_radius, 0, 0.01};
  wheel.friction = 0.7;
  scene->AddShape("leftWheel", robot.left, {}, wheel);
  scene->AddShape("rightWheel", robot.right, {}, wheel);
  return robot;
}

// Wheel surface speeds in m/s, positive forward. The right wheel's axis is
// -y, so it turns backwards (negative joint velocity) to drive forward.
inline void SetWheelSpeeds(Scene* scene, const Robot& robot, double v_left, double v_right) {
  scene->mutable_joint(robot.left).target_velocity = v_left / robot.spec.wheel_radius;
  scene->mutable_joint(robot.right).target_velocity = -v_right / robot.spec.wheel_radius;
}

// A static box standing on the floor, height 0.2 m.
inline ObjectId AddWall(Scene* scene, double x, double y, double size_x, double size_y,
                        double yaw = 0) {
  ShapeData wall;
  wall.kind = ShapeKind::kBox;
  wall.size = {size_x, size_y, 0.2};
  return scene->AddShape("wall", {}, {{x, y, 0.1}, Quat::FromYaw(yaw)}, wall);
}

// A floor slab under everything: must not be an obstacle.
inline void AddFloor(Scene* scene) {
  ShapeData floor;
  floor.kind = ShapeKind::kBox;
  floor.size = {20, 20, 0.1};
  scene->AddShape("floor", {}, {{0, 0, -0.05}, {}}, floor);
}

}  // namespace swarmsim::plane_test
