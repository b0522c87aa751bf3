// swarmsim.World (world.h).
#include "swarm/python/world.h"

#include <pybind11/stl.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <limits>
#include <memory>
#include <set>
#include <sstream>
#include <thread>

#include "framework/error.h"
#include "framework/registry.h"
#include "framework/scheduler.h"
#include "framework/state_hash.h"
#include "framework/world.h"
#include "swarm/loader/describe.h"
#include "swarm/python/ir_arrays.h"
#include "swarm/python/sensor_arrays.h"
#include "swarm/python/writers.h"

namespace swarmsim::python {
namespace {

std::vector<std::filesystem::path> PluginDirectories() {
  std::vector<std::filesystem::path> out;
  if (const char* env = std::getenv("SWARMSIM_PLUGIN_PATH"))
    for (std::string_view rest = env; !rest.empty();) {
      const size_t colon = rest.find(':');
      out.emplace_back(rest.substr(0, colon));
      rest = colon == std::string_view::npos ? "" : rest.substr(colon + 1);
    }
  // Beside the package in the build tree (build/python/swarmsim/_swarmsim*.so
  // -> build/plugins).
  const std::filesystem::path here =
      py::module_::import("swarmsim._swarmsim").attr("__file__").cast<std::string>();
  out.push_back(here.parent_path().parent_path().parent_path() / "plugins");
  return out;
}

// WriteError -> TypeError or ValueError.
template <typename F>
void Translate(F&& write) {
  try {
    write();
  } catch (const WriteError& e) {
    if (e.type_error) throw py::type_error(e.what());
    throw py::value_error(e.what());
  } catch (const Error& e) {
    throw py::value_error(e.what());
  }
}

}  // namespace

void CheckThreads(int64_t threads, const char* where) {
  if (threads < 0 || threads > kMaxThreads)
    throw py::value_error(std::string(where) + ": threads is 0 (every core, " +
                          std::to_string(TaskScheduler::HardwareThreads()) + " here) or 1 to " +
                          std::to_string(kMaxThreads) + ", got " + std::to_string(threads));
}

// Reads `model`'s layout with the gate held and calls read(scene, layout).
template <typename F>
auto PyWorld::Read(const std::string& model, F&& read) {
  auto r = Reading();
  const ModelLayout& layout = Layout(model);
  return read(Any().scene(), layout);
}

PyWorld::PyWorld(const std::string& path, std::optional<uint64_t> seed,
                 const std::map<std::string, py::object>& set, int threads,
                 const std::map<std::string, py::object>& controllers,
                 const std::vector<std::string>& package_path, bool keep_scripts)
    : args_{path, seed, set, threads, controllers, package_path, keep_scripts} {
  CheckThreads(threads, "World(threads=...)");
  LoadOptions options;
  if (!keep_scripts)
    for (const auto& [model, function] : controllers) options.drop_scripts.push_back(model);
  for (const std::string& dir : package_path) options.package_path.emplace_back(dir);
  options.seed = seed;
  options.threads = threads;
  options.python_controllers = true;
  options.plugin_directories = PluginDirectories();
  for (const auto& [name, value] : set) {
    std::string text;
    if (py::isinstance<py::bool_>(value))
      text = value.cast<bool>() ? "true" : "false";
    else
      text = py::str(value).cast<std::string>();
    options.overrides.emplace_back(name, text);
  }
  options.override_option = "World(set=...)";
  loaded_overrides_ = options.overrides;
  const auto load_start = std::chrono::steady_clock::now();
  try {
    loaded_ = LoadWorld(path, options, Registry());
  } catch (const Error& e) {
    throw py::value_error(e.what());
  }
  load_seconds_ =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - load_start).count();
  World& world = *loaded_.world;
  loaded_seed_ = world.settings().seed;
  planar_ = world.registry().dynamics_capabilities(world.settings().physics).planar;
  // Controllers: the world file's, then the constructor's (replacing them).
  std::map<std::string, ControllerConfig> configs;
  // A controller drives every robot of its model, so all the entries of
  // one model must name the same one (or none at all).
  for (const ModelSummary& m : loaded_.models)
    for (const ModelSummary& other : loaded_.models)
      if (&other != &m && other.name == m.name && !m.python.file.empty() &&
          (other.python.file != m.python.file || other.python.function != m.python.function))
        throw py::value_error(
            m.python.where + ": model '" + m.name + "' has another models entry with " +
            (other.python.file.empty() ? std::string("no python_controller")
                                       : "python_controller at " + other.python.where) +
            ": a Python controller drives every robot of its model, so "
            "give every entry of the model the same one");
  for (const ModelSummary& m : loaded_.models) {
    if (m.python.file.empty() || configs.contains(m.name)) continue;
    configs[m.name] = {m.name, m.python.where, LoadFunction(m.python), planar_, gate_.get()};
  }
  for (const auto& [model, function] : controllers) {
    if (!PyCallable_Check(function.ptr()))
      throw py::type_error("controllers['" + model + "'] is not callable");
    configs[model] = {model, "World(controllers={'" + model + "': ...})", function, planar_,
                      gate_.get()};
  }
  for (auto& [model, config] : configs) {
    if (!HasModel(model)) {
      std::string known;
      for (const std::string& m : ModelNames()) known += (known.empty() ? "" : ", ") + m;
      throw py::value_error("controllers: the world has no model '" + model + "' (it has " +
                            (known.empty() ? std::string("none") : known) + ")");
    }
    world.AddModule(kControllerModule, &config);
  }
}

