// swarmsim.World: a world file loaded, placed and ready to step, its swarm
// read and written as numpy arrays (arrays.h, sensor_arrays.h, ir_arrays.h,
// writers.h), snapshots (snapshot.h), and the gate (controller.h) that lets
// one thread use it at a time. The bindings are in module.cc.
#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "swarm/loader/world_loader.h"
#include "swarm/python/arrays.h"
#include "swarm/python/controller.h"
#include "swarm/python/initialized.h"
#include "swarm/python/snapshot.h"

namespace swarmsim::python {

// Thread counts a World or step_worlds takes: 0 (every core) to kMaxThreads;
// ValueError naming `where` otherwise.
inline constexpr int kMaxThreads = 256;
void CheckThreads(int64_t threads, const char* where);

// `python3 -m swarmsim run --out DIR` of a world that did not load: DIR
// (made if missing) gets summary.json with status error and `error`, the
// earlier run's outputs removed, as `swarmsim run` does (run.cc).
// ValueError when the folder cannot be used or written.
void WriteLoadFailure(const std::string& out, const std::string& world_file,
                      const std::string& error);

class PyWorld {
 public:
  PyWorld(const std::string& path, std::optional<uint64_t> seed,
          const std::map<std::string, py::object>& set, int threads,
          const std::map<std::string, py::object>& controllers,
          const std::vector<std::string>& package_path, bool keep_scripts);
  ~PyWorld();

  // --- Snapshots, reset and pickling (snapshot.cc; framework/world_state.h) -----------
  // Each a whole call between steps: refused inside a controller, and
  // waiting for another thread's step (the World's gate).
  py::bytes snapshot();
  void restore(const py::object& data);  // bytes, bytearray or a bytes-like buffer
  // The world as a fresh load with `seed` (None: the seed it was loaded
  // with) leaves it, in place: the snapshot of the world before its first
  // step (taken then, or from a load with the same arguments if it has
  // stepped), with the seed's random streams and the robots placed as the
  // loader places them with it.
  void reset(std::optional<uint64_t> seed);
  py::tuple getstate();
  static std::unique_ptr<PyWorld> setstate(const py::tuple& t);

  void Step(int64_t n);
  // run(): `swarmsim run`'s loop (swarm/run/runner.h) over this world: the
  // steps (None: the world's duration), progress and summary table unless
  // quiet, the state hash printed when asked, and with `out` (a folder)
  // summary.json and metrics.csv written as the run goes. The world is
  // stopped at the end (its scripts' cleanups run): readable, not steppable.
  // Returns the run's figures; raises RuntimeError (the run's error, after
  // its outputs are written) or KeyboardInterrupt (a stop signal, or one a
  // controller raised).
  py::dict Run(std::optional<int64_t> steps, const std::optional<std::string>& out, bool quiet,
               bool hash);

  void Close();

  // --- For step() and step_worlds() -----------------------------------------------------

  // Raises RuntimeError when called from inside one of this world's
  // controllers (on the thread running it): the world is in the middle of
  // its step.
  void NotFromController(const char* call) const;
  WorldGate* gate() { return gate_.get(); }
  std::string file() const { return loaded_.file.string(); }
  // Up to n steps, the gate held and the GIL released: stops at an error
  // (kept in failed_) or an interrupt in a controller. Never throws.
  void RunSteps(int64_t n) noexcept;
  // After RunSteps, the GIL held: takes the metrics, then raises a
  // controller's KeyboardInterrupt or SystemExit as itself, or the step's
  // error as RuntimeError (prefixed with `who`).
  void FinishSteps(const std::string& who = "");
  // Is the world open and not failed? Else RuntimeError saying which.
  World& Live();
  const World& Any() const;

  double time();
  int64_t steps();
  std::string state_hash();
  int threads() const { return Any().threads(); }
  bool planar() const {  // a closed world raises, as every other call
    Any();
    return planar_;
  }
  std::optional<int64_t> default_steps() const { return loaded_.steps; }

  py::dict robots();

  // columns: 3 (x, y, yaw), 7 (x, y, z, qw, qx, qy, qz), or 0: 3 in a planar world.
  py::object poses(const std::string& model, const py::object& out, int columns);
  py::object velocities(const std::string& model, const py::object& out);
  py::object proximity(const std::string& model, const py::object& out);
  py::object proximity_values(const std::string& model, const py::object& out);
  py::object ground(const std::string& model, const py::object& out);
  std::vector<std::string> ground_names(const std::string& model);
  py::object light(const std::string& model, const py::object& out);
  std::vector<std::string> light_sensor_names(const std::string& model);
  py::object joint_positions(const std::string& model, const py::object& out);
  py::object joint_velocities(const std::string& model, const py::object& out);
  std::vector<std::string> joint_names(const std::string& model);
  std::vector<std::string> sensor_names(const std::string& model);
  Array param(const std::string& model, const std::string& name);
  // What each robot's first range-and-bearing board heard (arrays.h).
  py::dict range_and_bearing(const std::string& model);

