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
#include <mutex>
#include <optional>
#include <set>
#include <sstream>
#include <string>
#include <thread>
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
#include "swarm/python/ir_arrays.h"
#include "swarm/python/sensor_arrays.h"
#include "swarm/python/snapshot.h"
#include "swarm/python/writers.h"

namespace py = pybind11;

namespace swarmsim::python {
namespace {

constexpr const char* kControllerModule = "python_controller";

// --- Who may use a World now -----------------------------------------------------------

// A World is used by one thread at a time: step() and every writer hold
// `mutex` (taken with the GIL released, so a second Python thread waits for
// the first one's step instead of racing it); reads take it too, except from
// inside one of the world's controllers, where the world is paused in its
// actuate phase. A controller may not step, close or write to its own world
// (it returns its targets instead): those calls raise RuntimeError.
struct WorldGate {
  std::mutex mutex;
  // A controller of this world is running (Python code, GIL held), on this thread.
  bool in_controller = false;
  std::thread::id controller_thread;
  // A KeyboardInterrupt or SystemExit raised by a controller: the step
  // finishes without the controllers' targets, then it is raised again.
  py::object interrupt_type, interrupt_value, interrupt_trace;
  bool interrupted() const { return static_cast<bool>(interrupt_type); }
};

// Holds a world's gate for one call (the GIL held on entry and exit).
class GateLock {
 public:
  explicit GateLock(WorldGate* gate) : gate_(gate) {
    if (!gate_->mutex.try_lock()) {
      py::gil_scoped_release release;
      gate_->mutex.lock();
    }
  }
  ~GateLock() { gate_->mutex.unlock(); }
  GateLock(const GateLock&) = delete;
  GateLock& operator=(const GateLock&) = delete;

 private:
  WorldGate* gate_;
};

// --- Python controllers ----------------------------------------------------------------

// What a controller function receives: the arrays of all its model's robots
// this step (read on first use, then kept for the call). It expires when the
// call returns: reading it later raises RuntimeError (the arrays it gave
// are copies and stay valid).
class Robots {
 public:
  Robots(World* world, const ModelLayout* layout, bool planar)
      : world_(world), layout_(layout), planar_(planar), step_(world->step_count()) {}
  void Expire() {
    world_ = nullptr;
    layout_ = nullptr;
    for (py::object* o :
         {&poses_, &velocities_, &proximity_, &proximity_values_, &ground_, &light_,
          &joint_positions_, &joint_velocities_, &range_and_bearing_, &ir_messages_})
      *o = py::object();
  }
  int64_t count() const { return static_cast<int64_t>(L().robots.size()); }
  const std::vector<int>& indices() const { return L().robots; }
  std::vector<std::string> names() const {
    std::vector<std::string> out;
    for (const int i : L().robots) out.push_back(W().scene().instance(i).name);
    return out;
  }
  const std::vector<std::string>& joint_names() const { return L().joint_names; }
  const std::vector<std::string>& sensor_names() const { return L().sensor_names; }
  double time() const { return W().time(); }
  int64_t step() const { return W().step_count(); }
  double dt() const { return W().settings().time_step; }
  py::object poses() {
    return Cached(&poses_, [&] { return Poses(W(), L(), planar_, py::none()); });
  }
  py::object velocities() {
    return Cached(&velocities_, [&] { return Velocities(Sc(), L(), py::none()); });
  }
  py::object proximity() {
    return Cached(&proximity_, [&] { return Proximity(Sc(), L(), py::none()); });
  }
  py::object proximity_values() {
    return Cached(&proximity_values_, [&] { return ProximityValues(Sc(), L(), py::none()); });
  }
  py::object ground() {
    return Cached(&ground_, [&] { return Ground(Sc(), L(), py::none()); });
  }
  const std::vector<std::string>& ground_names() const { return L().ground_names; }
  const std::vector<std::string>& light_sensor_names() const { return L().light_names; }
  py::object light() {
    return Cached(&light_, [&] { return Light(Sc(), L(), py::none()); });
  }
  py::object joint_positions() {
    return Cached(&joint_positions_, [&] { return Joints(Sc(), L(), 0, py::none()); });
  }
  py::object joint_velocities() {
    return Cached(&joint_velocities_, [&] { return Joints(Sc(), L(), 1, py::none()); });
  }
  py::object range_and_bearing() {
    return Cached(&range_and_bearing_, [&] { return RangeAndBearing(Sc(), L()); });
  }
  // What each robot's first board sends from the next sense phase on.
  void set_range_and_bearing_data(const py::object& data) {
    SetRangeAndBearingData(&W().scene(), L(), data);
  }
  // IR messages (ir_arrays.h): what each robot's only transceiver heard, and
  // messages it sends at the next sense phase.
  py::object ir_messages() {
    return Cached(&ir_messages_, [&] {
      return IrMessages(Sc(), IrTransceivers(Sc(), L(), "", nullptr), py::none());
    });
  }
  void send_ir_messages(const py::object& data, const py::object& send) {
    std::vector<std::string> who;
    const auto slots = IrTransceivers(Sc(), L(), "", &who);
    SendIrMessages(&W().scene(), slots, who, data, send);
  }
  // A model parameter of every robot, as an array (numbers and booleans).
  Array param(const std::string& name) const { return ParamArray(W(), L(), name); }
  std::string repr() const {
    if (world_ == nullptr)
      return "<swarmsim.Robots of step " + std::to_string(step_) + " (expired)>";
    return "<swarmsim.Robots: " + std::to_string(count()) + " robots of model '" + L().model +
           "' at step " + std::to_string(step_) + ">";
  }