PyWorld::~PyWorld() {
  if (!loaded_.world) return;
  try {
    py::gil_scoped_release release;
    if (failed_.empty()) loaded_.world->Stop();
  } catch (const Error&) {
  }
  loaded_.world.reset();
}

py::bytes PyWorld::snapshot() {
  NotFromController("snapshot()");
  GateLock lock(gate_.get());
  return py::bytes(SnapshotBytes());
}

std::string PyWorld::SnapshotBytes() {
  World& w = Live();
  try {
    py::gil_scoped_release release;
    return PackSnapshot(&w, Metrics());
  } catch (const Error& e) {
    throw std::runtime_error(e.what());
  }
}

void PyWorld::restore(const py::object& data) {
  NotFromController("restore()");
  // bytes, bytearray, memoryview, a uint8 array: any contiguous buffer of bytes.
  if (py::isinstance<py::str>(data) || !PyObject_CheckBuffer(data.ptr()))
    throw py::type_error("restore(state): state must be the bytes snapshot() returned, not " +
                         std::string(py::str(py::type::of(data).attr("__name__"))));
  Py_buffer view;
  if (PyObject_GetBuffer(data.ptr(), &view, PyBUF_SIMPLE) != 0) throw py::error_already_set();
  const std::unique_ptr<Py_buffer, void (*)(Py_buffer*)> held(&view, PyBuffer_Release);
  GateLock lock(gate_.get());
  World& w = Live();
  const std::string_view bytes(static_cast<const char*>(view.buf), static_cast<size_t>(view.len));
  try {
    py::gil_scoped_release release;
    UnpackSnapshot(bytes, &w, Metrics());
  } catch (const Error& e) {
    throw py::value_error(e.what());
  }
}

void PyWorld::reset(std::optional<uint64_t> seed) {
  NotFromController("reset()");
  GateLock lock(gate_.get());
  World& w = Live();
  if (initial_.empty()) {
    try {
      if (w.step_count() == 0 && history_.empty()) {
        initial_ = SnapshotBytes();
      } else {
        PyWorld fresh(args_.path, loaded_seed_, args_.set, args_.threads, args_.controllers,
                      args_.package_path, args_.keep_scripts);
        initial_ = fresh.SnapshotBytes();
      }
    } catch (const std::runtime_error& e) {
      // reset() is a snapshot of the start restored: say so in its words.
      std::string why = e.what();
      if (why.rfind("snapshot: ", 0) == 0) why.erase(0, 10);
      throw std::runtime_error("reset(): " + why + ", or make a new World from the file");
    }
  }
  const uint64_t s = seed.value_or(loaded_seed_);
  const std::string_view bytes(initial_);
  try {
    py::gil_scoped_release release;
    if (s == loaded_seed_) {
      UnpackSnapshot(bytes, &w, Metrics());
    } else {
      const std::vector<std::pair<int, Pose>> roots = loaded_.placement(s);
      const World::Reseed reseed{s, roots};
      UnpackSnapshot(bytes, &w, Metrics(), &reseed);
    }
  } catch (const Error& e) {
    throw py::value_error(e.what());
  }
}

