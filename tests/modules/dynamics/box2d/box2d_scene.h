// Wheeled robots, walls and a step loop on a bare Scene, for the tests that
// drive the Box2D backend directly (no World).
#pragma once

#include <cmath>
#include <functional>
#include <string>

#include "framework/dynamics_backend.h"
#include "framework/scene.h"
#include "tests/modules/dynamics/plane_robot.h"

namespace swarmsim::box2d::scene_kit {

constexpr double kDt = 0.01;   // s, one physics substep
constexpr int kSubsteps = 10;  // substeps per control step (0.1 s)

// The robot, wall and floor builders shared with the planar backend's tests.
using plane_test::AddFloor;
using plane_test::AddRobot;
using plane_test::AddWall;
using plane_test::Robot;
using plane_test::RobotSpec;
using plane_test::SetWheelSpeeds;

// Runs `seconds` of simulated time in control steps as the world would.
inline void Simulate(DynamicsBackend* backend, Scene* scene, double seconds,
                     const std::function<void()>& after_step = {}) {
  const int steps = static_cast<int>(std::lround(seconds / (kDt * kSubsteps)));
  for (int i = 0; i < steps; ++i) {
    backend->Step(scene, kDt, kSubsteps);
    scene->UpdateWorldPoses();
    if (after_step) after_step();
  }
}

inline double Yaw(const Scene& scene, ObjectId id) { return scene.world_pose(id).q.Yaw(); }
inline Vec3 Position(const Scene& scene, ObjectId id) { return scene.world_pose(id).p; }

// Wraps an angle difference into (-pi, pi].
inline double AngleDiff(double a, double b) { return std::remainder(a - b, 2 * M_PI); }

}  // namespace swarmsim::box2d::scene_kit
