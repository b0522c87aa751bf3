// Python controllers (controller.h): the Robots a controller receives, the
// module that calls it in the actuate phase, and the registry with it.
#include "swarm/python/controller.h"

#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "framework/error.h"
#include "framework/registry.h"
#include "framework/world.h"
#include "modules/builtin.h"
#include "swarm/python/arrays.h"
#include "swarm/python/initialized.h"
#include "swarm/python/ir_arrays.h"
#include "swarm/python/writers.h"

namespace swarmsim::python {
namespace {

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
      const WorldGate* outer;  // a controller of another world this one's runs inside
      ~Expiry() {
        robots->Expire();
        gate->in_controller = false;
        running_controller = outer;
      }
    } expiry{robots.get(), &gate, running_controller};
    gate.in_controller = true;
    gate.controller_thread = std::this_thread::get_id();
    running_controller = &gate;
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
        if (gate.in_run)
          throw Error(config_.where + ": the Python controller of model '" + config_.model +
                      "' raised " +
                      (e.matches(PyExc_KeyboardInterrupt) ? "KeyboardInterrupt" : "SystemExit"));
        return;
      }
      // The traceback, as Python prints it.
      // An error raised before the controller's first line (a function that
      // takes no argument) has no traceback: None, not a null handle.
      std::string trace;
      try {
        const auto or_none = [](const py::object& o) { return o ? o : py::none(); };
        py::module_ tb = py::module_::import("traceback");
        py::list lines =
            tb.attr("format_exception")(or_none(e.type()), or_none(e.value()), or_none(e.trace()));
        for (const auto& line : lines) trace += py::str(line).cast<std::string>();
      } catch (const std::exception&) {
        trace = e.what();
      }
      throw Error(config_.where + ": the Python controller of model '" + config_.model +
                  "' raised an exception in step " + std::to_string(world->step_count() + 1) +
                  " of the run (its robots.step was " + std::to_string(world->step_count()) +
                  ": robots.step counts the steps finished before the call):\n" + trace);
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

}  // namespace
}  // namespace swarmsim::python

// Robots.__new__(Robots)'s methods raise TypeError (initialized.h).
namespace pybind11::detail {
template <>
class type_caster<swarmsim::python::Robots>
    : public swarmsim::python::InitializedCaster<swarmsim::python::Robots> {};
}  // namespace pybind11::detail

namespace swarmsim::python {

const ModuleRegistry& Registry() {
  static const std::shared_ptr<ModuleRegistry> registry = MakeRegistry();
  return *registry;
}

void BindRobots(py::module_& m) {
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
}

}  // namespace swarmsim::python