py::tuple PyWorld::getstate() {
  return py::make_tuple(args_.path, args_.seed, args_.set, args_.threads, args_.controllers,
                        args_.package_path, args_.keep_scripts, snapshot());
}

std::unique_ptr<PyWorld> PyWorld::setstate(const py::tuple& t) {
  if (t.size() != 8) throw py::value_error("World.__setstate__: not a pickled World");
  auto w =
      std::make_unique<PyWorld>(t[0].cast<std::string>(), t[1].cast<std::optional<uint64_t>>(),
                                t[2].cast<std::map<std::string, py::object>>(), t[3].cast<int>(),
                                t[4].cast<std::map<std::string, py::object>>(),
                                t[5].cast<std::vector<std::string>>(), t[6].cast<bool>());
  w->restore(t[7].cast<py::bytes>());
  return w;
}

void PyWorld::Step(int64_t n) {
  if (n < 0) throw py::value_error("step(n): n must be >= 0, got " + std::to_string(n));
  NotFromController("step()");
  GateLock lock(gate_.get());
  Live();
  for (int64_t i = 0; i < n; ++i) {
    {
      py::gil_scoped_release release;
      RunSteps(1);
    }
    FinishSteps();
    if (PyErr_CheckSignals() != 0) throw py::error_already_set();
  }
}

void PyWorld::Close() {
  NotFromController("close()");
  GateLock lock(gate_.get());
  if (!loaded_.world) return;
  try {
    py::gil_scoped_release release;
    if (failed_.empty()) loaded_.world->Stop();
  } catch (const Error&) {
  }
  loaded_.world.reset();  // the controllers' functions are released with the GIL held
  // And the constructor's copies (kept for pickling and reset): a controller
  // that refers to its World made a cycle through C++ that Python's
  // collector cannot see, kept after close() (330 KiB a World of 8 robots).
  args_.controllers.clear();
  args_.set.clear();
}

void PyWorld::NotFromController(const char* call) const {
  if (gate_->in_controller && gate_->controller_thread == std::this_thread::get_id())
    throw std::runtime_error(
        std::string(call) +
        " inside a controller of this world: the world is in the middle of its step; a "
        "controller returns its joint targets, and the world is stepped, closed or written "
        "after step() returns");
}

void PyWorld::RunSteps(int64_t n) noexcept {
  World& w = *loaded_.world;
  for (int64_t i = 0; i < n && failed_.empty() && !gate_->interrupted(); ++i) {
    try {
      w.Step();
    } catch (const Error& e) {
      failed_ = e.what();
    } catch (const std::exception& e) {
      failed_ = std::string("internal error: ") + e.what();
    }
  }
}

void PyWorld::FinishSteps(const std::string& who) {
  if (loaded_.world) TakeMetrics();
  if (gate_->interrupted()) {
    PyErr_Restore(gate_->interrupt_type.release().ptr(), gate_->interrupt_value.release().ptr(),
                  gate_->interrupt_trace.release().ptr());
    throw py::error_already_set();
  }
  if (!failed_.empty() && !reported_) {
    reported_ = true;
    throw std::runtime_error(who + failed_);
  }
}

World& PyWorld::Live() {
  if (!loaded_.world) throw std::runtime_error("the world is closed");
  if (ran_)
    throw std::runtime_error(
        "the world's run() ran it to its end (its scripts' sysCall_cleanup ran): it can be "
        "read, not stepped; load it again to run more");
  if (!failed_.empty())
    throw std::runtime_error("the world stopped after an error and cannot be stepped again: " +
                             failed_);
  return *loaded_.world;
}

const World& PyWorld::Any() const {
  if (!loaded_.world) throw std::runtime_error("the world is closed");
  return *loaded_.world;
}

void PyWorld::NotWritingFromController(const char* call) const {
  if (gate_->in_controller && gate_->controller_thread == std::this_thread::get_id())
    throw std::runtime_error(std::string(call) +
                             " while the world is stepping (from inside a controller): a "
                             "controller returns its joint targets; write state between steps");
}

double PyWorld::time() {
  auto r = Reading();
  return Any().time();
}

int64_t PyWorld::steps() {
  auto r = Reading();
  return Any().step_count();
}

std::string PyWorld::state_hash() {
  auto r = Reading();
  return StateHasher::ToHex(Any().StateHash());
}

