#include "swarm/python/arrays.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "framework/error.h"
#include "framework/scene.h"
#include "framework/scheduler.h"
#include "modules/ground_sensor/ground_sensor.h"
#include "modules/light/light.h"
#include "modules/proximity/proximity_sensor.h"
#include "modules/range_and_bearing/range_and_bearing.h"

namespace swarmsim::python {

namespace {
ObjectType TypeNamed(const Scene& scene, const char* name) {
  ObjectType type;
  if (!scene.FindType(name, &type)) throw InternalError(std::string("no type ") + name);
  return type;
}
}  // namespace

// Names that repeat within a robot (a proximity ring's `prox`) get the index
// scripts use: prox[0], prox[1], ...
void IndexRepeats(std::vector<std::string>* names) {
  std::map<std::string, int> count, seen;
  for (const std::string& n : *names) ++count[n];
  for (std::string& n : *names)
    if (count[n] > 1) {
      const int k = seen[n]++;
      n += '[';
      n += std::to_string(k);
      n += ']';
    }
}

// Rebuilds `layout` for `model` ("" : every robot) if robots came or went.
void Refresh(const World& world, const std::string& model, ModelLayout* layout) {
  // Unchanged unless robots were copied (more instances) or removed (a
  // root's slot freed): a check of N bytes, not a walk of the instances.
  if (layout->robot_count == world.robot_count() && layout->model == model &&
      std::all_of(layout->root_slots.begin(), layout->root_slots.end(),
                  [&](uint32_t slot) { return world.scene().alive_at(slot); }))
    return;
  const Scene& scene = world.scene();
  const ObjectType joint = TypeNamed(scene, "joint");
  // Without the proximity module's type no object matches `sensor`.
  ObjectType sensor = static_cast<ObjectType>(kMaxObjectTypes);
  proximity::FindSensorType(scene, &sensor);
  ObjectType board = static_cast<ObjectType>(kMaxObjectTypes);
  scene.FindType(range_and_bearing::kTypeName, &board);
  ObjectType ground = static_cast<ObjectType>(kMaxObjectTypes);
  ground_sensor::FindSensorType(scene, &ground);
  ObjectType light_sensor = static_cast<ObjectType>(kMaxObjectTypes);
  light::FindSensorType(scene, &light_sensor);
  *layout = ModelLayout{};
  layout->model = model;
  const auto instances = scene.instances();
  bool first = true;
  for (size_t i = 0; i < instances.size(); ++i) {
    const ModelInstance& inst = instances[i];
    if (!inst.alive || (!model.empty() && inst.model_name != model)) continue;
    std::vector<std::string> joints, sensors, grounds, lights;
    std::vector<uint32_t> joint_slots, sensor_slots, ground_slots, light_slots;
    uint32_t board_slot = ModelLayout::kNoBoard;
    for (const uint32_t slot : inst.objects) {
      if (scene.type_at(slot) == board && board_slot == ModelLayout::kNoBoard) board_slot = slot;
      if (scene.type_at(slot) == joint) {
        joints.push_back(scene.name_at(slot));
        joint_slots.push_back(slot);
      } else if (scene.type_at(slot) == sensor) {
        sensors.push_back(scene.name_at(slot));
        sensor_slots.push_back(slot);
      } else if (scene.type_at(slot) == ground) {
        grounds.push_back(scene.name_at(slot));
        ground_slots.push_back(slot);
      } else if (scene.type_at(slot) == light_sensor) {
        lights.push_back(scene.name_at(slot));
        light_slots.push_back(slot);
      }
    }
    IndexRepeats(&joints);
    IndexRepeats(&sensors);
    IndexRepeats(&grounds);
    IndexRepeats(&lights);
    if (first) {
      layout->joint_names = joints;
      layout->sensor_names = sensors;
      layout->ground_names = grounds;
      layout->light_names = lights;
      first = false;
    } else if (joints != layout->joint_names || sensors != layout->sensor_names ||
               grounds != layout->ground_names || lights != layout->light_names) {
      if (!model.empty())
        throw Error("robot '" + inst.name + "' of model '" + model +
                    "' has other joints or sensors than the first copy: arrays need one layout");
      // Mixed models: arrays over every robot have no common columns.
      layout->joint_names.clear();
      layout->sensor_names.clear();
      layout->ground_names.clear();
      joint_slots.clear();
      sensor_slots.clear();
      ground_slots.clear();
      layout->joint_slots.clear();
      layout->sensor_slots.clear();
      layout->ground_slots.clear();
      layout->light_names.clear();
      light_slots.clear();
      layout->light_slots.clear();
    }
    layout->robots.push_back(static_cast<int>(i));
    layout->root_slots.push_back(scene.SlotOf(inst.root));
    layout->board_slots.push_back(board_slot);
    if (layout->joint_names.size() == joint_slots.size())
      layout->joint_slots.insert(layout->joint_slots.end(), joint_slots.begin(), joint_slots.end());
    if (layout->sensor_names.size() == sensor_slots.size())
      layout->sensor_slots.insert(layout->sensor_slots.end(), sensor_slots.begin(),
                                  sensor_slots.end());
    if (layout->ground_names.size() == ground_slots.size())
      layout->ground_slots.insert(layout->ground_slots.end(), ground_slots.begin(),
                                  ground_slots.end());
    if (layout->light_names.size() == light_slots.size())
      layout->light_slots.insert(layout->light_slots.end(), light_slots.begin(), light_slots.end());
  }
  const size_t n = layout->robots.size();
  if (layout->joint_slots.size() != n * layout->joint_names.size()) {
    layout->joint_names.clear();
    layout->joint_slots.clear();
  }
  if (layout->sensor_slots.size() != n * layout->sensor_names.size()) {
    layout->sensor_names.clear();
    layout->sensor_slots.clear();
  }
  if (layout->ground_slots.size() != n * layout->ground_names.size()) {
    layout->ground_names.clear();
    layout->ground_slots.clear();
  }
  if (layout->light_slots.size() != n * layout->light_names.size()) {
    layout->light_names.clear();
    layout->light_slots.clear();
  }
  layout->robot_count = world.robot_count();
}

// An output array of `shape`: `out` if it is one (float64, C-contiguous,
// writeable, that shape), else a new one.
void CheckOut(const py::object& out, const py::dtype& dtype,
              const std::vector<py::ssize_t>& shape) {
  if (!py::isinstance<py::array>(out)) throw py::value_error("out= must be a numpy array");
  static const py::handle ndarray =
      py::object(py::module_::import("numpy").attr("ndarray")).release();
  if (!py::type::of(out).is(ndarray))
    throw py::value_error("out= must be a plain numpy.ndarray, not a " +
                          std::string(py::str(py::type::of(out).attr("__name__"))) +
                          " (what it adds, such as a mask, would be ignored)");
  auto a = py::reinterpret_borrow<py::array>(out);
  if (!a.dtype().is(dtype))
    throw py::value_error("out= must have dtype " + std::string(py::str(py::object(dtype))) +
                          ", got " + std::string(py::str(a.dtype())));
  if (!(a.flags() & py::array::c_style) || !a.writeable())
    throw py::value_error("out= must be a writeable C-contiguous array");
  if (a.ndim() != static_cast<py::ssize_t>(shape.size()) ||
      !std::equal(shape.begin(), shape.end(), a.shape())) {
    const auto text = [](const py::ssize_t* begin, const py::ssize_t* end) {
      std::string t = "(";
      for (const py::ssize_t* d = begin; d != end; ++d)
        t += (d == begin ? "" : ", ") + std::to_string(*d);
      return t + (end - begin == 1 ? ",)" : ")");
    };
    throw py::value_error("out= has shape " + text(a.shape(), a.shape() + a.ndim()) +
                          ", expected " + text(shape.data(), shape.data() + shape.size()));
  }
}

Array OutArray(std::vector<py::ssize_t> shape, const py::object& out) {
  if (out.is_none()) return Array(shape);
  CheckOut(out, py::dtype::of<double>(), shape);
  return py::reinterpret_borrow<Array>(out);
}

namespace {
// atan2 without libm's cost (~20 ns, most of reading 10,000 poses): Cephes's
// atan (Moshier; relative error ~2e-16), branch-light. The heading a planar
// pose reports, so within an ulp or two of std::atan2.
double Atan(double x) {
  constexpr double P[] = {-8.750608600031904122785E-1, -1.615753718733365076637E1,
                          -7.500855792314704667340E1, -1.228866684490136173410E2,
                          -6.485021904942025371773E1};
  constexpr double Q[] = {2.485846490142306297962E1, 1.650270098316988542046E2,
                          4.328810604912902668951E2, 4.853903996359136964868E2,
                          1.945506571482613964425E2};
  constexpr double kMoreBits = 6.123233995736765886130E-17;
  constexpr double kTan3Pi8 = 2.41421356237309504880;
  const double sign = x < 0 ? -1 : 1;
  x = std::fabs(x);
  double base = 0, extra = 0;
  if (x > kTan3Pi8) {
    base = M_PI_2, extra = kMoreBits, x = -1 / x;
  } else if (x > 0.66) {
    base = M_PI_4, extra = 0.5 * kMoreBits, x = (x - 1) / (x + 1);
  }
  const double z = x * x;
  const double p = (((P[0] * z + P[1]) * z + P[2]) * z + P[3]) * z + P[4];
  const double q = ((((z + Q[0]) * z + Q[1]) * z + Q[2]) * z + Q[3]) * z + Q[4];
  return sign * (base + (x * (z * p / q) + x + extra));
}
}  // namespace

namespace {
double Atan2(double y, double x) {
  if (x == 0) return y > 0 ? M_PI_2 : (y < 0 ? -M_PI_2 : 0);
  const double a = Atan(y / x);
  if (x > 0) return a;
  return std::signbit(y) ? a - M_PI : a + M_PI;
}
}  // namespace

namespace {
double Yaw(const Quat& q) {
  return Atan2(2 * (q.w * q.z + q.x * q.y), 1 - 2 * (q.y * q.y + q.z * q.z));
}
}  // namespace

// Poses of the layout's robots' roots: N x 3 (x, y, yaw) or N x 7 (x, y, z,
// qw, qx, qy, qz).
Array Poses(World& world, const ModelLayout& layout, bool planar, const py::object& out) {
  const auto n = static_cast<int64_t>(layout.robots.size());
  const int columns = planar ? 3 : 7;
  Array a = OutArray({static_cast<py::ssize_t>(n), columns}, out);
  double* const data = a.mutable_data();
  const Scene& scene = world.scene();
  const uint32_t* roots = layout.root_slots.data();
  // Roots lie a robot's worth of slots apart: fetch a few ahead.
  auto gather = [&](int64_t begin, int64_t end) {
    double* d = data + begin * columns;
    for (int64_t i = begin; i < end; ++i, d += columns) {
      if (i + 8 < end) __builtin_prefetch(&scene.world_pose_at(roots[i + 8]));
      const Pose& X = scene.world_pose_at(roots[i]);
      if (planar) {
        d[0] = X.p.x, d[1] = X.p.y, d[2] = Yaw(X.q);
      } else {
        d[0] = X.p.x, d[1] = X.p.y, d[2] = X.p.z;
        d[3] = X.q.w, d[4] = X.q.x, d[5] = X.q.y, d[6] = X.q.z;
      }
    }
  };
  world.scheduler().ParallelFor(0, n, 2048, gather);
  return a;
}

Array Velocities(const Scene& scene, const ModelLayout& layout, const py::object& out) {
  const auto n = static_cast<py::ssize_t>(layout.robots.size());
  Array a = OutArray({n, 6}, out);
  double* d = a.mutable_data();
  for (py::ssize_t i = 0; i < n; ++i, d += 6) {
    const Vec3& v = scene.linear_velocity_at(layout.root_slots[i]);
    const Vec3& w = scene.angular_velocity_at(layout.root_slots[i]);
    d[0] = v.x, d[1] = v.y, d[2] = v.z, d[3] = w.x, d[4] = w.y, d[5] = w.z;
  }
  return a;
}

// Proximity readings, N x sensors: the distance to what each sensor sees,
// +inf where it sees nothing.
Array Proximity(const Scene& scene, const ModelLayout& layout, const py::object& out) {
  const auto n = static_cast<py::ssize_t>(layout.robots.size());
  const auto s = static_cast<py::ssize_t>(layout.sensor_names.size());
  Array a = OutArray({n, s}, out);
  double* d = a.mutable_data();
  const std::span<const ProximitySensorData> rows = proximity::Sensors(scene).rows;
  for (size_t k = 0; k < layout.sensor_slots.size(); ++k) {
    const ProximitySensorData& p = rows[scene.row_at(layout.sensor_slots[k])];
    d[k] = p.detected ? p.distance : std::numeric_limits<double>::infinity();
  }
  return a;
}

Array ProximityValues(const Scene& scene, const ModelLayout& layout, const py::object& out) {
  const auto n = static_cast<py::ssize_t>(layout.robots.size());
  const auto s = static_cast<py::ssize_t>(layout.sensor_names.size());
  Array a = OutArray({n, s}, out);
  double* d = a.mutable_data();
  const std::span<const ProximitySensorData> rows = proximity::Sensors(scene).rows;
  for (size_t k = 0; k < layout.sensor_slots.size(); ++k) {
    const ProximitySensorData& p = rows[scene.row_at(layout.sensor_slots[k])];
    const ProximitySensorSettings& settings = *p.settings;
    d[k] = !settings.has_response() ? std::numeric_limits<double>::quiet_NaN()
           : p.detected             ? static_cast<double>(p.value)
                                    : settings.response.back().second;
  }
  return a;
}

py::dict RangeAndBearing(const Scene& scene, const ModelLayout& layout) {
  using range_and_bearing::RangeAndBearingRow;
  const size_t n = layout.robots.size();
  ObjectType type;
  const RangeAndBearingRow* rows = nullptr;
  if (scene.FindType(range_and_bearing::kTypeName, &type))
    rows = scene.rows<RangeAndBearingRow>(type).rows.data();
  const auto board = [&](size_t i) -> const RangeAndBearingRow* {
    const uint32_t slot = layout.board_slots[i];
    return slot == ModelLayout::kNoBoard || rows == nullptr ? nullptr : &rows[scene.row_at(slot)];
  };
  // A model none of whose robots has a board is a mistake, as for IR
  // messages and set_range_and_bearing_data (robots without one among
  // others just hear nothing).
  bool any_board = false;
  for (size_t i = 0; i < n && !any_board; ++i) any_board = board(i) != nullptr;
  if (n > 0 && !any_board)
    throw py::value_error(
        "the robots have no range-and-bearing board (worlds/README.md, "
        "\"range_and_bearing\")");
  size_t m = 0, width = 0;
  for (size_t i = 0; i < n; ++i)
    if (const RangeAndBearingRow* b = board(i)) {
      m += b->readings.size();
      for (const auto& r : b->readings) width = std::max<size_t>(width, r.data_size);
    }
  const auto sm = static_cast<py::ssize_t>(m), sw = static_cast<py::ssize_t>(width);
  py::array_t<int64_t> offsets(static_cast<py::ssize_t>(n + 1)), sender(sm);
  Array range(sm), bearing(sm), elevation(sm);
  py::array_t<uint8_t> data({sm, sw});
  int64_t* o = offsets.mutable_data();
  int64_t* who = sender.mutable_data();
  double *ra = range.mutable_data(), *be = bearing.mutable_data(), *el = elevation.mutable_data();
  uint8_t* bytes = data.mutable_data();
  if (m > 0) std::fill(bytes, bytes + m * width, uint8_t{0});
  size_t k = 0;
  for (size_t i = 0; i < n; ++i) {
    o[i] = static_cast<int64_t>(k);
    const RangeAndBearingRow* b = board(i);
    if (b == nullptr) continue;
    for (const auto& r : b->readings) {
      ra[k] = r.range, be[k] = r.bearing, el[k] = r.elevation;
      who[k] = scene.IsValid(r.sender) ? scene.instance_of(r.sender) : -1;
      std::copy_n(b->received.data() + r.data_offset, r.data_size, bytes + k * width);
      ++k;
    }
  }
  o[n] = static_cast<int64_t>(k);
  py::dict out;
  out["offsets"] = offsets;
  out["range"] = range;
  out["bearing"] = bearing;
  out["elevation"] = elevation;
  out["sender"] = sender;
  out["data"] = data;
  return out;
}

py::array_t<int64_t, py::array::c_style> MessageBytes(const py::object& data,
                                                      const std::string& what) {
  // Never booleans or fractions cast away in silence.
  const py::array raw = py::array::ensure(data);
  if (!raw) throw py::value_error(what + " must be an array of bytes, one row per robot");
  const char kind = raw.dtype().kind();
  if (kind == 'b') throw py::type_error(what + " is booleans, not bytes (0..255)");
  if (kind != 'i' && kind != 'u' && kind != 'f')
    throw py::type_error(what + " must be bytes, 0..255, not dtype " +
                         py::str(raw.dtype()).cast<std::string>());
  if (kind == 'f') {
    const auto f = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(raw);
    for (py::ssize_t i = 0; i < f.size(); ++i)
      if (!(f.data()[i] >= 0 && f.data()[i] <= 255 && f.data()[i] == std::floor(f.data()[i])))
        throw py::value_error(what + " must be bytes, whole numbers 0..255 (got " +
                              py::str(py::float_(f.data()[i])).cast<std::string>() + ")");
  }
  return py::array_t<int64_t, py::array::c_style | py::array::forcecast>::ensure(raw);
}

void SetRangeAndBearingData(Scene* scene, const ModelLayout& layout, const py::object& data) {
  using range_and_bearing::RangeAndBearingRow;
  const size_t n = layout.robots.size();
  const auto a = MessageBytes(data, "range-and-bearing data");
  if (a.ndim() != 2 || static_cast<size_t>(a.shape(0)) != n)
    throw py::value_error("range-and-bearing data must have shape (" + std::to_string(n) +
                          ", bytes): one row per robot");
  ObjectType type;
  if (!scene->FindType(range_and_bearing::kTypeName, &type))
    throw py::value_error("no range-and-bearing boards in this world");
  auto& rows = scene->rows<RangeAndBearingRow>(type).rows;
  const size_t k = static_cast<size_t>(a.shape(1));
  const int64_t* v = a.data();
  for (size_t i = 0; i < k * n; ++i)
    if (v[i] < 0 || v[i] > 255)
      throw py::value_error("range-and-bearing data must be bytes, 0..255 (got " +
                            std::to_string(v[i]) + ")");
  for (size_t i = 0; i < n; ++i) {
    const uint32_t slot = layout.board_slots[i];
    const std::string& robot = scene->instance(layout.robots[i]).name;
    if (slot == ModelLayout::kNoBoard)
      throw py::value_error("robot '" + robot + "' has no range-and-bearing board");
    const uint32_t payload = rows[scene->row_at(slot)].settings->payload_size;
    if (k > payload)
      throw py::value_error("range-and-bearing data of " + std::to_string(k) +
                            " bytes, more than robot '" + robot + "''s payload_size (" +
                            std::to_string(payload) + " bytes)");
  }
  for (size_t i = 0; i < n; ++i) {
    std::vector<uint8_t>& bytes = rows[scene->row_at(layout.board_slots[i])].data;
    bytes.resize(k);
    for (size_t j = 0; j < k; ++j) bytes[j] = static_cast<uint8_t>(v[i * k + j]);
  }
}

// Ground sensor readings, N x ground sensors.
Array Ground(const Scene& scene, const ModelLayout& layout, const py::object& out) {
  const auto n = static_cast<py::ssize_t>(layout.robots.size());
  const auto s = static_cast<py::ssize_t>(layout.ground_names.size());
  Array a = OutArray({n, s}, out);
  double* d = a.mutable_data();
  ObjectType type;
  if (!ground_sensor::FindSensorType(scene, &type)) return a;  // no columns
  const std::vector<ground_sensor::GroundSensorRow>& rows =
      scene.rows<ground_sensor::GroundSensorRow>(type).rows;
  for (size_t k = 0; k < layout.ground_slots.size(); ++k)
    d[k] = rows[scene.row_at(layout.ground_slots[k])].value;
  return a;
}

// Light sensor readings, N x light sensors.
Array Light(const Scene& scene, const ModelLayout& layout, const py::object& out) {
  const auto n = static_cast<py::ssize_t>(layout.robots.size());
  const auto s = static_cast<py::ssize_t>(layout.light_names.size());
  Array a = OutArray({n, s}, out);
  double* d = a.mutable_data();
  std::span<const uint32_t> owners;
  const std::span<const light::LightSensorRow> rows = light::Sensors(scene, &owners);
  for (size_t k = 0; k < layout.light_slots.size(); ++k)
    d[k] = rows[scene.row_at(layout.light_slots[k])].reading;
  return a;
}

// Joint positions (what = 0) or velocities (1), N x joints.
Array Joints(const Scene& scene, const ModelLayout& layout, int what, const py::object& out) {
  const auto n = static_cast<py::ssize_t>(layout.robots.size());
  const auto j = static_cast<py::ssize_t>(layout.joint_names.size());
  Array a = OutArray({n, j}, out);
  double* d = a.mutable_data();
  const auto rows = scene.joints();
  for (size_t k = 0; k < layout.joint_slots.size(); ++k) {
    const JointData& joint = rows[scene.row_at(layout.joint_slots[k])];
    d[k] = what == 0 ? joint.position : joint.velocity;
  }
  return a;
}

}  // namespace swarmsim::python
