// What Python writes into a world between steps (swarm/python/world.cc):
// joint targets, robots' poses, joint states and model parameters, each
// checked whole before anything is written, so a refused call changes nothing.
#pragma once

#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "swarm/python/arrays.h"

namespace swarmsim::python {

// A mistake in what Python passed: TypeError (not real numbers: booleans,
// complex numbers, text) or ValueError (a shape, a name, a value not finite).
class WriteError : public std::runtime_error {
 public:
  WriteError(bool type_error, const std::string& message)
      : std::runtime_error(message), type_error(type_error) {}
  bool type_error;
};

// `value` as float64 numbers (a number or an array of them); what: "'leftMotor'"
// for messages. Throws WriteError for booleans, complex numbers, text and objects.
Array RealNumbers(const py::handle& value, const std::string& what);

// Joint targets {joint name: N values or one number}, read and checked
// (names, shapes, finite values, joint modes) before any is set.
struct JointTargets {
  std::vector<size_t> columns;              // joint column in the layout
  std::vector<std::vector<double>> values;  // per column: N values
};
JointTargets ReadJointTargets(const Scene& scene, const ModelLayout& layout,
                              const py::handle& targets);
// The target velocity of velocity-mode joints, the target position of
// position-mode ones, the position of joints nothing simulates (passive).
void SetJointTargets(Scene* scene, const ModelLayout& layout, const JointTargets& targets);

// Robots' root poses: N x 3 (x, y, yaw: z and tilt kept) or N x 7 (x, y,
// z, qw, qx, qy, qz; the quaternion normalised). The dynamics backend
// teleports the bodies at the next step.
void SetPoses(World* world, const ModelLayout& layout, const py::object& poses);
// Robots' velocities: N x 6 (vx, vy, vz m/s, wx, wy, wz rad/s, world
// frame) or N x 3 (vx, vy, wz: vz, wx, wy kept), as set_poses' two forms.
// The root and every shape on it get the rigid motion; the dynamics backend
// takes them at the next step (World::SetVelocities).
void SetVelocities(World* world, const ModelLayout& layout, const py::object& velocities);
// Joint positions (what = 0) or velocities (1), N x joints, of joints
// nothing simulates (the dynamics backend's own joints are refused).
void SetJointStates(World* world, const ModelLayout& layout, int what, const py::object& values);
// A model parameter (a number or a boolean the model declares) of every
// robot: one value, or N; each within `bounds` (the model's `range`, shown
// as `range_text`, "[-0.1288, 0.1288] m/s") when it has one.
void SetParam(World* world, const ModelLayout& layout, const std::string& name,
              const py::object& values,
              const std::optional<std::pair<double, double>>& bounds = std::nullopt,
              const std::string& range_text = "");
// A model parameter of every robot, as an array (numbers, booleans as 0/1).
Array ParamArray(const World& world, const ModelLayout& layout, const std::string& name);

}  // namespace swarmsim::python