ModelLayout& PyWorld::Layout(const std::string& model) {
  const World& w = Any();
  if (!model.empty() && !HasModel(model)) {
    std::string known;
    for (const std::string& m : ModelNames()) known += (known.empty() ? "" : ", ") + m;
    throw py::value_error("the world has no model '" + model + "' (it has " +
                          (known.empty() ? std::string("none") : known) + ")");
  }
  ModelLayout& layout = layouts_[model];
  try {
    Refresh(w, model, &layout);
  } catch (const Error& e) {
    throw py::value_error(e.what());
  }
  return layout;
}

py::dict PyWorld::robots() {
  auto r = Reading();
  const ModelLayout& layout = Layout("");
  py::list names, models;
  for (const int i : layout.robots) {
    names.append(Any().scene().instance(i).name);
    models.append(Any().scene().instance(i).model_name);
  }
  py::dict out;
  out["names"] = names;
  out["models"] = models;
  out["indices"] = py::cast(layout.robots);
  return out;
}

py::object PyWorld::poses(const std::string& model, const py::object& out, int columns) {
  if (columns != 0 && columns != 3 && columns != 7)
    throw py::value_error("poses(columns=...) is 3 (x, y, yaw) or 7 (x, y, z, qw, qx, qy, qz)");
  const bool planar = columns == 0 ? planar_ : columns == 3;
  auto r = Reading();
  const ModelLayout& layout = Layout(model);  // checks the world is open
  return Poses(*loaded_.world, layout, planar, out);
}

py::object PyWorld::velocities(const std::string& model, const py::object& out) {
  return Read(model, [&](const Scene& s, const ModelLayout& l) { return Velocities(s, l, out); });
}

py::object PyWorld::proximity(const std::string& model, const py::object& out) {
  return Read(model, [&](const Scene& s, const ModelLayout& l) { return Proximity(s, l, out); });
}

py::object PyWorld::proximity_values(const std::string& model, const py::object& out) {
  return Read(model,
              [&](const Scene& s, const ModelLayout& l) { return ProximityValues(s, l, out); });
}

py::object PyWorld::ground(const std::string& model, const py::object& out) {
  return Read(model, [&](const Scene& s, const ModelLayout& l) { return Ground(s, l, out); });
}

std::vector<std::string> PyWorld::ground_names(const std::string& model) {
  return Read(model, [](const Scene&, const ModelLayout& l) { return l.ground_names; });
}

py::object PyWorld::light(const std::string& model, const py::object& out) {
  return Read(model, [&](const Scene& s, const ModelLayout& l) { return Light(s, l, out); });
}

std::vector<std::string> PyWorld::light_sensor_names(const std::string& model) {
  return Read(model, [](const Scene&, const ModelLayout& l) { return l.light_names; });
}

py::object PyWorld::joint_positions(const std::string& model, const py::object& out) {
  return Read(model, [&](const Scene& s, const ModelLayout& l) { return Joints(s, l, 0, out); });
}

py::object PyWorld::joint_velocities(const std::string& model, const py::object& out) {
  return Read(model, [&](const Scene& s, const ModelLayout& l) { return Joints(s, l, 1, out); });
}

std::vector<std::string> PyWorld::joint_names(const std::string& model) {
  return Read(model, [](const Scene&, const ModelLayout& l) { return l.joint_names; });
}

std::vector<std::string> PyWorld::sensor_names(const std::string& model) {
  return Read(model, [](const Scene&, const ModelLayout& l) { return l.sensor_names; });
}

Array PyWorld::param(const std::string& model, const std::string& name) {
  return Read(model,
              [&](const Scene&, const ModelLayout& l) { return ParamArray(Any(), l, name); });
}

py::dict PyWorld::range_and_bearing(const std::string& model) {
  return Read(model, [](const Scene& s, const ModelLayout& l) { return RangeAndBearing(s, l); });
}

std::vector<std::string> PyWorld::device_names(const std::string& model, const char* type) {
  return Read(model,
              [&](const Scene& s, const ModelLayout& l) { return Devices(s, l, type).names; });
}

