// The Python binding (`import swarmsim`): load a world file, step it, read
// the swarm as numpy arrays, and drive whole models from one vectorised
// Python function per step (a models entry's `python_controller:`).
//
// pybind11 and numpy types stay in this file. Every array handed to Python
// is a copy gathered from the scene (robots' objects are scattered through
// its slots, so no strided view exists), made into a buffer the caller may
// pass back (`out=`) to avoid the allocation.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <map>
#include <memory>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "framework/error.h"
#include "framework/registry.h"
#include "framework/scheduler.h"
#include "framework/state_hash.h"
#include "framework/world.h"
#include "modules/builtin.h"
#include "swarm/loader/world_loader.h"
#include "swarm/python/arrays.h"
#include "swarm/python/snapshot.h"

namespace py = pybind11;

namespace swarmsim::python {
namespace {

constexpr const char* kControllerModule = "python_controller";

// --- Python controllers ----------------------------------------------------------------

// What a controller function receives: the arrays of all its model's robots
// this step (read on first use, then kept for the call).
class Robots {
 public:
  Robots(World* world, const ModelLayout* layout, bool planar)
      : world_(world), layout_(layout), planar_(planar) {}
  int64_t count() const { return static_cast<int64_t>(layout_->robots.size()); }
  const std::vector<int>& indices() const { return layout_->robots; }
  std::vector<std::string> names() const {
    std::vector<std::string> out;
    for (const int i : layout_->robots) out.push_back(world_->scene().instance(i).name);
    return out;
  }
  const std::vector<std::string>& joint_names() const { return layout_->joint_names; }
  const std::vector<std::string>& sensor_names() const { return layout_->sensor_names; }
  double time() const { return world_->time(); }
  int64_t step() const { return world_->step_count(); }
  double dt() const { return world_->settings().time_step; }
  py::object poses() {
    return Cached(&poses_, [&] { return Poses(*world_, *layout_, planar_, py::none()); });
  }
  py::object velocities() {
    return Cached(&velocities_, [&] { return Velocities(Sc(), *layout_, py::none()); });
  }
  py::object proximity() {
    return Cached(&proximity_, [&] { return Proximity(Sc(), *layout_, py::none()); });
  }
  py::object proximity_values() {
    return Cached(&proximity_values_, [&] { return ProximityValues(Sc(), *layout_, py::none()); });
  }
  py::object ground() {
    return Cached(&ground_, [&] { return Ground(Sc(), *layout_, py::none()); });
  }
  const std::vector<std::string>& ground_names() const { return layout_->ground_names; }
  const std::vector<std::string>& light_sensor_names() const { return layout_->light_names; }
  py::object light() {
    return Cached(&light_, [&] { return Light(Sc(), *layout_, py::none()); });
  }
  py::object joint_positions() {
    return Cached(&joint_positions_, [&] { return Joints(Sc(), *layout_, 0, py::none()); });
  }
  py::object joint_velocities() {
    return Cached(&joint_velocities_, [&] { return Joints(Sc(), *layout_, 1, py::none()); });
  }
  py::object range_and_bearing() {
    return Cached(&range_and_bearing_, [&] { return RangeAndBearing(Sc(), *layout_); });
  }
  // What each robot's first board sends from the next sense phase on.
  void set_range_and_bearing_data(const py::object& data) {
    SetRangeAndBearingData(&world_->scene(), *layout_, data);
  }
  // A model parameter of every robot, as an array (numbers and booleans).
  Array param(const std::string& name) const {
    Array a(static_cast<py::ssize_t>(layout_->robots.size()));
    double* d = a.mutable_data();
    for (size_t i = 0; i < layout_->robots.size(); ++i) {
      const ParamValue* v = world_->FindParameter(layout_->robots[i], name);
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

 private:
  const Scene& Sc() const { return world_->scene(); }
  template <typename F>
  py::object Cached(py::object* slot, F&& make) {
    if (!*slot) *slot = make();
    return *slot;
  }
  World* world_;
  const ModelLayout* layout_;
  bool planar_;
  py::object poses_, velocities_, proximity_, proximity_values_, ground_, light_, joint_positions_,
      joint_velocities_, range_and_bearing_;
};

struct ControllerConfig {
  std::string model;
  std::string where;  // "file:line:col" of python_controller, or "World.set_controller"
  py::object function;
  bool planar = true;
};

// Applies a controller's result: {joint name: array of N or a number}. The
// value is the joint's target velocity (velocity mode) or target position
// (position mode) or position (joints nothing simulates, passive mode).
void ApplyTargets(World* world, const ModelLayout& layout, const ControllerConfig& config,
                  const py::handle& result) {
  if (result.is_none()) return;
  if (!py::isinstance<py::dict>(result))
    throw Error(config.where + ": the controller of model '" + config.model +
                "' must return a dict {joint name: array}, got " +
                std::string(py::str(py::type::of(result).attr("__name__"))));
  const size_t n = layout.robots.size();
  const size_t joints = layout.joint_names.size();
  Scene& scene = world->scene();
  const auto rows = scene.joints();
  for (const auto& [key, value] : py::reinterpret_borrow<py::dict>(result)) {
    const std::string name = py::str(key);
    size_t column = joints;
    for (size_t j = 0; j < joints; ++j)
      if (layout.joint_names[j] == name) {
        column = j;
        break;
      }
    if (column == joints) {
      std::string known;
      for (const std::string& j : layout.joint_names) known += (known.empty() ? "" : ", ") + j;
      throw Error(config.where + ": the controller of model '" + config.model + "' returned '" +
                  name + "', which is not one of its joints (" + known + ")");
    }
    Array values;
    try {
      values = py::cast<Array>(value);
    } catch (const py::cast_error&) {
      throw Error(config.where + ": the controller's '" + name + "' is not numbers");
    } catch (py::error_already_set&) {
      throw Error(config.where + ": the controller's '" + name + "' is not numbers");
    }
    const bool scalar =
        values.ndim() == 0 || (values.ndim() == 1 && values.shape(0) == 1 && n != 1);
    if (!scalar && (values.ndim() != 1 || static_cast<size_t>(values.shape(0)) != n))
      throw Error(config.where + ": the controller's '" + name + "' has shape " +
                  std::string(py::str(py::tuple(py::cast(
                      std::vector<py::ssize_t>(values.shape(), values.shape() + values.ndim()))))) +
                  ", expected (" + std::to_string(n) + ",): one value per robot");
    const double* v = values.data();
    for (size_t i = 0; i < n; ++i) {
      const double x = scalar ? v[0] : v[i];
      if (!std::isfinite(x))
        throw Error(config.where + ": the controller's '" + name + "' for robot '" +
                    scene.instance(layout.robots[i]).name + "' is not finite");
      JointData& joint = rows[scene.row_at(layout.joint_slots[i * joints + column])];
      if (joint.mode() == JointMode::kVelocity)
        joint.target_velocity = x;
      else if (joint.mode() == JointMode::kPosition)
        joint.target_position = x;
      else if (!joint.simulated && !joint.depends())
        joint.JumpTo(x);
      else
        throw Error(config.where + ": joint '" + name + "' is in " + ToString(joint.mode()) +
                    " mode: a controller sets velocity- and position-mode joints");
    }
  }
}

// One model's controller, run in the actuate phase before everything that
// moves joints (order 10: path followers 50, IK 100): the sensors read this
// step, the scripts have run. One call a step for all the model's robots,
// on the calling thread, so results do not depend on the thread count.
class ControllerModule : public Module {
 public:
  explicit ControllerModule(const ControllerConfig& config) : config_(config) {}
  // Snapshots: the controller's own memory is the Python program's, not saved.
  bool SaveState(const World&, StateWriter*) const override { return true; }
  ~ControllerModule() override {
    py::gil_scoped_acquire gil;
    config_.function = py::object();
  }
  void Actuate(World* world) override {
    Refresh(*world, config_.model, &layout_);
    if (layout_.robots.empty()) return;
    py::gil_scoped_acquire gil;
    try {
      Robots robots(world, &layout_, config_.planar);
      py::object result = config_.function(py::cast(&robots, py::return_value_policy::reference));
      ApplyTargets(world, layout_, config_, result);
    } catch (py::error_already_set& e) {
      // The traceback, as Python prints it.
      std::string trace;
      try {
        py::module_ tb = py::module_::import("traceback");
        py::list lines = tb.attr("format_exception")(e.type(), e.value(), e.trace());
        for (const auto& line : lines) trace += py::str(line).cast<std::string>();
      } catch (py::error_already_set&) {
        trace = e.what();
      }
      throw Error(config_.where + ": the Python controller of model '" + config_.model +
                  "' raised an exception at step " + std::to_string(world->step_count() + 1) +
                  ":\n" + trace);
    }
  }

 private:
  ControllerConfig config_;
  ModelLayout layout_;
};

std::shared_ptr<ModuleRegistry> MakeRegistry() {
  auto registry = std::make_shared<ModuleRegistry>();
  RegisterBuiltinModules(registry.get());
  ModuleDescriptor d;
  d.info = {"calculation", kControllerModule, "1",
            "a models entry's python_controller, called once a step with all its robots"};
  d.phases = PhaseBit(Phase::kActuate);
  d.order = 10;
  d.make = [](World*, const void* config) -> std::unique_ptr<Module> {
    return std::make_unique<ControllerModule>(*static_cast<const ControllerConfig*>(config));
  };
  registry->RegisterModule(std::move(d));
  return registry;
}

const ModuleRegistry& Registry() {
  static const std::shared_ptr<ModuleRegistry> registry = MakeRegistry();
  return *registry;
}

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

// --- World ------------------------------------------------------------------------------

class PyWorld {
 public:
  PyWorld(const std::string& path, std::optional<uint64_t> seed,
          const std::map<std::string, py::object>& set, int threads,
          const std::map<std::string, py::object>& controllers,
          const std::vector<std::string>& package_path)
      : args_{path, seed, set, threads, controllers, package_path} {
    LoadOptions options;
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
    try {
      loaded_ = LoadWorld(path, options, Registry());
    } catch (const Error& e) {
      throw py::value_error(e.what());
    }
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
      configs[m.name] = {m.name, m.python.where, LoadFunction(m.python), planar_};
    }
    for (const auto& [model, function] : controllers) {
      if (!PyCallable_Check(function.ptr()))
        throw py::type_error("controllers['" + model + "'] is not callable");
      configs[model] = {model, "World(controllers={'" + model + "': ...})", function, planar_};
    }
    for (auto& [model, config] : configs) {
      if (!HasModel(model))
        throw py::value_error("controllers: the world has no model '" + model + "'");
      world.AddModule(kControllerModule, &config);
    }
  }
  ~PyWorld() { Close(); }

  // --- Snapshots, reset and pickling (snapshot.cc; framework/world_state.h) -----------
  py::bytes snapshot() { return py::bytes(SnapshotBytes()); }
  std::string SnapshotBytes() {
    World& w = Live();
    try {
      py::gil_scoped_release release;
      return PackSnapshot(&w, Metrics());
    } catch (const Error& e) {
      throw std::runtime_error(e.what());
    }
  }
  void restore(const py::bytes& data) {
    World& w = Live();
    const std::string_view bytes(PyBytes_AS_STRING(data.ptr()),
                                 static_cast<size_t>(PyBytes_GET_SIZE(data.ptr())));
    try {
      py::gil_scoped_release release;
      UnpackSnapshot(bytes, &w, Metrics());
    } catch (const Error& e) {
      throw py::value_error(e.what());
    }
  }
  // The world as a fresh load with `seed` (None: the seed it was loaded
  // with) leaves it, in place: the snapshot of the world before its first
  // step (taken then, or from a load with the same arguments if it has
  // stepped), with the seed's random streams and the robots placed as the
  // loader places them with it.
  void reset(std::optional<uint64_t> seed) {
    World& w = Live();
    if (initial_.empty()) {
      if (w.step_count() == 0 && history_.empty()) {
        initial_ = SnapshotBytes();
      } else {
        PyWorld fresh(args_.path, loaded_seed_, args_.set, args_.threads, args_.controllers,
                      args_.package_path);
        initial_ = fresh.SnapshotBytes();
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
  py::tuple getstate() {
    return py::make_tuple(args_.path, args_.seed, args_.set, args_.threads, args_.controllers,
                          args_.package_path, snapshot());
  }
  static std::unique_ptr<PyWorld> setstate(const py::tuple& t) {
    if (t.size() != 7) throw py::value_error("World.__setstate__: not a pickled World");
    auto w = std::make_unique<PyWorld>(
        t[0].cast<std::string>(), t[1].cast<std::optional<uint64_t>>(),
        t[2].cast<std::map<std::string, py::object>>(), t[3].cast<int>(),
        t[4].cast<std::map<std::string, py::object>>(), t[5].cast<std::vector<std::string>>());
    w->restore(t[6].cast<py::bytes>());
    return w;
  }
  MetricMaps Metrics() { return {&swarm_metrics_, &robot_metrics_, &history_}; }

  void Step(int64_t n) {
    World& w = Live();
    if (n < 0) throw py::value_error("step(n): n must be >= 0");
    for (int64_t i = 0; i < n; ++i) {
      try {
        py::gil_scoped_release release;
        w.Step();
      } catch (const Error& e) {
        failed_ = e.what();
        throw std::runtime_error(e.what());
      } catch (const std::exception& e) {
        failed_ = e.what();
        throw std::runtime_error(std::string("internal error: ") + e.what());
      }
      TakeMetrics();
      if (PyErr_CheckSignals() != 0) throw py::error_already_set();
    }
  }

  void Close() {
    if (!loaded_.world) return;
    try {
      py::gil_scoped_release release;
      if (failed_.empty()) loaded_.world->Stop();
    } catch (const Error&) {
    }
    loaded_.world.reset();  // the controllers' functions are released with the GIL held
  }

  World& Live() {
    if (!loaded_.world) throw std::runtime_error("the world is closed");
    if (!failed_.empty())
      throw std::runtime_error("the world stopped after an error and cannot be stepped again: " +
                               failed_);
    return *loaded_.world;
  }
  const World& Any() const {
    if (!loaded_.world) throw std::runtime_error("the world is closed");
    return *loaded_.world;
  }

  double time() const { return Any().time(); }
  int64_t steps() const { return Any().step_count(); }
  std::string state_hash() const { return StateHasher::ToHex(Any().StateHash()); }
  int threads() const { return Any().threads(); }
  bool planar() const { return planar_; }
  std::optional<int64_t> default_steps() const { return loaded_.steps; }

  ModelLayout& Layout(const std::string& model) {
    const World& w = Any();
    ModelLayout& layout = layouts_[model];
    if (!model.empty() && !HasModel(model))
      throw py::value_error("the world has no model '" + model + "'");
    Refresh(w, model, &layout);
    return layout;
  }

  py::dict robots() {
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

  // columns: 3 (x, y, yaw), 7 (x, y, z, qw, qx, qy, qz), or 0: 3 in a planar world.
  py::object poses(const std::string& model, const py::object& out, int columns) {
    if (columns != 0 && columns != 3 && columns != 7)
      throw py::value_error("poses(columns=...) is 3 (x, y, yaw) or 7 (x, y, z, qw, qx, qy, qz)");
    const bool planar = columns == 0 ? planar_ : columns == 3;
    const ModelLayout& layout = Layout(model);  // checks the world is open
    return Poses(*loaded_.world, layout, planar, out);
  }
  py::object velocities(const std::string& model, const py::object& out) {
    return Velocities(Any().scene(), Layout(model), out);
  }
  py::object proximity(const std::string& model, const py::object& out) {
    return Proximity(Any().scene(), Layout(model), out);
  }
  py::object proximity_values(const std::string& model, const py::object& out) {
    return ProximityValues(Any().scene(), Layout(model), out);
  }
  py::object ground(const std::string& model, const py::object& out) {
    return Ground(Any().scene(), Layout(model), out);
  }
  std::vector<std::string> ground_names(const std::string& model) {
    return Layout(model).ground_names;
  }
  py::object light(const std::string& model, const py::object& out) {
    return Light(Any().scene(), Layout(model), out);
  }
  std::vector<std::string> light_sensor_names(const std::string& model) {
    return Layout(model).light_names;
  }
  py::object joint_positions(const std::string& model, const py::object& out) {
    return Joints(Any().scene(), Layout(model), 0, out);
  }
  py::object joint_velocities(const std::string& model, const py::object& out) {
    return Joints(Any().scene(), Layout(model), 1, out);
  }
  std::vector<std::string> joint_names(const std::string& model) {
    return Layout(model).joint_names;
  }
  std::vector<std::string> sensor_names(const std::string& model) {
    return Layout(model).sensor_names;
  }
  // What each robot's first range-and-bearing board heard (arrays.h).
  py::dict range_and_bearing(const std::string& model) {
    return RangeAndBearing(Any().scene(), Layout(model));
  }
  // Sets what each robot's first board sends, from the next sense phase on.
  void set_range_and_bearing_data(const std::string& model, const py::object& data) {
    World& w = Live();
    SetRangeAndBearingData(&w.scene(), Layout(model), data);
  }
  // Sets joint targets of a model's robots from Python between steps.
  void set_joint_targets(const std::string& model, const py::dict& targets) {
    World& w = Live();
    const ModelLayout& layout = Layout(model);
    ApplyTargets(&w, layout, {model, "World.set_joint_targets", py::none(), planar_}, targets);
  }

  // Swarm-level metrics: the last value of each.
  py::dict metrics() const {
    py::dict out;
    for (const auto& [name, value] : swarm_metrics_) out[py::str(name)] = value;
    return out;
  }
  // A robot-level metric's last value per robot (NaN: none yet), robots as `robots`.
  Array robot_metric(const std::string& name) {
    const ModelLayout& layout = Layout("");
    Array a(static_cast<py::ssize_t>(layout.robots.size()));
    double* d = a.mutable_data();
    const auto it = robot_metrics_.find(name);
    for (size_t i = 0; i < layout.robots.size(); ++i) {
      d[i] = std::numeric_limits<double>::quiet_NaN();
      if (it == robot_metrics_.end()) continue;
      const auto v = it->second.find(layout.robots[i]);
      if (v != it->second.end()) d[i] = v->second;
    }
    return a;
  }
  // Every swarm-level sample of `name` so far: (steps, values).
  py::tuple metric_history(const std::string& name) const {
    const auto it = history_.find(name);
    std::vector<double> steps, values;
    if (it != history_.end())
      for (const auto& [s, v] : it->second)
        steps.push_back(static_cast<double>(s)), values.push_back(v);
    return py::make_tuple(py::array(py::cast(steps)), py::array(py::cast(values)));
  }

  std::string describe() const {
    std::ostringstream out;
    const World& w = Any();
    out << "world: " << loaded_.file.string() << "\n";
    out << "physics: " << w.settings().physics << ", time step " << w.settings().time_step
        << " s, seed " << w.settings().seed << ", threads " << w.threads() << "\n";
    for (const ModelSummary& m : loaded_.models) {
      out << "model " << m.name << " (" << m.file << "), " << m.count << " copies\n";
      for (const ParameterSummary& p : m.parameters)
        out << "  parameter " << p.name << " = " << p.value << (p.unit.empty() ? "" : " " + p.unit)
            << "\n";
      for (const std::string& s : m.scripts) out << "  script: " << s << "\n";
      if (!m.python.file.empty())
        out << "  python controller: " << m.python.file.string() << ":" << m.python.function
            << "\n";
    }
    return out.str();
  }
  std::vector<std::string> warnings() const { return loaded_.warnings; }

 private:
  bool HasModel(const std::string& model) const {
    for (const ModelSummary& m : loaded_.models)
      if (m.name == model) return true;
    for (const ModelInstance& inst : Any().scene().instances())
      if (inst.model_name == model) return true;
    return false;
  }

  // Imports FILE.py as a module of its own and returns FUNCTION from it.
  static py::object LoadFunction(const PythonController& c) {
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
      if (e.matches(PyExc_ValueError)) throw;
      throw py::value_error(c.where + ": loading the Python controller " + c.file.string() +
                            " failed: " + e.what());
    }
  }

  void TakeMetrics() {
    for (const MetricSample& s : loaded_.world->TakeMetrics()) {
      if (s.instance < 0) {
        swarm_metrics_[s.name] = s.value;
        history_[s.name].emplace_back(s.step, s.value);
      } else {
        robot_metrics_[s.name][s.instance] = s.value;
      }
    }
  }

  LoadedWorld loaded_;
  bool planar_ = true;
  std::string failed_;
  std::map<std::string, ModelLayout> layouts_;
  std::map<std::string, double> swarm_metrics_;
  std::map<std::string, std::map<int, double>> robot_metrics_;
  std::map<std::string, std::vector<std::pair<int64_t, double>>> history_;
  // The constructor's arguments (pickling, reset with another seed), the
  // seed the world was loaded with, and fresh worlds' snapshots by seed.
  struct Args {
    std::string path;
    std::optional<uint64_t> seed;
    std::map<std::string, py::object> set;
    int threads;
    std::map<std::string, py::object> controllers;
    std::vector<std::string> package_path;
  } args_;
  uint64_t loaded_seed_ = 0;
  std::string initial_;  // reset: the snapshot before the first step ("": not yet taken)
};

}  // namespace
}  // namespace swarmsim::python

PYBIND11_MODULE(_swarmsim, m) {
  using swarmsim::python::PyWorld;
  using swarmsim::python::Robots;
  m.doc() = "swarmsim: load a world, step it, read and drive the swarm with numpy";
  py::class_<Robots>(m, "Robots",
                     "A model's robots as a Python controller sees them in one step "
                     "(arrays are copies, read on first use)")
      .def_property_readonly("count", &Robots::count)
      .def("__len__", &Robots::count)
      .def_property_readonly("indices", &Robots::indices)
      .def_property_readonly("names", &Robots::names)
      .def_property_readonly("joint_names", &Robots::joint_names)
      .def_property_readonly("sensor_names", &Robots::sensor_names)
      .def_property_readonly("time", &Robots::time)
      .def_property_readonly("step", &Robots::step)
      .def_property_readonly("dt", &Robots::dt)
      .def_property_readonly("poses", &Robots::poses)
      .def_property_readonly("velocities", &Robots::velocities)
      .def_property_readonly("proximity", &Robots::proximity)
      .def_property_readonly("proximity_values", &Robots::proximity_values)
      .def_property_readonly("ground", &Robots::ground)
      .def_property_readonly("ground_names", &Robots::ground_names)
      .def_property_readonly("light", &Robots::light)
      .def_property_readonly("light_sensor_names", &Robots::light_sensor_names)
      .def_property_readonly("joint_positions", &Robots::joint_positions)
      .def_property_readonly("joint_velocities", &Robots::joint_velocities)
      .def_property_readonly("range_and_bearing", &Robots::range_and_bearing)
      .def("set_range_and_bearing_data", &Robots::set_range_and_bearing_data, py::arg("data"))
      .def("param", &Robots::param, py::arg("name"));
  py::class_<PyWorld>(m, "World")
      .def(py::init<const std::string&, std::optional<uint64_t>,
                    const std::map<std::string, py::object>&, int,
                    const std::map<std::string, py::object>&, const std::vector<std::string>&>(),
           py::arg("path"), py::arg("seed") = py::none(),
           py::arg("set") = std::map<std::string, py::object>{}, py::arg("threads") = 0,
           py::arg("controllers") = std::map<std::string, py::object>{},
           py::arg("package_path") = std::vector<std::string>{})
      .def("step", &PyWorld::Step, py::arg("n") = 1)
      .def("close", &PyWorld::Close)
      .def_property_readonly("time", &PyWorld::time)
      .def_property_readonly("steps", &PyWorld::steps)
      .def_property_readonly("threads", &PyWorld::threads)
      .def_property_readonly("planar", &PyWorld::planar)
      .def_property_readonly("default_steps", &PyWorld::default_steps)
      .def("state_hash", &PyWorld::state_hash)
      .def_property_readonly("robots", &PyWorld::robots)
      .def("poses", &PyWorld::poses, py::arg("model") = "", py::arg("out") = py::none(),
           py::arg("columns") = 0)
      .def("velocities", &PyWorld::velocities, py::arg("model") = "", py::arg("out") = py::none())
      .def("proximity", &PyWorld::proximity, py::arg("model") = "", py::arg("out") = py::none())
      .def("proximity_values", &PyWorld::proximity_values, py::arg("model") = "",
           py::arg("out") = py::none())
      .def("ground", &PyWorld::ground, py::arg("model") = "", py::arg("out") = py::none())
      .def("ground_names", &PyWorld::ground_names, py::arg("model") = "")
      .def("light", &PyWorld::light, py::arg("model") = "", py::arg("out") = py::none())
      .def("light_sensor_names", &PyWorld::light_sensor_names, py::arg("model") = "")
      .def("joint_positions", &PyWorld::joint_positions, py::arg("model") = "",
           py::arg("out") = py::none())
      .def("joint_velocities", &PyWorld::joint_velocities, py::arg("model") = "",
           py::arg("out") = py::none())
      .def("joint_names", &PyWorld::joint_names, py::arg("model") = "")
      .def("sensor_names", &PyWorld::sensor_names, py::arg("model") = "")
      .def("set_joint_targets", &PyWorld::set_joint_targets, py::arg("model"), py::arg("targets"))
      .def("range_and_bearing", &PyWorld::range_and_bearing, py::arg("model") = "")
      .def("set_range_and_bearing_data", &PyWorld::set_range_and_bearing_data, py::arg("model"),
           py::arg("data"))
      .def_property_readonly("metrics", &PyWorld::metrics)
      .def("robot_metric", &PyWorld::robot_metric, py::arg("name"))
      .def("metric_history", &PyWorld::metric_history, py::arg("name"))
      .def("snapshot", &PyWorld::snapshot,
           "The world's state as bytes (README.md, Python: snapshots); restore() puts it back")
      .def("restore", &PyWorld::restore, py::arg("state"),
           "Puts the world in the state snapshot() saved (ValueError for another world's or "
           "corrupt bytes)")
      .def("reset", &PyWorld::reset, py::arg("seed") = py::none(),
           "Back to the state of a fresh load with `seed` (None: the world's own), in place")
      .def(py::pickle([](PyWorld& w) { return w.getstate(); }, &PyWorld::setstate))
      .def("describe", &PyWorld::describe)
      .def_property_readonly("warnings", &PyWorld::warnings);
}