 private:
  World& W() const {
    if (world_ == nullptr)
      throw std::runtime_error(
          "this Robots object belongs to step " + std::to_string(step_) +
          ", which is over: read what you need inside the controller (its arrays are copies "
          "you may keep) or read the World between steps");
    return *world_;
  }
  const ModelLayout& L() const {
    W();
    return *layout_;
  }
  const Scene& Sc() const { return W().scene(); }
  template <typename F>
  py::object Cached(py::object* slot, F&& make) {
    W();
    if (!*slot) *slot = make();
    return *slot;
  }
  World* world_;
  const ModelLayout* layout_;
  bool planar_;
  int64_t step_;
  py::object poses_, velocities_, proximity_, proximity_values_, ground_, light_, joint_positions_,
      joint_velocities_, range_and_bearing_, ir_messages_;
};

struct ControllerConfig {
  std::string model;
  std::string where;  // "file:line:col" of python_controller, or "World.set_controller"
  py::object function;
  bool planar = true;
  WorldGate* gate = nullptr;
};

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
    WorldGate& gate = *config_.gate;
    if (gate.interrupted()) return;  // Ctrl-C in an earlier controller of this step
    // The Robots object expires when the call returns, however it returns.
    auto robots = std::make_shared<Robots>(world, &layout_, config_.planar);
    struct Expiry {
      Robots* robots;
      WorldGate* gate;
      ~Expiry() {
        robots->Expire();
        gate->in_controller = false;
      }
    } expiry{robots.get(), &gate};
    gate.in_controller = true;
    gate.controller_thread = std::this_thread::get_id();
    try {
      py::object result = config_.function(py::cast(robots));
      gate.in_controller = false;
      if (result.is_none()) return;
      if (!py::isinstance<py::dict>(result))
        throw Error(config_.where + ": the controller of model '" + config_.model +
                    "' must return a dict {joint name: array}, got " +
                    std::string(py::str(py::type::of(result).attr("__name__"))));
      JointTargets targets;
      try {
        targets = ReadJointTargets(world->scene(), layout_, result);
      } catch (const WriteError& e) {
        throw Error(config_.where + ": the controller of model '" + config_.model +
                    "' returned targets that cannot be used: " + e.what());
      }
      SetJointTargets(&world->scene(), layout_, targets);
    } catch (py::error_already_set& e) {
      // KeyboardInterrupt, SystemExit: the step goes on without this step's
      // targets, then step() raises it as itself (the world stays usable).
      if (e.matches(PyExc_KeyboardInterrupt) || e.matches(PyExc_SystemExit)) {
        gate.interrupt_type = e.type();
        gate.interrupt_value = e.value();
        gate.interrupt_trace = e.trace();
        return;
      }
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

// Thread counts a World or step_worlds takes: 0 (every core) to kMaxThreads.
constexpr int kMaxThreads = 256;
void CheckThreads(int threads, const char* where) {
  if (threads < 0 || threads > kMaxThreads)
    throw py::value_error(std::string(where) + ": threads is 0 (every core, " +
                          std::to_string(TaskScheduler::HardwareThreads()) + " here) or 1 to " +
                          std::to_string(kMaxThreads) + ", got " + std::to_string(threads));
}

class PyWorld {
 public:
  PyWorld(const std::string& path, std::optional<uint64_t> seed,
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
      configs[m.name] = {m.name, m.python.where, LoadFunction(m.python), planar_, gate_.get()};
    }
    for (const auto& [model, function] : controllers) {
      if (!PyCallable_Check(function.ptr()))
        throw py::type_error("controllers['" + model + "'] is not callable");
      configs[model] = {model, "World(controllers={'" + model + "': ...})", function, planar_,
                        gate_.get()};
    }
    for (auto& [model, config] : configs) {
      if (!HasModel(model))
        throw py::value_error("controllers: the world has no model '" + model + "'");
      world.AddModule(kControllerModule, &config);
    }
  }
  ~PyWorld() {
    if (!loaded_.world) return;
    try {
      py::gil_scoped_release release;
      if (failed_.empty()) loaded_.world->Stop();
    } catch (const Error&) {
    }
    loaded_.world.reset();
  }

  // --- Snapshots, reset and pickling (snapshot.cc; framework/world_state.h) -----------
  // Each a whole call between steps: refused inside a controller, and
  // waiting for another thread's step (the World's gate).
  py::bytes snapshot() {
    NotFromController("snapshot()");
    GateLock lock(gate_.get());
    return py::bytes(SnapshotBytes());
  }
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
    NotFromController("restore()");
    GateLock lock(gate_.get());
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
    NotFromController("reset()");
    GateLock lock(gate_.get());
    World& w = Live();
    if (initial_.empty()) {
      if (w.step_count() == 0 && history_.empty()) {
        initial_ = SnapshotBytes();
      } else {
        PyWorld fresh(args_.path, loaded_seed_, args_.set, args_.threads, args_.controllers,
                      args_.package_path, args_.keep_scripts);
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
                          args_.package_path, args_.keep_scripts, snapshot());
  }
  static std::unique_ptr<PyWorld> setstate(const py::tuple& t) {
    if (t.size() != 8) throw py::value_error("World.__setstate__: not a pickled World");
    auto w =
        std::make_unique<PyWorld>(t[0].cast<std::string>(), t[1].cast<std::optional<uint64_t>>(),
                                  t[2].cast<std::map<std::string, py::object>>(), t[3].cast<int>(),
                                  t[4].cast<std::map<std::string, py::object>>(),
                                  t[5].cast<std::vector<std::string>>(), t[6].cast<bool>());
    w->restore(t[7].cast<py::bytes>());
    return w;
  }
  MetricMaps Metrics() { return {&swarm_metrics_, &robot_metrics_, &history_}; }

  void Step(int64_t n) {
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

  void Close() {
    NotFromController("close()");
    GateLock lock(gate_.get());
    if (!loaded_.world) return;
    try {
      py::gil_scoped_release release;
      if (failed_.empty()) loaded_.world->Stop();
    } catch (const Error&) {
    }
    loaded_.world.reset();  // the controllers' functions are released with the GIL held
  }

  // --- For step() and step_worlds() -----------------------------------------------------

  // Raises RuntimeError when called from inside one of this world's
  // controllers (on the thread running it): the world is in the middle of
  // its step.
  void NotFromController(const char* call) const {
    if (gate_->in_controller && gate_->controller_thread == std::this_thread::get_id())
      throw std::runtime_error(
          std::string(call) +
          " inside a controller of this world: the world is in the middle of its step; a "
          "controller returns its joint targets, and the world is stepped, closed or written "
          "after step() returns");
  }
  WorldGate* gate() { return gate_.get(); }
  std::string file() const { return loaded_.file.string(); }
  // Up to n steps, the gate held and the GIL released: stops at an error
  // (kept in failed_) or an interrupt in a controller. Never throws.
  void RunSteps(int64_t n) noexcept {
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
  // After RunSteps, the GIL held: takes the metrics, then raises a
  // controller's KeyboardInterrupt or SystemExit as itself, or the step's
  // error as RuntimeError (prefixed with `who`).
  void FinishSteps(const std::string& who = "") {
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
  // Is the world open and not failed? Else RuntimeError saying which.
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

  // Reads wait for a step another thread runs; inside one of the world's
  // controllers (the world paused in its actuate phase) they read at once.
  class ReadLock {
   public:
    explicit ReadLock(WorldGate* gate) {
      if (!gate->in_controller) lock_.emplace(gate);
    }

   private:
    std::optional<GateLock> lock_;
  };
  ReadLock Reading() { return ReadLock(gate_.get()); }
  // Writers: not from inside one of the world's controllers (RuntimeError,
  // before waiting for the gate that thread's step holds).
  void NotWritingFromController(const char* call) const {
    if (gate_->in_controller && gate_->controller_thread == std::this_thread::get_id())
      throw std::runtime_error(std::string(call) +
                               " while the world is stepping (from inside a controller): a "
                               "controller returns its joint targets; write state between steps");
  }
  // WriteError -> TypeError or ValueError.
  template <typename F>
  static void Translate(F&& write) {
    try {
      write();
    } catch (const WriteError& e) {
      if (e.type_error) throw py::type_error(e.what());
      throw py::value_error(e.what());
    } catch (const Error& e) {
      throw py::value_error(e.what());
    }
  }

  double time() {
    auto r = Reading();
    return Any().time();
  }
  int64_t steps() {
    auto r = Reading();
    return Any().step_count();
  }
  std::string state_hash() {
    auto r = Reading();
    return StateHasher::ToHex(Any().StateHash());
  }
  int threads() const { return Any().threads(); }
  bool planar() const { return planar_; }
  std::optional<int64_t> default_steps() const { return loaded_.steps; }

  // The layout of `model`'s robots ("": every robot), refreshed; call with the gate held.
  ModelLayout& Layout(const std::string& model) {
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

  py::dict robots() {
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

  // columns: 3 (x, y, yaw), 7 (x, y, z, qw, qx, qy, qz), or 0: 3 in a planar world.
  py::object poses(const std::string& model, const py::object& out, int columns) {
    if (columns != 0 && columns != 3 && columns != 7)
      throw py::value_error("poses(columns=...) is 3 (x, y, yaw) or 7 (x, y, z, qw, qx, qy, qz)");
    const bool planar = columns == 0 ? planar_ : columns == 3;
    auto r = Reading();
    const ModelLayout& layout = Layout(model);  // checks the world is open
    return Poses(*loaded_.world, layout, planar, out);
  }
  // Reads `model`'s layout with the gate held and calls read(scene, layout).
  template <typename F>
  auto Read(const std::string& model, F&& read) {
    auto r = Reading();
    const ModelLayout& layout = Layout(model);
    return read(Any().scene(), layout);
  }
  py::object velocities(const std::string& model, const py::object& out) {
    return Read(model, [&](const Scene& s, const ModelLayout& l) { return Velocities(s, l, out); });
  }
  py::object proximity(const std::string& model, const py::object& out) {
    return Read(model, [&](const Scene& s, const ModelLayout& l) { return Proximity(s, l, out); });
  }
  py::object proximity_values(const std::string& model, const py::object& out) {
    return Read(model,
                [&](const Scene& s, const ModelLayout& l) { return ProximityValues(s, l, out); });
  }
  py::object ground(const std::string& model, const py::object& out) {
    return Read(model, [&](const Scene& s, const ModelLayout& l) { return Ground(s, l, out); });
  }
  std::vector<std::string> ground_names(const std::string& model) {
    return Read(model, [](const Scene&, const ModelLayout& l) { return l.ground_names; });
  }
  py::object light(const std::string& model, const py::object& out) {
    return Read(model, [&](const Scene& s, const ModelLayout& l) { return Light(s, l, out); });
  }
  std::vector<std::string> light_sensor_names(const std::string& model) {
    return Read(model, [](const Scene&, const ModelLayout& l) { return l.light_names; });
  }
  py::object joint_positions(const std::string& model, const py::object& out) {
    return Read(model, [&](const Scene& s, const ModelLayout& l) { return Joints(s, l, 0, out); });
  }
  py::object joint_velocities(const std::string& model, const py::object& out) {
    return Read(model, [&](const Scene& s, const ModelLayout& l) { return Joints(s, l, 1, out); });
  }
  std::vector<std::string> joint_names(const std::string& model) {
    return Read(model, [](const Scene&, const ModelLayout& l) { return l.joint_names; });
  }
  std::vector<std::string> sensor_names(const std::string& model) {
    return Read(model, [](const Scene&, const ModelLayout& l) { return l.sensor_names; });
  }
  Array param(const std::string& model, const std::string& name) {
    return Read(model,
                [&](const Scene&, const ModelLayout& l) { return ParamArray(Any(), l, name); });
  }
  // What each robot's first range-and-bearing board heard (arrays.h).
  py::dict range_and_bearing(const std::string& model) {
    return Read(model, [](const Scene& s, const ModelLayout& l) { return RangeAndBearing(s, l); });
  }

  // --- Devices beyond the basic arrays (sensor_arrays.h) -------------------------------

  std::vector<std::string> device_names(const std::string& model, const char* type) {
    return Read(model,
                [&](const Scene& s, const ModelLayout& l) { return Devices(s, l, type).names; });
  }
  // The slots of one named device per robot, and a name per robot for messages.
  std::vector<uint32_t> DeviceColumnSlots(const Scene& scene, const ModelLayout& layout,
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
  py::array vision_images(const std::string& model, const std::string& sensor, bool filtered,
                          const py::object& out) {
    return Read(model, [&](const Scene& s, const ModelLayout& l) {
      std::vector<std::string> who;
      const auto slots = DeviceColumnSlots(s, l, "vision_sensor", sensor, "vision sensor", &who);
      return VisionImages(s, slots, filtered, out, who);
    });
  }
  py::array vision_depths(const std::string& model, const std::string& sensor,
                          const py::object& out) {
    return Read(model, [&](const Scene& s, const ModelLayout& l) {
      std::vector<std::string> who;
      const auto slots = DeviceColumnSlots(s, l, "vision_sensor", sensor, "vision sensor", &who);
      return VisionDepths(s, slots, out, who);
    });
  }
  // One vision sensor by path (a scene's own, or "/footbot#3/eye"): (H, W, 3) or (H, W).
  py::array vision_sensor(const std::string& path, bool depth, bool filtered,
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
  py::dict blob_cameras(const std::string& model, const std::string& sensor) {
    return Read(model, [&](const Scene& s, const ModelLayout& l) {
      return BlobCameras(s, DeviceColumnSlots(s, l, "blob_camera", sensor, "blob camera", nullptr));
    });
  }
  py::dict ir_messages(const std::string& model, const std::string& transceiver,
                       const py::object& out) {
    return Read(model, [&](const Scene& s, const ModelLayout& l) {
      return IrMessages(s, IrTransceivers(s, l, transceiver, nullptr), out);
    });
  }
  Array force_sensors(const std::string& model, const py::object& out) {
    return Read(model, [&](const Scene& s, const ModelLayout& l) {
      return ForceSensors(s, Devices(s, l, "force_sensor"), l.robots.size(), out);
    });
  }
  py::array force_sensors_broken(const std::string& model) {
    return Read(model, [&](const Scene& s, const ModelLayout& l) {
      return ForceSensorsBroken(s, Devices(s, l, "force_sensor"), l.robots.size());
    });
  }
  py::dict distances() {
    auto r = Reading();
    return Distances(Any().scene());
  }
  py::dict collisions() {
    auto r = Reading();
    return Collisions(Any().scene());
  }

  // --- Writers: between steps (RuntimeError inside a controller or when closed) --------

  // Sets what each robot's first board sends, from the next sense phase on.
  void set_range_and_bearing_data(const std::string& model, const py::object& data) {
    NotWritingFromController("set_range_and_bearing_data()");
    GateLock lock(gate_.get());
    World& w = Live();
    SetRangeAndBearingData(&w.scene(), Layout(model), data);
  }
  // Queues IR messages for the next sense phase (ir_arrays.h).
  void send_ir_messages(const std::string& model, const py::object& data, const py::object& send,
                        const std::string& transceiver) {
    NotWritingFromController("send_ir_messages()");
    GateLock lock(gate_.get());
    World& w = Live();
    const ModelLayout& layout = Layout(model);
    std::vector<std::string> who;
    const auto slots = IrTransceivers(w.scene(), layout, transceiver, &who);
    SendIrMessages(&w.scene(), slots, who, data, send);
  }
  // Sets joint targets of a model's robots from Python between steps.
  void set_joint_targets(const std::string& model, const py::object& targets) {
    NotWritingFromController("set_joint_targets()");
    GateLock lock(gate_.get());
    World& w = Live();
    const ModelLayout& layout = Layout(model);
    Translate(
        [&] { SetJointTargets(&w.scene(), layout, ReadJointTargets(w.scene(), layout, targets)); });
  }
  void set_poses(const std::string& model, const py::object& poses) {
    NotWritingFromController("set_poses()");
    GateLock lock(gate_.get());
    World& w = Live();
    const ModelLayout& layout = Layout(model);
    Translate([&] { SetPoses(&w, layout, poses); });
  }
  void set_velocities(const std::string& model, const py::object& velocities) {
    NotWritingFromController("set_velocities()");
    GateLock lock(gate_.get());
    World& w = Live();
    const ModelLayout& layout = Layout(model);
    Translate([&] { SetVelocities(&w, layout, velocities); });
  }
  void set_joint_states(const std::string& model, const py::object& values, int what) {
    NotWritingFromController(what == 0 ? "set_joint_positions()" : "set_joint_velocities()");
    GateLock lock(gate_.get());
    World& w = Live();
    const ModelLayout& layout = Layout(model);
    Translate([&] { SetJointStates(&w, layout, what, values); });
  }
  void set_param(const std::string& model, const std::string& name, const py::object& values) {
    NotWritingFromController("set_param()");
    GateLock lock(gate_.get());
    World& w = Live();
    const ModelLayout& layout = Layout(model);
    Translate([&] { SetParam(&w, layout, name, values); });
  }

  // Swarm-level metrics: the last value of each.
  py::dict metrics() {
    auto r = Reading();
    py::dict out;
    for (const auto& [name, value] : swarm_metrics_) out[py::str(name)] = value;
    return out;
  }
  // A robot-level metric's last value per robot (NaN: none yet), robots as `robots`.
  Array robot_metric(const std::string& name) {
    auto r = Reading();
    const ModelLayout& layout = Layout("");
    const auto it = robot_metrics_.find(name);
    if (it == robot_metrics_.end() && !IsMetric(name))
      throw py::key_error("no robot-level metric '" + name + "' (" + MetricList() + ")");
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
  // Every swarm-level sample of `name` so far: (steps, values).
  py::tuple metric_history(const std::string& name) {
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

  std::string describe() {
    auto r = Reading();
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
  // The world file's metrics and any sampled so far (scripts' sim.recordMetric).
  bool IsMetric(const std::string& name) const {
    return std::find(loaded_.metric_names.begin(), loaded_.metric_names.end(), name) !=
           loaded_.metric_names.end();
  }
  std::string MetricList() const {
    std::set<std::string> names(loaded_.metric_names.begin(), loaded_.metric_names.end());
    for (const auto& [name, samples] : history_) names.insert(name);
    for (const auto& [name, values] : robot_metrics_) names.insert(name);
    std::string list;
    for (const std::string& n : names) list += (list.empty() ? "" : ", ") + n;
    return list.empty() ? "the world records none so far" : "known: " + list;
  }
  std::vector<std::string> ModelNames() const {
    std::set<std::string> names;
    for (const ModelSummary& m : loaded_.models) names.insert(m.name);
    for (const ModelInstance& inst : Any().scene().instances()) names.insert(inst.model_name);
    std::vector<std::string> out(names.begin(), names.end());
    return out;
  }
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

  std::unique_ptr<WorldGate> gate_ = std::make_unique<WorldGate>();  // outlives loaded_.world
  LoadedWorld loaded_;
  bool planar_ = true;
  std::string failed_;
  bool reported_ = false;  // failed_ was raised by the step that failed
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
    bool keep_scripts = true;
  } args_;
  uint64_t loaded_seed_ = 0;
  std::string initial_;  // reset: the snapshot before the first step ("": not yet taken)
};

// --- Many worlds at once ---------------------------------------------------------------

// The scheduler of the last thread count asked for, kept between calls
// (made again when the count changes: oneTBB applies the smallest
// parallelism limit alive, so old ones are not kept). Never destroyed at
// exit: oneTBB arenas outlive the interpreter's teardown.
TaskScheduler& WorldsScheduler(int threads) {
  static TaskScheduler* scheduler = nullptr;
  static int made_for = -1;
  if (scheduler == nullptr || made_for != threads) {
    delete scheduler;
    scheduler = new TaskScheduler(threads);
    made_for = threads;
  }
  return *scheduler;
}

// Steps each world n steps, the worlds in parallel on `threads` workers
// (each one's own step is as deterministic as ever: the same state as
// stepping it alone), the GIL released but for Python controllers.
void StepWorlds(const py::sequence& worlds, int64_t n, int threads) {
  if (n < 0) throw py::value_error("step_worlds: n must be >= 0, got " + std::to_string(n));
  CheckThreads(threads, "step_worlds");
  const size_t k = py::len(worlds);
  std::vector<PyWorld*> list(k);
  std::map<PyWorld*, size_t> seen;
  for (size_t i = 0; i < k; ++i) {
    py::object item = worlds[i];
    if (!py::isinstance<PyWorld>(item))
      throw py::type_error("step_worlds: worlds[" + std::to_string(i) + "] is a " +
                           std::string(py::str(py::type::of(item).attr("__name__"))) +
                           ", not a swarmsim.World");
    list[i] = item.cast<PyWorld*>();
    const auto [it, fresh] = seen.emplace(list[i], i);
    if (!fresh)
      throw py::value_error("step_worlds: worlds[" + std::to_string(i) + "] is worlds[" +
                            std::to_string(it->second) +
                            "]: each world may appear once (it would be stepped twice)");
  }
  const auto name = [&](size_t i) {
    return "step_worlds: worlds[" + std::to_string(i) + "] (" + list[i]->file() + "): ";
  };
  for (size_t i = 0; i < k; ++i) {
    try {
      list[i]->NotFromController("step_worlds()");
    } catch (const std::runtime_error& e) {
      throw std::runtime_error(name(i) + e.what());
    }
  }
  // The gates in address order (two threads stepping overlapping lists
  // cannot deadlock), then every world checked open.
  std::vector<PyWorld*> order = list;
  std::sort(order.begin(), order.end());
  std::vector<std::unique_ptr<GateLock>> locks;
  for (PyWorld* w : order) locks.push_back(std::make_unique<GateLock>(w->gate()));
  for (size_t i = 0; i < k; ++i) {
    try {
      list[i]->Live();
    } catch (const std::runtime_error& e) {
      throw std::runtime_error(name(i) + e.what());
    }
  }
  {
    py::gil_scoped_release release;
    WorldsScheduler(threads).ParallelFor(0, static_cast<int64_t>(k), 1, [&](int64_t b, int64_t e) {
      for (int64_t i = b; i < e; ++i) list[i]->RunSteps(n);
    });
  }
  // Metrics of every world, then the first world's interrupt or error.
  std::exception_ptr first;
  for (size_t i = 0; i < k; ++i) {
    try {
      list[i]->FinishSteps(name(i));
    } catch (...) {
      if (!first) first = std::current_exception();
    }
  }
  if (first) std::rethrow_exception(first);
  if (PyErr_CheckSignals() != 0) throw py::error_already_set();
}

}  // namespace
}  // namespace swarmsim::python

PYBIND11_MODULE(_swarmsim, m) {
  using swarmsim::python::PyWorld;
  using swarmsim::python::Robots;
  m.doc() = "swarmsim: load a world, step it, read and drive the swarm with numpy";

  // --- Robots: what a controller receives ------------------------------------------------
  py::class_<Robots, std::shared_ptr<Robots>>(
      m, "Robots",
      "A model's robots as a Python controller sees them during one step.\n\n"
      "Arrays are float64 copies with one row per robot (robots in index order), read on\n"
      "first use and kept for the call. The object expires when the controller returns:\n"
      "reading it later raises RuntimeError (the arrays it gave stay valid).")
      .def_property_readonly("count", &Robots::count, "Number of robots (int).")
      .def("__len__", &Robots::count, "Number of robots.")
      .def("__repr__", &Robots::repr)
      .def_property_readonly("indices", &Robots::indices,
                             "Robot indices (list of int), as World.robots['indices'].")
      .def_property_readonly("names", &Robots::names, "Robot names (list of str), 'footbot#3'.")
      .def_property_readonly("joint_names", &Robots::joint_names,
                             "The model's joints, the keys a controller returns (list of str).")
      .def_property_readonly("sensor_names", &Robots::sensor_names,
                             "Proximity sensors, the columns of proximity (list of str).")
      .def_property_readonly("time", &Robots::time, "Simulated time at the start of the step, s.")
      .def_property_readonly("step", &Robots::step, "Steps done before this one (int).")
      .def_property_readonly("dt", &Robots::dt, "The control step, s.")
      .def_property_readonly("poses", &Robots::poses,
                             "(N, 3) x, y, yaw (m, rad) in a planar world, else (N, 7) x, y, z, "
                             "qw, qx, qy, qz.")
      .def_property_readonly("velocities", &Robots::velocities,
                             "(N, 6) vx, vy, vz (m/s), wx, wy, wz (rad/s) of the roots.")
      .def_property_readonly("proximity", &Robots::proximity,
                             "(N, sensors) distance each proximity sensor sees, m; inf: nothing.")
      .def_property_readonly("proximity_values", &Robots::proximity_values,
                             "(N, sensors) response-curve values (e-puck IR); NaN: no curve.")
      .def_property_readonly("ground", &Robots::ground,
                             "(N, ground sensors) grey level, 0/1 in binary mode.")
      .def_property_readonly("ground_names", &Robots::ground_names,
                             "Ground sensors, the columns of ground.")
      .def_property_readonly("light", &Robots::light, "(N, light sensors) readings.")
      .def_property_readonly("light_sensor_names", &Robots::light_sensor_names,
                             "Light sensors, the columns of light.")
      .def_property_readonly("joint_positions", &Robots::joint_positions,
                             "(N, joints) positions, rad or m, columns as joint_names.")
      .def_property_readonly("joint_velocities", &Robots::joint_velocities,
                             "(N, joints) velocities, rad/s or m/s.")
      .def_property_readonly("range_and_bearing", &Robots::range_and_bearing,
                             "What each robot's first range-and-bearing board heard: a dict of "
                             "flat arrays (see World.range_and_bearing).")
      .def("set_range_and_bearing_data", &Robots::set_range_and_bearing_data, py::arg("data"),
           "Sets what each robot's first board sends from the next sense phase on: an (N, k)\n"
           "array of bytes 0..255, k at most the payload size. Raises ValueError.")
      .def_property_readonly("ir_messages", &Robots::ir_messages,
                             "What each robot's IR transceiver heard: a dict of flat arrays "
                             "(see World.ir_messages).")
      .def("send_ir_messages", &Robots::send_ir_messages, py::arg("data"),
           py::arg("send") = py::none(),
           "Queues row i of data ((N, k) bytes 0..255, k at most the payload size) as robot\n"
           "i's IR message for the next sense phase; send: (N,) bools, which robots send\n"
           "(None: all). Raises ValueError or TypeError, sending nothing.")
      .def("param", &Robots::param, py::arg("name"),
           "A model parameter of every robot: (N,) float64 (booleans 0/1). KeyError if the\n"
           "model has none of that name, TypeError for text.");

  // --- World -----------------------------------------------------------------------------
  py::class_<PyWorld>(
      m, "World",
      "A world file loaded, placed and ready to step.\n\n"
      "World(path, seed=None, set={}, threads=0, controllers={}, package_path=[],\n"
      "      keep_scripts=True)\n\n"
      "path: the world file (YAML). seed: replaces simulation.seed. set: parameter\n"
      "overrides {name or 'model.name': value}, as --set. threads: workers, 0 = every core,\n"
      "1 to 256 (ValueError otherwise); the state is the same for any count. controllers:\n"
      "{model: function(robots) -> {joint: targets}} called once a step (see Robots).\n"
      "keep_scripts: False drops the Lua scripts of the models given in controllers, so\n"
      "Python alone drives them. package_path: folders for a URDF's package:// URIs.\n\n"
      "A world that does not load raises ValueError with file:line:column. Arrays are\n"
      "float64 copies, one row per robot in index order; model='' means every robot;\n"
      "out= fills an array you keep (same dtype and shape, C-contiguous).\n\n"
      "Threads: one thread uses a World at a time. A second Python thread's call waits\n"
      "until the first one's step ends. A controller may read its world but not step,\n"
      "close or write it (RuntimeError).")
      .def(py::init<const std::string&, std::optional<uint64_t>,
                    const std::map<std::string, py::object>&, int,
                    const std::map<std::string, py::object>&, const std::vector<std::string>&,
                    bool>(),
           py::arg("path"), py::arg("seed") = py::none(),
           py::arg("set") = std::map<std::string, py::object>{}, py::arg("threads") = 0,
           py::arg("controllers") = std::map<std::string, py::object>{},
           py::arg("package_path") = std::vector<std::string>{}, py::arg("keep_scripts") = true)
      // Stepping and state.
      .def("step", &PyWorld::Step, py::arg("n") = 1,
           "Runs n control steps (sense, control, actuate, physics, record).\n\n"
           "Raises RuntimeError when a script or controller fails (the world then cannot be\n"
           "stepped again), when the world is closed, or from inside its own controller.\n"
           "A KeyboardInterrupt or SystemExit raised in a controller ends that step without\n"
           "the controllers' targets, then propagates as itself; the world stays usable.")
      .def("close", &PyWorld::Close,
           "Runs the scripts' cleanup and frees the world; later calls raise RuntimeError.\n"
           "RuntimeError from inside one of its controllers.")
      .def_property_readonly("time", &PyWorld::time, "Simulated time, s.")
      .def_property_readonly("steps", &PyWorld::steps, "Steps done (int).")
      .def_property_readonly("threads", &PyWorld::threads, "Worker threads (int).")
      .def_property_readonly("planar", &PyWorld::planar,
                             "True when the physics backend is planar (poses are x, y, yaw).")
      .def_property_readonly("default_steps", &PyWorld::default_steps,
                             "The world file's run length in steps, or None.")
      .def("state_hash", &PyWorld::state_hash,
           "The state hash (16 hex digits) `swarmsim run --hash` prints: equal hashes,\n"
           "equal futures.")
      .def_property_readonly("robots", &PyWorld::robots,
                             "{'names': [...], 'models': [...], 'indices': [...]} of the live "
                             "robots, in index order.")
      .def("describe", &PyWorld::describe, "What swarmsim describe prints (str).")
      .def_property_readonly("warnings", &PyWorld::warnings, "Load warnings (list of str).")
      // Reading arrays.
      .def("poses", &PyWorld::poses, py::arg("model") = "", py::arg("out") = py::none(),
           py::arg("columns") = 0,
           "Root poses: (N, 3) x, y, yaw (m, rad) in a planar world, else (N, 7) x, y, z, qw,\n"
           "qx, qy, qz; columns=3 or 7 forces one. ValueError for an unknown model or out=.")
      .def("velocities", &PyWorld::velocities, py::arg("model") = "", py::arg("out") = py::none(),
           "(N, 6) root velocities: vx, vy, vz (m/s), wx, wy, wz (rad/s).")
      .def("proximity", &PyWorld::proximity, py::arg("model") = "", py::arg("out") = py::none(),
           "(N, sensors) distance each proximity sensor sees, m; inf where it sees nothing.\n"
           "Columns as sensor_names(model).")
      .def("proximity_values", &PyWorld::proximity_values, py::arg("model") = "",
           py::arg("out") = py::none(),
           "(N, sensors) values on the sensors' response curves (the e-puck's IR), the far\n"
           "end where nothing is seen; NaN for sensors without a curve.")
      .def("sensor_names", &PyWorld::sensor_names, py::arg("model") = "",
           "Proximity sensors of the model, in hierarchy order ('prox[0]', ...).")
      .def("ground", &PyWorld::ground, py::arg("model") = "", py::arg("out") = py::none(),
           "(N, ground sensors) each one's grey level (0/1 in binary mode).")
      .def("ground_names", &PyWorld::ground_names, py::arg("model") = "",
           "Ground sensors, the columns of ground().")
      .def("light", &PyWorld::light, py::arg("model") = "", py::arg("out") = py::none(),
           "(N, light sensors) readings, 0 before the first step.")
      .def("light_sensor_names", &PyWorld::light_sensor_names, py::arg("model") = "",
           "Light sensors, the columns of light().")
      .def("joint_positions", &PyWorld::joint_positions, py::arg("model") = "",
           py::arg("out") = py::none(), "(N, joints) joint positions, rad or m.")
      .def("joint_velocities", &PyWorld::joint_velocities, py::arg("model") = "",
           py::arg("out") = py::none(), "(N, joints) joint velocities, rad/s or m/s.")
      .def("joint_names", &PyWorld::joint_names, py::arg("model") = "",
           "Joints of the model in hierarchy order: the columns of joint_positions().")
      .def("param", &PyWorld::param, py::arg("model"), py::arg("name"),
           "A model parameter of every robot of `model`: (N,) float64 (booleans 0/1).\n"
           "KeyError for an unknown name, TypeError for text.")
      .def("range_and_bearing", &PyWorld::range_and_bearing, py::arg("model") = "",
           "What each robot's first range-and-bearing board heard in the last sense phase:\n"
           "{'offsets': (N+1,) int64, 'range': (M,) m, 'bearing', 'elevation': (M,) rad,\n"
           "'sender': (M,) int64 robot index or -1, 'data': (M, bytes) uint8}; robot i's\n"
           "readings are rows offsets[i] to offsets[i+1]-1, nearest first.")
      // Devices: vision sensors, blob cameras, force sensors, distance and collision objects.
      .def(
          "vision_sensor_names",
          [](PyWorld& w, const std::string& model) {
            return w.device_names(model, "vision_sensor");
          },
          py::arg("model") = "", "Vision sensors on each robot of the model, hierarchy order.")
      .def("vision_images", &PyWorld::vision_images, py::arg("model") = "", py::arg("sensor") = "",
           py::arg("filtered") = false, py::arg("out") = py::none(),
           "(N, H, W, 3) uint8 RGB images, rows top to bottom, of vision sensor `sensor` (''\n"
           ": the robots' only one) of each robot, from the last sense phase it rendered in\n"
           "(its `rate`); filtered=True: its filter chain's image. Zeros before the first\n"
           "step. ValueError for an unknown or ambiguous sensor or different resolutions.")
      .def("vision_depths", &PyWorld::vision_depths, py::arg("model") = "", py::arg("sensor") = "",
           py::arg("out") = py::none(),
           "(N, H, W) float32 depth images, m along the view axis (`far` where nothing is\n"
           "seen). ValueError for a sensor with `depth: false`.")
      .def(
          "vision_image",
          [](PyWorld& w, const std::string& path, bool filtered, const py::object& out) {
            return w.vision_sensor(path, false, filtered, out);
          },
          py::arg("path"), py::arg("filtered") = false, py::arg("out") = py::none(),
          "(H, W, 3) uint8 image of the vision sensor at `path` ('/overhead',\n"
          "'/footbot#3/eye'): a scene's own sensors as well as robots'.")
      .def(
          "vision_depth",
          [](PyWorld& w, const std::string& path, const py::object& out) {
            return w.vision_sensor(path, true, false, out);
          },
          py::arg("path"), py::arg("out") = py::none(),
          "(H, W) float32 depth image of the vision sensor at `path`, m.")
      .def(
          "blob_camera_names",
          [](PyWorld& w, const std::string& model) { return w.device_names(model, "blob_camera"); },
          py::arg("model") = "", "Blob cameras on each robot of the model.")
      .def("ir_messages", &PyWorld::ir_messages, py::arg("model") = "", py::arg("transceiver") = "",
           py::arg("out") = py::none(),
           "What each robot's IR transceiver `transceiver` ('': its only one) heard in the\n"
           "last sense phase, as flat arrays: {'offsets': (N+1,) int64, 'distance': (M,) m\n"
           "(the receiver's estimate), 'sender': (M,) int64 sending robot or -1, 'size': (M,)\n"
           "int64 bytes, 'data': (M, largest size) uint8 zero-padded, 'sent': (N,) bool (the\n"
           "robot's own message went out)}; robot i's messages are rows offsets[i] to\n"
           "offsets[i+1]-1, in arrival order. out=: a dict it returned before, whose arrays\n"
           "are refilled where their shapes still fit (and replaced where not).")
      .def("blob_cameras", &PyWorld::blob_cameras, py::arg("model") = "", py::arg("sensor") = "",
           "What each robot's blob camera `sensor` ('': its only one) saw in the last sense\n"
           "phase: {'offsets': (N+1,) int64, 'color': (M, 3) RGB 0..1, 'distance': (M,) m,\n"
           "'bearing', 'elevation': (M,) rad in the camera's frame, 'robot': (M,) int64 the\n"
           "LED's robot index or -1}; robot i's blobs are rows offsets[i] to offsets[i+1]-1.")
      .def(
          "force_sensor_names",
          [](PyWorld& w, const std::string& model) {
            return w.device_names(model, "force_sensor");
          },
          py::arg("model") = "", "Force sensors on each robot of the model, hierarchy order.")
      .def("force_sensors", &PyWorld::force_sensors, py::arg("model") = "",
           py::arg("out") = py::none(),
           "(N, sensors, 6) Fx, Fy, Fz (N), Tx, Ty, Tz (N m): what each force sensor's link\n"
           "transmits, parent on child in the sensor's frame, filtered as sim.readForceSensor\n"
           "(without its read noise); NaN where the physics backend gives no reading.")
      .def("force_sensors_broken", &PyWorld::force_sensors_broken, py::arg("model") = "",
           "(N, sensors) bool: the force sensor's link broke.")
      .def("distances", &PyWorld::distances,
           "Every distance object of the world: {'names': [paths], 'found': (K,) bool,\n"
           "'distance': (K,) m (inf: nothing within the threshold), 'p1', 'p2': (K, 3) the\n"
           "closest points, world frame (NaN when not found)}, measured after each step.")
      .def("collisions", &PyWorld::collisions,
           "Every collision object (collision pairs): {'names': [paths], 'colliding': (K,)\n"
           "bool, 'offsets': (K+1,) int64, 'points': (M, 3) contact points, world frame};\n"
           "object k's points are rows offsets[k] to offsets[k+1]-1.")
      // Writing state between steps.
      .def("set_joint_targets", &PyWorld::set_joint_targets, py::arg("model"), py::arg("targets"),
           "Sets joint targets {joint name: (N,) array or one number}: the target velocity of\n"
           "velocity-mode joints, the target position of position-mode ones. Nothing is set\n"
           "unless all are right: ValueError for an unknown joint, a wrong shape or a value\n"
           "not finite (naming the robot); TypeError for booleans, complex numbers or text;\n"
           "RuntimeError when the world is closed or stepping.")
      .def("set_poses", &PyWorld::set_poses, py::arg("model"), py::arg("poses"),
           "Moves the robots' roots (with everything on them): (N, 3) x, y, yaw (z and tilt\n"
           "kept) or (N, 7) x, y, z, qw, qx, qy, qz (normalised). The physics engine takes\n"
           "them at the next step (velocities kept by ode, zeroed by box2d). ValueError for\n"
           "shapes and values, TypeError for non-numbers, RuntimeError if closed or stepping.")
      .def("set_velocities", &PyWorld::set_velocities, py::arg("model"), py::arg("velocities"),
           "Sets the robots' velocities, world frame: (N, 6) vx, vy, vz (m/s), wx, wy, wz\n"
           "(rad/s) or (N, 3) vx, vy, wz (vz, wx, wy kept), as velocities() reads them; every\n"
           "shape on a robot gets the same rigid motion. box2d and ode take them as the\n"
           "bodies' velocities at the next step (friction and motors act from there);\n"
           "kinematic and planar move the robot at them for the next step only (no inertia).\n"
           "ValueError for shapes, values not finite or robots without a body, TypeError for\n"
           "non-numbers, RuntimeError if closed or stepping.")
      .def(
          "set_joint_positions",
          [](PyWorld& w, const std::string& model, const py::object& v) {
            w.set_joint_states(model, v, 0);
          },
          py::arg("model"), py::arg("positions"),
          "Sets (N, joints) joint positions (columns as joint_names) of joints nothing\n"
          "simulates; a position-mode joint's target moves with it. ValueError for joints the\n"
          "physics engine simulates, shapes and values.")
      .def(
          "set_joint_velocities",
          [](PyWorld& w, const std::string& model, const py::object& v) {
            w.set_joint_states(model, v, 1);
          },
          py::arg("model"), py::arg("velocities"),
          "Sets (N, joints) joint velocities of joints nothing simulates (what\n"
          "joint_velocities() reads until the next step; motors follow their targets).")
      .def("set_param", &PyWorld::set_param, py::arg("model"), py::arg("name"), py::arg("values"),
           "Sets a model parameter of every robot of `model`: one number or (N,) array\n"
           "(booleans: 0 or 1). Scripts and controllers read it from then on; the state hash\n"
           "and snapshots hold it. ValueError for an unknown parameter (the message lists\n"
           "them) or a shape, TypeError for text.")
      .def("send_ir_messages", &PyWorld::send_ir_messages, py::arg("model"), py::arg("data"),
           py::arg("send") = py::none(), py::arg("transceiver") = "",
           "Queues row i of data ((N, k) bytes 0..255, k from 1 to the payload size) as\n"
           "robot i's IR message (its transceiver `transceiver`, '': its only one) for the\n"
           "next sense phase, for the robots whose send ((N,) bools; None: all) is true.\n"
           "The module then decides who hears it (range, carrier sense, collisions, loss).\n"
           "ValueError for shapes, values or sizes, TypeError for non-integers (nothing is\n"
           "queued then), RuntimeError if closed or stepping.")
      .def("set_range_and_bearing_data", &PyWorld::set_range_and_bearing_data, py::arg("model"),
           py::arg("data"),
           "Sets what each robot's first board sends from the next sense phase on: (N, k)\n"
           "bytes 0..255, k at most the payload size (ValueError otherwise).")
      // Metrics.
      .def_property_readonly("metrics", &PyWorld::metrics,
                             "{name: last value} of the swarm-level metrics.")
      .def("robot_metric", &PyWorld::robot_metric, py::arg("name"),
           "(N,) last value of a robot-level metric per robot (NaN: none yet). KeyError for\n"
           "a metric the world neither declares nor has recorded, listing the known ones.")
      .def("metric_history", &PyWorld::metric_history, py::arg("name"),
           "(steps, values): every swarm-level sample of `name` so far (float64 arrays).\n"
           "KeyError for an unknown metric, listing the known ones.")
      // Snapshots, reset and pickling.
      .def("snapshot", &PyWorld::snapshot,
           "The world's state as bytes (README.md, Python: snapshots); restore() puts it back.\n"
           "RuntimeError naming what cannot be saved (robots running Lua scripts, ...).")
      .def("restore", &PyWorld::restore, py::arg("state"),
           "Puts the world in the state snapshot() saved: restore + k steps gives the state\n"
           "hash of the uninterrupted run. ValueError for another world's or corrupt bytes\n"
           "(the world is then unchanged).")
      .def("reset", &PyWorld::reset, py::arg("seed") = py::none(),
           "Back, in place, to the state a fresh load with `seed` (None: the world's own)\n"
           "leaves: robots placed as the loader places them with that seed, every random\n"
           "stream from it. No file is read again.")
      .def(py::pickle([](PyWorld& w) { return w.getstate(); }, &PyWorld::setstate));

  m.def("step_worlds", &swarmsim::python::StepWorlds, py::arg("worlds"), py::arg("n") = 1,
        py::arg("threads") = 0,
        "Steps every World of the list n steps, the worlds in parallel on `threads` workers\n"
        "(0: every core; 1 to 256). Each world ends in the state stepping it alone gives (the\n"
        "same state hash). The GIL is released while no Python runs; Python controllers are\n"
        "called under it. Give worlds threads=1 for throughput: the parallelism is across\n"
        "worlds.\n\n"
        "ValueError for a world listed twice or a bad n or threads; TypeError for an item\n"
        "that is not a World; RuntimeError naming the world (worlds[i] and its file) when one\n"
        "is closed or failed, or when a world's step fails: the other worlds finish their n\n"
        "steps, the failed one stops at its error.");
}