std::vector<uint32_t> PyWorld::DeviceColumnSlots(const Scene& scene, const ModelLayout& layout,
                                                 const char* type, const std::string& name,
                                                 const char* what, std::vector<std::string>* who) {
  const DeviceTable table = Devices(scene, layout, type);
  const size_t column = DeviceColumn(table, name, what);
  std::vector<uint32_t> slots;
  for (size_t i = 0; i < layout.robots.size(); ++i) {
    slots.push_back(table.slots[i * table.names.size() + column]);
    if (who) who->push_back(std::string(what) + " " + scene.PathOf(scene.IdAt(slots.back())));
  }
  return slots;
}

py::array PyWorld::vision_images(const std::string& model, const std::string& sensor, bool filtered,
                                 const py::object& out) {
  return Read(model, [&](const Scene& s, const ModelLayout& l) {
    std::vector<std::string> who;
    const auto slots = DeviceColumnSlots(s, l, "vision_sensor", sensor, "vision sensor", &who);
    return VisionImages(s, slots, filtered, out, who);
  });
}

py::array PyWorld::vision_depths(const std::string& model, const std::string& sensor,
                                 const py::object& out) {
  return Read(model, [&](const Scene& s, const ModelLayout& l) {
    std::vector<std::string> who;
    const auto slots = DeviceColumnSlots(s, l, "vision_sensor", sensor, "vision sensor", &who);
    return VisionDepths(s, slots, out, who);
  });
}

py::array PyWorld::vision_sensor(const std::string& path, bool depth, bool filtered,
                                 const py::object& out) {
  auto r = Reading();
  const Scene& scene = Any().scene();
  const ObjectId id = scene.FindObject(path);
  if (id.IsNull())
    throw py::value_error("no object '" + path + "'" + scene.ExplainMissingPath(path));
  const std::vector<uint32_t> slots{scene.SlotOf(id)};
  const std::vector<std::string> who{"'" + path + "'"};
  py::object batch = py::none();
  if (!out.is_none()) {
    if (!py::isinstance<py::array>(out)) throw py::value_error("out= must be a numpy array");
    batch = out.attr("reshape")(py::make_tuple(1) + py::tuple(out.attr("shape")));
    if (!py::reinterpret_borrow<py::array>(batch).writeable() ||
        !(py::reinterpret_borrow<py::array>(out).flags() & py::array::c_style))
      throw py::value_error("out= must be a writeable C-contiguous array");
  }
  py::array a = depth ? VisionDepths(scene, slots, batch, who)
                      : VisionImages(scene, slots, filtered, batch, who);
  return out.is_none() ? py::array(a[py::int_(0)]) : py::reinterpret_borrow<py::array>(out);
}

py::dict PyWorld::blob_cameras(const std::string& model, const std::string& sensor) {
  return Read(model, [&](const Scene& s, const ModelLayout& l) {
    return BlobCameras(s, DeviceColumnSlots(s, l, "blob_camera", sensor, "blob camera", nullptr));
  });
}

py::dict PyWorld::ir_messages(const std::string& model, const std::string& transceiver,
                              const py::object& out) {
  return Read(model, [&](const Scene& s, const ModelLayout& l) {
    return IrMessages(s, IrTransceivers(s, l, transceiver, nullptr), out);
  });
}

Array PyWorld::force_sensors(const std::string& model, const py::object& out) {
  return Read(model, [&](const Scene& s, const ModelLayout& l) {
    return ForceSensors(s, Devices(s, l, "force_sensor"), l.robots.size(), out);
  });
}

py::array PyWorld::force_sensors_broken(const std::string& model) {
  return Read(model, [&](const Scene& s, const ModelLayout& l) {
    return ForceSensorsBroken(s, Devices(s, l, "force_sensor"), l.robots.size());
  });
}

py::dict PyWorld::distances() {
  auto r = Reading();
  return Distances(Any().scene());
}

py::dict PyWorld::collisions() {
  auto r = Reading();
  return Collisions(Any().scene());
}

void PyWorld::set_range_and_bearing_data(const std::string& model, const py::object& data) {
  NotWritingFromController("set_range_and_bearing_data()");
  GateLock lock(gate_.get());
  World& w = Live();
  SetRangeAndBearingData(&w.scene(), Layout(model), data);
}

void PyWorld::send_ir_messages(const std::string& model, const py::object& data,
                               const py::object& send, const std::string& transceiver) {
  NotWritingFromController("send_ir_messages()");
  GateLock lock(gate_.get());
  World& w = Live();
  const ModelLayout& layout = Layout(model);
  std::vector<std::string> who;
  const auto slots = IrTransceivers(w.scene(), layout, transceiver, &who);
  SendIrMessages(&w.scene(), slots, who, data, send);
}

