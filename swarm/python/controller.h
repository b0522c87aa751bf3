// Python controllers: a models entry's `python_controller:` (or one given
// to World(controllers=...)) called once a step with all its model's robots
// (a swarmsim.Robots), and the gate that lets one thread use a World at a
// time. The pybind11 types stay in swarm/python/.
#pragma once

#include <pybind11/pybind11.h>

#include <atomic>
#include <cstdint>
#include <mutex>
#include <stdexcept>
#include <string>
#include <thread>

namespace swarmsim {
class ModuleRegistry;
}

namespace swarmsim::python {

namespace py = pybind11;

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
  // World.run() is stepping (swarm/run's loop, which knows nothing of
  // Python): a controller's KeyboardInterrupt or SystemExit also ends the
  // step with an error, so that the run stops and writes its outputs.
  bool in_run = false;
  // The step_worlds() call holding this gate (0: none). A controller of one
  // of its worlds that waited for another of them would wait for ever (the
  // call holds every gate until all its worlds have stepped).
  std::atomic<uint64_t> stepping_call{0};
};

// The gate of the world whose controller this thread is running (null: none).
inline thread_local const WorldGate* running_controller = nullptr;

// Holds a world's gate for one call (the GIL held on entry and exit).
class GateLock {
 public:
  explicit GateLock(WorldGate* gate) : gate_(gate) {
    if (!gate_->mutex.try_lock()) {
      const uint64_t call = gate_->stepping_call.load();
      if (running_controller != nullptr && call != 0 &&
          running_controller->stepping_call.load() == call)
        throw std::runtime_error(
            "this world is stepping in the same step_worlds() call as the world whose "
            "controller asks: a controller there may read only its own world (read or step "
            "the others between step_worlds() calls)");
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

// What a controller module is made from (World adds one per model).
struct ControllerConfig {
  std::string model;
  std::string where;  // "file:line:col" of python_controller, or "World.set_controller"
  py::object function;
  bool planar = true;
  WorldGate* gate = nullptr;
};

// The built-in modules and "python_controller" (made from a
// ControllerConfig), the registry every World of the binding loads with.
inline constexpr const char* kControllerModule = "python_controller";
const ModuleRegistry& Registry();

// Adds swarmsim.Robots, what a controller receives, to the module.
void BindRobots(py::module_& m);

}  // namespace swarmsim::python