  // --- Devices beyond the basic arrays (sensor_arrays.h) -------------------------------

  std::vector<std::string> device_names(const std::string& model, const char* type);
  py::array vision_images(const std::string& model, const std::string& sensor, bool filtered,
                          const py::object& out);
  py::array vision_depths(const std::string& model, const std::string& sensor,
                          const py::object& out);
  // One vision sensor by path (a scene's own, or "/footbot#3/eye"): (H, W, 3) or (H, W).
  py::array vision_sensor(const std::string& path, bool depth, bool filtered,
                          const py::object& out);
  py::dict blob_cameras(const std::string& model, const std::string& sensor);
  py::dict ir_messages(const std::string& model, const std::string& transceiver,
                       const py::object& out);
  Array force_sensors(const std::string& model, const py::object& out);
  py::array force_sensors_broken(const std::string& model);
  py::dict distances();
  py::dict collisions();

  // --- Writers: between steps (RuntimeError inside a controller or when closed) --------

  // Sets what each robot's first board sends, from the next sense phase on.
  void set_range_and_bearing_data(const std::string& model, const py::object& data);
  // Queues IR messages for the next sense phase (ir_arrays.h).
  void send_ir_messages(const std::string& model, const py::object& data, const py::object& send,
                        const std::string& transceiver);
  // Sets joint targets of a model's robots from Python between steps.
  void set_joint_targets(const std::string& model, const py::object& targets);
  void set_poses(const std::string& model, const py::object& poses);
  void set_velocities(const std::string& model, const py::object& velocities);
  void set_joint_states(const std::string& model, const py::object& values, int what);
  void set_param(const std::string& model, const std::string& name, const py::object& values);

  // Swarm-level metrics: the last value of each.
  py::dict metrics();
  // The swarm-level metrics the world declares (its `metrics:`), in order.
  std::vector<std::string> metric_names();
  // A robot-level metric's last value per robot (NaN: none yet), robots as `robots`.
  Array robot_metric(const std::string& name);
  // Every swarm-level sample of `name` so far: (steps, values).
  py::tuple metric_history(const std::string& name);

  std::string describe();
  std::vector<std::string> warnings() const {
    Any();  // RuntimeError once closed, as every other accessor
    return loaded_.warnings;
  }

 private:
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
  void NotWritingFromController(const char* call) const;
  // The layout of `model`'s robots ("": every robot), refreshed; call with the gate held.
  ModelLayout& Layout(const std::string& model);
  // Reads `model`'s layout with the gate held and calls read(scene, layout).
  template <typename F>
  auto Read(const std::string& model, F&& read);
  // The slots of one named device per robot, and a name per robot for messages.
  std::vector<uint32_t> DeviceColumnSlots(const Scene& scene, const ModelLayout& layout,
                                          const char* type, const std::string& name,
                                          const char* what, std::vector<std::string>* who);
  // The snapshot of the world now (the GIL released while it is packed).
  std::string SnapshotBytes();
  MetricMaps Metrics() { return {&swarm_metrics_, &robot_metrics_, &history_}; }

  // The world file's metrics and any sampled so far (scripts' sim.recordMetric).
  bool IsMetric(const std::string& name) const;
  std::string MetricList() const;
  // robot_metric's KeyError: the robot-level names recorded so far, then the
  // declared swarm-level ones (not read there).
  std::string RobotMetricList() const;
  std::vector<std::string> ModelNames() const;
  bool HasModel(const std::string& model) const;

  // Imports FILE.py as a module of its own and returns FUNCTION from it.
  static py::object LoadFunction(const PythonController& c);

  void TakeMetrics();
  void KeepMetrics(const std::vector<MetricSample>& samples);

  std::unique_ptr<WorldGate> gate_ = std::make_unique<WorldGate>();  // outlives loaded_.world
  LoadedWorld loaded_;
  bool planar_ = true;
  std::string failed_;
  bool reported_ = false;     // failed_ was raised by the step that failed
  bool ran_ = false;          // run() ended the world
  double load_seconds_ = -1;  // the constructor's load, for run()'s summary
  std::vector<std::pair<std::string, std::string>> loaded_overrides_;  // set=, as text
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

}  // namespace swarmsim::python

// World.__new__(World)'s methods raise TypeError (initialized.h).
namespace pybind11::detail {
template <>
class type_caster<swarmsim::python::PyWorld>
    : public swarmsim::python::InitializedCaster<swarmsim::python::PyWorld> {};
}  // namespace pybind11::detail