void PyWorld::set_joint_targets(const std::string& model, const py::object& targets) {
  NotWritingFromController("set_joint_targets()");
  GateLock lock(gate_.get());
  World& w = Live();
  const ModelLayout& layout = Layout(model);
  Translate(
      [&] { SetJointTargets(&w.scene(), layout, ReadJointTargets(w.scene(), layout, targets)); });
}

void PyWorld::set_poses(const std::string& model, const py::object& poses) {
  NotWritingFromController("set_poses()");
  GateLock lock(gate_.get());
  World& w = Live();
  const ModelLayout& layout = Layout(model);
  Translate([&] { SetPoses(&w, layout, poses); });
}

void PyWorld::set_velocities(const std::string& model, const py::object& velocities) {
  NotWritingFromController("set_velocities()");
  GateLock lock(gate_.get());
  World& w = Live();
  const ModelLayout& layout = Layout(model);
  Translate([&] { SetVelocities(&w, layout, velocities); });
}

void PyWorld::set_joint_states(const std::string& model, const py::object& values, int what) {
  NotWritingFromController(what == 0 ? "set_joint_positions()" : "set_joint_velocities()");
  GateLock lock(gate_.get());
  World& w = Live();
  const ModelLayout& layout = Layout(model);
  Translate([&] { SetJointStates(&w, layout, what, values); });
}

void PyWorld::set_param(const std::string& model, const std::string& name,
                        const py::object& values) {
  NotWritingFromController("set_param()");
  GateLock lock(gate_.get());
  World& w = Live();
  const ModelLayout& layout = Layout(model);
  // Held to the model's `range`, as World(set=...) and --set are.
  std::optional<std::pair<double, double>> bounds;
  std::string range_text;
  for (const ModelSummary& m : loaded_.models)
    if (m.name == model)
      for (const ParameterSummary& p : m.parameters)
        if (p.name == name && p.bounds) {
          bounds = p.bounds;
          range_text = p.range + (p.unit.empty() || p.unit == "1" ? "" : " " + p.unit);
        }
  Translate([&] { SetParam(&w, layout, name, values, bounds, range_text); });
}

py::dict PyWorld::metrics() {
  Any();  // RuntimeError once closed, as every other accessor
  auto r = Reading();
  py::dict out;
  for (const auto& [name, value] : swarm_metrics_) out[py::str(name)] = value;
  return out;
}

std::vector<std::string> PyWorld::metric_names() {
  Any();
  auto r = Reading();
  return loaded_.metric_names;
}

Array PyWorld::robot_metric(const std::string& name) {
  auto r = Reading();
  const ModelLayout& layout = Layout("");
  const auto it = robot_metrics_.find(name);
  if (it == robot_metrics_.end() && !IsMetric(name))
    throw py::key_error("no robot-level metric '" + name + "' (" + RobotMetricList() + ")");
  Array a(static_cast<py::ssize_t>(layout.robots.size()));
  double* d = a.mutable_data();
  for (size_t i = 0; i < layout.robots.size(); ++i) {
    d[i] = std::numeric_limits<double>::quiet_NaN();
    if (it == robot_metrics_.end()) continue;
    const auto v = it->second.find(layout.robots[i]);
    if (v != it->second.end()) d[i] = v->second;
  }
  return a;
}

py::tuple PyWorld::metric_history(const std::string& name) {
  auto r = Reading();
  const auto it = history_.find(name);
  if (it == history_.end() && !IsMetric(name))
    throw py::key_error("no metric '" + name + "' (" + MetricList() + ")");
  std::vector<double> steps, values;
  if (it != history_.end())
    for (const auto& [s, v] : it->second)
      steps.push_back(static_cast<double>(s)), values.push_back(v);
  return py::make_tuple(py::array(py::cast(steps)), py::array(py::cast(values)));
}

std::string PyWorld::describe() {
  auto r = Reading();
  Any();  // RuntimeError once closed
  std::ostringstream out;
  PrintDescription(loaded_, out);
  return out.str();
}

