#include "swarm/python/writers.h"

#include <charconv>
#include <cmath>
#include <cstdio>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "framework/error.h"
#include "framework/math.h"
#include "framework/scene.h"

namespace swarmsim::python {

namespace {

std::string ShapeText(const py::array& a) {
  std::string s = "(";
  for (py::ssize_t d = 0; d < a.ndim(); ++d) s += (d ? ", " : "") + std::to_string(a.shape(d));
  return s + (a.ndim() == 1 ? ",)" : ")");
}

const std::string& RobotName(const Scene& scene, const ModelLayout& layout, size_t i) {
  return scene.instance(layout.robots[i]).name;
}

std::string JointList(const ModelLayout& layout) {
  std::string known;
  for (const std::string& j : layout.joint_names) known += (known.empty() ? "" : ", ") + j;
  return known.empty() ? "it has none" : known;
}

// An N x columns array of real numbers, every one finite; what: "set_poses".
Array Table(const py::object& value, size_t n, std::vector<size_t> columns, const std::string& what,
            const std::string& expected) {
  Array a = RealNumbers(value, what);
  bool ok = a.ndim() == 2 && static_cast<size_t>(a.shape(0)) == n;
  if (ok) {
    ok = false;
    for (const size_t c : columns) ok = ok || static_cast<size_t>(a.shape(1)) == c;
  }
  if (!ok)
    throw WriteError(false, what + ": the array has shape " + ShapeText(a) + ", expected " +
                                expected + " (" + std::to_string(n) + " robots)");
  return a;
}

}  // namespace

Array RealNumbers(const py::handle& value, const std::string& what) {
  if (py::isinstance<py::bool_>(value))
    throw WriteError(true, what + " is a boolean, not a number");
  py::array a;
  try {
    a = py::module_::import("numpy").attr("asarray")(value);
  } catch (py::error_already_set&) {
    throw WriteError(true, what + " is not numbers");
  }
  const char kind = a.dtype().kind();
  if (kind == 'b') throw WriteError(true, what + " is booleans, not numbers (use 0.0 and 1.0)");
  if (kind == 'c')
    throw WriteError(true, what + " is complex numbers: poses, joint targets and states are real");
  if (kind != 'f' && kind != 'i' && kind != 'u')
    throw WriteError(true,
                     what + " is not numbers (dtype " + std::string(py::str(a.dtype())) + ")");
  return py::cast<Array>(a);  // a C-contiguous float64 copy when it is not one already
}

JointTargets ReadJointTargets(const Scene& scene, const ModelLayout& layout,
                              const py::handle& targets) {
  if (!py::isinstance<py::dict>(targets))
    throw WriteError(true,
                     "joint targets are a dict {joint name: array of one value per robot}, "
                     "got " +
                         std::string(py::str(py::type::of(targets).attr("__name__"))));
  const size_t n = layout.robots.size();
  const size_t joints = layout.joint_names.size();
  const auto rows = scene.joints();
  JointTargets out;
  for (const auto& [key, value] : py::reinterpret_borrow<py::dict>(targets)) {
    const std::string name = py::str(key);
    size_t column = joints;
    for (size_t j = 0; j < joints; ++j)
      if (layout.joint_names[j] == name) column = j;
    if (column == joints)
      throw WriteError(false, "model '" + layout.model + "': '" + name +
                                  "' is not one of its joints (" + JointList(layout) + ")");
    const Array values = RealNumbers(value, "'" + name + "'");
    const bool scalar =
        values.ndim() == 0 || (values.ndim() == 1 && values.shape(0) == 1 && n != 1);
    if (!scalar && (values.ndim() != 1 || static_cast<size_t>(values.shape(0)) != n))
      throw WriteError(false, "'" + name + "' has shape " + ShapeText(values) + ", expected (" +
                                  std::to_string(n) + ",): one value per robot");
    const double* v = values.data();
    std::vector<double> column_values(n);
    for (size_t i = 0; i < n; ++i) {
      const double x = scalar ? v[0] : v[i];
      if (!std::isfinite(x))
        throw WriteError(false, "'" + name + "' for robot '" + RobotName(scene, layout, i) +
                                    "' is not finite (" + std::to_string(x) + ")");
      const JointData& joint = rows[scene.row_at(layout.joint_slots[i * joints + column])];
      if (joint.mode() != JointMode::kVelocity && joint.mode() != JointMode::kPosition &&
          (joint.simulated || joint.depends()))
        throw WriteError(false, "joint '" + name + "' is in " + ToString(joint.mode()) +
                                    " mode: targets are for velocity- and position-mode joints");
      column_values[i] = x;
    }
    out.columns.push_back(column);
    out.values.push_back(std::move(column_values));
  }
  return out;
}

void SetJointTargets(Scene* scene, const ModelLayout& layout, const JointTargets& targets) {
  const size_t n = layout.robots.size();
  const size_t joints = layout.joint_names.size();
  const auto rows = scene->joints();
  for (size_t k = 0; k < targets.columns.size(); ++k)
    for (size_t i = 0; i < n; ++i) {
      JointData& joint = rows[scene->row_at(layout.joint_slots[i * joints + targets.columns[k]])];
      const double x = targets.values[k][i];
      if (joint.mode() == JointMode::kVelocity)
        joint.target_velocity = x;
      else if (joint.mode() == JointMode::kPosition)
        joint.target_position = x;
      else
        joint.JumpTo(x);
    }
}

void SetPoses(World* world, const ModelLayout& layout, const py::object& poses) {
  Scene& scene = world->scene();
  const size_t n = layout.robots.size();
  const Array a =
      Table(poses, n, {3, 7}, "set_poses", "(N, 3) x, y, yaw or (N, 7) x, y, z, qw, qx, qy, qz");
  const size_t columns = static_cast<size_t>(a.shape(1));
  const double* d = a.data();
  std::vector<Pose> out(n);
  for (size_t i = 0; i < n; ++i) {
    const double* r = d + i * columns;
    for (size_t c = 0; c < columns; ++c)
      if (!std::isfinite(r[c]))
        throw WriteError(false, "set_poses: the pose of robot '" + RobotName(scene, layout, i) +
                                    "' is not finite");
    if (std::abs(r[0]) > kMaxCoordinate || std::abs(r[1]) > kMaxCoordinate ||
        (columns == 7 && std::abs(r[2]) > kMaxCoordinate))
      throw WriteError(false, "set_poses: robot '" + RobotName(scene, layout, i) +
                                  "' would be beyond +-1e6 m, the largest coordinate a world "
                                  "may use");
    Pose X = scene.world_pose_at(layout.root_slots[i]);
    if (columns == 3) {
      // The heading replaced, the tilt kept: q = yaw' * yaw^-1 * q.
      X.p.x = r[0], X.p.y = r[1];
      const Quat& q = X.q;
      const double yaw = std::atan2(2 * (q.w * q.z + q.x * q.y), 1 - 2 * (q.y * q.y + q.z * q.z));
      X.q = (Quat::FromYaw(r[2]) * (Quat::FromYaw(-yaw) * q)).Normalized();
    } else {
      const double norm = std::sqrt(r[3] * r[3] + r[4] * r[4] + r[5] * r[5] + r[6] * r[6]);
      if (!(norm > 1e-9))
        throw WriteError(false, "set_poses: the quaternion of robot '" +
                                    RobotName(scene, layout, i) + "' is zero");
      X.p = {r[0], r[1], r[2]};
      X.q = Quat{r[3], r[4], r[5], r[6]}.Normalized();
    }
    out[i] = X;
  }
  for (size_t i = 0; i < n; ++i) scene.SetWorldPose(scene.IdAt(layout.root_slots[i]), out[i]);
}

void SetVelocities(World* world, const ModelLayout& layout, const py::object& velocities) {
  Scene& scene = world->scene();
  const size_t n = layout.robots.size();
  const Array a = Table(velocities, n, {3, 6}, "set_velocities",
                        "(N, 3) vx, vy, wz or (N, 6) vx, vy, vz, wx, wy, wz");
  const size_t columns = static_cast<size_t>(a.shape(1));
  const double* d = a.data();
  std::vector<Vec3> v(n), w(n);
  for (size_t i = 0; i < n; ++i) {
    const double* r = d + i * columns;
    for (size_t c = 0; c < columns; ++c)
      if (!std::isfinite(r[c]) || std::abs(r[c]) > kMaxCoordinate)
        throw WriteError(false, "set_velocities: the velocity of robot '" +
                                    RobotName(scene, layout, i) +
                                    "' is not a finite number within +-1e6 (m/s, rad/s)");
    const uint32_t root = layout.root_slots[i];
    if (columns == 3) {
      // vx, vy and the turn about z set; the rest kept.
      v[i] = scene.linear_velocity_at(root), w[i] = scene.angular_velocity_at(root);
      v[i].x = r[0], v[i].y = r[1], w[i].z = r[2];
    } else {
      v[i] = {r[0], r[1], r[2]};
      w[i] = {r[3], r[4], r[5]};
    }
  }
  world->SetVelocities(layout.robots, v, w);
}

void SetJointStates(World* world, const ModelLayout& layout, int what, const py::object& values) {
  Scene& scene = world->scene();
  const size_t n = layout.robots.size(), joints = layout.joint_names.size();
  const std::string call = what == 0 ? "set_joint_positions" : "set_joint_velocities";
  const Array a = Table(
      values, n, {joints}, call,
      "(N, " + std::to_string(joints) + "): one column per joint (" + JointList(layout) + ")");
  const double* d = a.data();
  const auto rows = scene.joints();
  for (size_t k = 0; k < n * joints; ++k) {
    const JointData& joint = rows[scene.row_at(layout.joint_slots[k])];
    const std::string& name = layout.joint_names[k % joints];
    if (!std::isfinite(d[k]))
      throw WriteError(false, call + ": joint '" + name + "' of robot '" +
                                  RobotName(scene, layout, k / joints) + "' is not finite");
    if (joint.simulated || joint.depends())
      throw WriteError(false, call + ": joint '" + name + "' is " +
                                  (joint.depends() ? "a dependent joint (its master moves it)"
                                                   : "simulated by the dynamics backend") +
                                  ": its state cannot be written");
  }
  for (size_t k = 0; k < n * joints; ++k) {
    JointData& joint = rows[scene.row_at(layout.joint_slots[k])];
    if (what == 0) {
      // Jump there (a position-mode joint's target with it, so it stays).
      const double v = joint.velocity;
      joint.JumpTo(d[k]);
      if (joint.mode() == JointMode::kVelocity) joint.velocity = v;
    } else {
      joint.velocity = d[k];
    }
  }
  if (what == 0)
    for (const int robot : layout.robots) scene.UpdateWorldPoses(robot);
}

void SetParam(World* world, const ModelLayout& layout, const std::string& name,
              const py::object& values, const std::optional<std::pair<double, double>>& bounds,
              const std::string& range_text) {
  const size_t n = layout.robots.size();
  const Array a = RealNumbers(values, "set_param('" + name + "')");
  const bool scalar = a.ndim() == 0 || (a.ndim() == 1 && a.shape(0) == 1 && n != 1);
  if (!scalar && (a.ndim() != 1 || static_cast<size_t>(a.shape(0)) != n))
    throw WriteError(false, "set_param('" + name + "'): the values have shape " + ShapeText(a) +
                                ", expected one number or (" + std::to_string(n) +
                                ",): one value per robot");
  const double* v = a.data();
  std::vector<ParamValue> next(n);
  for (size_t i = 0; i < n; ++i) {
    const int robot = layout.robots[i];
    const RobotRuntime& rt = world->runtime(robot);
    const ParamValue* old = nullptr;
    if (rt.parameters)
      if (auto it = rt.parameters->find(name); it != rt.parameters->end()) old = &it->second;
    if (old == nullptr) {
      std::string known;
      if (rt.parameters)
        for (const auto& [k, value] : *rt.parameters) known += (known.empty() ? "" : ", ") + k;
      throw WriteError(false, "set_param: model '" + layout.model + "' has no parameter '" + name +
                                  "' (" + (known.empty() ? "it has none" : known) + ")");
    }
    const double x = scalar ? v[0] : v[i];
    if (!std::isfinite(x))
      throw WriteError(false, "set_param('" + name + "'): the value for robot '" +
                                  RobotName(world->scene(), layout, i) + "' is not finite");
    if (bounds && !(x >= bounds->first && x <= bounds->second)) {
      char got[32];  // the shortest text that reads back as x (0.2, not 0.20000000000000001)
      *std::to_chars(got, got + sizeof got - 1, x).ptr = '\0';
      throw WriteError(false, "set_param('" + name + "'): parameter '" + name + "' of model '" +
                                  layout.model + "' must be within " + range_text + " (got " + got +
                                  " for robot '" + RobotName(world->scene(), layout, i) + "')");
    }
    if (std::holds_alternative<double>(*old)) {
      next[i] = x;
    } else if (std::holds_alternative<bool>(*old)) {
      if (x != 0 && x != 1)
        throw WriteError(
            false, "set_param('" + name + "') is a boolean: 0 or 1, got " + std::to_string(x));
      next[i] = x != 0;
    } else {
      throw WriteError(true, "set_param('" + name +
                                 "') is text: only numbers and booleans are "
                                 "set from arrays");
    }
  }
  // Robots that shared one set and get one value share the new one.
  std::map<const ParameterSet*, SharedParameters> made;
  for (size_t i = 0; i < n; ++i) {
    const int robot = layout.robots[i];
    const SharedParameters& old = world->runtime(robot).parameters;
    SharedParameters& mine = made[scalar ? old.get() : nullptr];
    if (!scalar || !mine) {
      auto copy = std::make_shared<ParameterSet>(*old);
      (*copy)[name] = next[i];
      mine = std::move(copy);
    }
    world->WriteInstanceParameters(robot, mine);  // hashed and saved from now on
  }
}

Array ParamArray(const World& world, const ModelLayout& layout, const std::string& name) {
  Array a(static_cast<py::ssize_t>(layout.robots.size()));
  double* d = a.mutable_data();
  for (size_t i = 0; i < layout.robots.size(); ++i) {
    const ParamValue* v = world.FindParameter(layout.robots[i], name);
    if (v == nullptr) throw py::key_error("no parameter '" + name + "'");
    if (const double* x = std::get_if<double>(v))
      d[i] = *x;
    else if (const bool* b = std::get_if<bool>(v))
      d[i] = *b ? 1 : 0;
    else
      throw py::type_error("parameter '" + name + "' is not a number");
  }
  return a;
}

}  // namespace swarmsim::python