bool PyWorld::IsMetric(const std::string& name) const {
  return std::find(loaded_.metric_names.begin(), loaded_.metric_names.end(), name) !=
         loaded_.metric_names.end();
}

std::string PyWorld::MetricList() const {
  std::set<std::string> names(loaded_.metric_names.begin(), loaded_.metric_names.end());
  for (const auto& [name, samples] : history_) names.insert(name);
  for (const auto& [name, values] : robot_metrics_) names.insert(name);
  std::string list;
  for (const std::string& n : names) list += (list.empty() ? "" : ", ") + n;
  return list.empty() ? "the world records none so far" : "known: " + list;
}

std::string PyWorld::RobotMetricList() const {
  std::string list, swarm;
  for (const auto& [name, values] : robot_metrics_) list += (list.empty() ? "" : ", ") + name;
  std::set<std::string> declared(loaded_.metric_names.begin(), loaded_.metric_names.end());
  for (const std::string& n : declared) swarm += (swarm.empty() ? "" : ", ") + n;
  std::string text =
      list.empty() ? "the robots have recorded none so far" : "the robots have recorded: " + list;
  if (!swarm.empty())
    text += "; the world's swarm-level metrics, read with metrics and metric_history: " + swarm;
  return text;
}

std::vector<std::string> PyWorld::ModelNames() const {
  std::set<std::string> names;
  for (const ModelSummary& m : loaded_.models) names.insert(m.name);
  for (const ModelInstance& inst : Any().scene().instances()) names.insert(inst.model_name);
  std::vector<std::string> out(names.begin(), names.end());
  return out;
}

bool PyWorld::HasModel(const std::string& model) const {
  for (const ModelSummary& m : loaded_.models)
    if (m.name == model) return true;
  for (const ModelInstance& inst : Any().scene().instances())
    if (inst.model_name == model) return true;
  return false;
}

py::object PyWorld::LoadFunction(const PythonController& c) {
  py::module_ util = py::module_::import("importlib.util");
  const std::string name = "swarmsim_controller_" + c.file.stem().string();
  try {
    py::object spec = util.attr("spec_from_file_location")(name, c.file.string());
    py::object module = util.attr("module_from_spec")(spec);
    spec.attr("loader").attr("exec_module")(module);
    if (!py::hasattr(module, c.function.c_str()))
      throw py::value_error(c.where + ": " + c.file.string() + " has no function '" + c.function +
                            "'");
    py::object f = module.attr(c.function.c_str());
    if (!PyCallable_Check(f.ptr()))
      throw py::value_error(c.where + ": '" + c.function + "' in " + c.file.string() +
                            " is not a function");
    return f;
  } catch (py::error_already_set& e) {
    // Ctrl-C and sys.exit() while the file runs stay themselves.
    if (e.matches(PyExc_ValueError) || e.matches(PyExc_KeyboardInterrupt) ||
        e.matches(PyExc_SystemExit))
      throw;
    // The error and the controller file's own lines of its traceback, not
    // the interpreter's import machinery ("<frozen importlib._bootstrap>").
    std::string said;
    try {
      py::module_ tb = py::module_::import("traceback");
      if (e.trace()) {
        py::list frames;
        for (const py::handle frame : tb.attr("extract_tb")(e.trace()))
          if (std::filesystem::path(py::str(frame.attr("filename")).cast<std::string>()) == c.file)
            frames.append(frame);
        for (const py::handle line : tb.attr("format_list")(frames))
          said += py::str(line).cast<std::string>();
      }
      for (const py::handle line : tb.attr("format_exception_only")(e.type(), e.value()))
        said += py::str(line).cast<std::string>();
      while (!said.empty() && said.back() == '\n') said.pop_back();
    } catch (const std::exception&) {
      said = e.what();
    }
    throw py::value_error(c.where + ": loading the Python controller " + c.file.string() +
                          " failed:\n" + said);
  }
}

void PyWorld::TakeMetrics() { KeepMetrics(loaded_.world->TakeMetrics()); }

void PyWorld::KeepMetrics(const std::vector<MetricSample>& samples) {
  for (const MetricSample& s : samples) {
    if (s.instance < 0) {
      swarm_metrics_[s.name] = s.value;
      history_[s.name].emplace_back(s.step, s.value);
    } else {
      robot_metrics_[s.name][s.instance] = s.value;
    }
  }
}

}  // namespace swarmsim::python
