// The Python binding (`import swarmsim`): load a world file, step it, read
// the swarm as numpy arrays, and drive whole models from one vectorised
// Python function per step (a models entry's `python_controller:`).
//
// This file holds the module's bindings and step_worlds; swarmsim.World is
// world.h, swarmsim.Robots and the controllers controller.h, the arrays
// arrays.h, sensor_arrays.h, ir_arrays.h and writers.h. pybind11 and numpy
// types stay in swarm/python/. Every array handed to Python is a copy
// gathered from the scene (robots' objects are scattered through its slots,
// so no strided view exists), made into a buffer the caller may pass back
// (`out=`) to avoid the allocation.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <exception>
#include <map>
#include <memory>
#include <new>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "framework/math.h"
#include "framework/scheduler.h"
#include "framework/utf8.h"
#include "swarm/python/controller.h"
#include "swarm/python/world.h"
#include "swarm/run/huge_pages.h"

namespace py = pybind11;

namespace swarmsim::python {
namespace {

// --- Whole-number arguments -------------------------------------------------------------

// Is `value` an integer as the README promises (int, a numpy integer: it
// has __index__), not a bool (Python's bool is an int, which pybind11 takes)?
bool IsInteger(const py::handle& value) {
  return !py::isinstance<py::bool_>(value) && PyIndex_Check(value.ptr()) != 0;
}
std::string TypeName(const py::handle& value) {
  return py::str(py::type::of(value).attr("__name__")).cast<std::string>();
}

// A count: TypeError for a bool, float or text, ValueError past 2^63 - 1.
int64_t IntArg(const py::handle& value, const std::string& what) {
  if (!IsInteger(value)) throw py::type_error(what + " must be an integer, not " + TypeName(value));
  try {
    return value.cast<int64_t>();
  } catch (const py::cast_error&) {
    throw py::value_error(what + " is out of range (at most 2^63 - 1), got " +
                          py::str(value).cast<std::string>());
  }
}

// A thread count: an integer from 0 (every core) to kMaxThreads.
int ThreadsArg(const py::object& value, const char* where) {
  const int64_t threads = IntArg(value, std::string(where) + ": threads");
  CheckThreads(threads, where);
  return static_cast<int>(threads);
}

// A {name: value} argument (set=, controllers=): None is none, anything
// but a dict with text keys a TypeError naming the argument (pybind11's own
// "incompatible function arguments" said neither which nor why).
std::map<std::string, py::object> NameMap(const py::object& value, const std::string& what) {
  std::map<std::string, py::object> out;
  if (value.is_none()) return out;
  if (!py::isinstance<py::dict>(value))
    throw py::type_error(what + " must be a dict of {name: value}, not " + TypeName(value));
  for (const auto& [key, item] : py::reinterpret_borrow<py::dict>(value)) {
    if (!py::isinstance<py::str>(key))
      throw py::type_error(what + ": the key " + py::repr(key).cast<std::string>() +
                           " is not a name (a str)");
    out[key.cast<std::string>()] = py::reinterpret_borrow<py::object>(item);
  }
  return out;
}

// A seed: None (the world's own) or an integer from 0 to 2^64 - 1.
std::optional<uint64_t> SeedArg(const py::object& value, const std::string& what) {
  if (value.is_none()) return std::nullopt;
  if (!IsInteger(value))
    throw py::type_error(what + " must be None or an integer from 0 to 18446744073709551615, not " +
                         TypeName(value));
  const py::int_ number = py::reinterpret_steal<py::int_>(PyNumber_Index(value.ptr()));
  const unsigned long long seed = PyLong_AsUnsignedLongLong(number.ptr());
  if (PyErr_Occurred() != nullptr) {
    PyErr_Clear();
    throw py::value_error(what + " must be from 0 to 18446744073709551615, got " +
                          number.attr("__str__")().cast<std::string>());
  }
  return static_cast<uint64_t>(seed);
}

// --- File paths -----------------------------------------------------------------------

// A file path as Python gives one: str (a name that is not UTF-8 arrives
// with surrogate escapes, as os.listdir returns it), bytes or any os.PathLike,
// turned into the file system's bytes by os.fsencode.
std::string FsPath(const py::handle& value, const std::string& what) {
  if (py::isinstance<py::bytes>(value)) return value.cast<std::string>();
  try {
    return py::module_::import("os").attr("fsencode")(value).cast<std::string>();
  } catch (const py::error_already_set& e) {
    if (!e.matches(PyExc_TypeError)) throw;
    throw py::type_error(what + " must be a path (str, bytes or os.PathLike), not " +
                         TypeName(value));
  }
}
std::vector<std::string> FsPaths(const py::handle& value, const std::string& what) {
  if (py::isinstance<py::str>(value) || py::isinstance<py::bytes>(value) ||
      !py::isinstance<py::sequence>(value))
    throw py::type_error(what + " must be a list of paths, not " + TypeName(value));
  std::vector<std::string> paths;
  for (const py::handle item : value) paths.push_back(FsPath(item, what + " entries"));
  return paths;
}

// --- Error text ---------------------------------------------------------------------------

// Messages quote world files, scripts and file names, whose bytes may not be
// UTF-8; Python's exception text must be, and one that is not would arrive
// empty (PyErr_SetString fails to decode it). Such a message is raised with
// each invalid sequence replaced by U+FFFD, as the program prints it; the
// exception types are pybind11's (a registered translator runs first).
void SetErrorText(PyObject* type, const char* what) {
  PyErr_SetString(type, ValidUtf8(what).c_str());
}
PyObject* StandardErrorType(const std::exception& e) {
  if (dynamic_cast<const std::bad_alloc*>(&e) != nullptr) return PyExc_MemoryError;
  if (dynamic_cast<const std::out_of_range*>(&e) != nullptr) return PyExc_IndexError;
  if (dynamic_cast<const std::overflow_error*>(&e) != nullptr) return PyExc_OverflowError;
  if (dynamic_cast<const std::invalid_argument*>(&e) != nullptr ||
      dynamic_cast<const std::domain_error*>(&e) != nullptr ||
      dynamic_cast<const std::length_error*>(&e) != nullptr ||
      dynamic_cast<const std::range_error*>(&e) != nullptr)
    return PyExc_ValueError;
  return PyExc_RuntimeError;
}
void TranslateNonUtf8Messages(std::exception_ptr error) {
  try {
    if (error) std::rethrow_exception(error);
  } catch (const py::error_already_set&) {
    throw;  // a Python exception already
  } catch (const py::builtin_exception& e) {
    if (IsValidUtf8(e.what())) throw;
    e.set_error();  // sets the type (its text failed to decode)
    PyObject* type = PyErr_Occurred();
    Py_XINCREF(type);
    SetErrorText(type != nullptr ? type : PyExc_RuntimeError, e.what());
    Py_XDECREF(type);
  } catch (const std::exception& e) {
    if (IsValidUtf8(e.what())) throw;
    SetErrorText(StandardErrorType(e), e.what());
  }
}

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
void StepWorlds(const py::sequence& worlds, const py::object& count,
                const py::object& threads_arg) {
  const int64_t n = IntArg(count, "step_worlds(n): n");
  if (n < 0) throw py::value_error("step_worlds: n must be >= 0, got " + std::to_string(n));
  const int threads = ThreadsArg(threads_arg, "step_worlds");
  const size_t k = py::len(worlds);
  std::vector<PyWorld*> list(k);
  std::map<PyWorld*, size_t> seen;
  for (size_t i = 0; i < k; ++i) {
    py::object item = worlds[i];
    if (!py::isinstance<PyWorld>(item))
      throw py::type_error("step_worlds: worlds[" + std::to_string(i) + "] is a " +
                           std::string(py::str(py::type::of(item).attr("__name__"))) +
                           ", not a swarmsim.World");
    try {
      list[i] = item.cast<PyWorld*>();
    } catch (const py::type_error& e) {  // made by World.__new__ alone (initialized.h)
      throw py::type_error("step_worlds: worlds[" + std::to_string(i) + "]: " + e.what());
    }
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
  // This call's mark on its gates, taken off before they are unlocked.
  static std::atomic<uint64_t> calls{0};
  struct Marks {
    const std::vector<PyWorld*>& worlds;
    ~Marks() {
      for (PyWorld* w : worlds) w->gate()->stepping_call.store(0);
    }
  } marks{order};
  const uint64_t call = ++calls;
  for (PyWorld* w : order) w->gate()->stepping_call.store(call);
  for (size_t i = 0; i < k; ++i) {
    try {
      list[i]->Live();
    } catch (const std::runtime_error& e) {
      throw std::runtime_error(name(i) + e.what());
    }
  }
  // In rounds of a few steps each (as many as take about 0.1 s): between
  // rounds, with the GIL, Ctrl-C is seen (Lua worlds never see Python's
  // signals) and a controller's KeyboardInterrupt stops every world, not
  // only its own. A world steps the same whatever the rounds.
  TaskScheduler& scheduler = WorldsScheduler(threads);
  std::optional<py::error_already_set> signal;
  for (int64_t done = 0, chunk = 1; done < n;) {
    const int64_t steps = std::min(chunk, n - done);
    const auto start = std::chrono::steady_clock::now();
    {
      py::gil_scoped_release release;
      scheduler.ParallelFor(0, static_cast<int64_t>(k), 1, [&](int64_t b, int64_t e) {
        for (int64_t i = b; i < e; ++i) list[i]->RunSteps(steps);
      });
    }
    done += steps;
    if (std::chrono::steady_clock::now() - start < std::chrono::milliseconds(100) &&
        chunk < (int64_t{1} << 40))
      chunk *= 2;
    if (PyErr_CheckSignals() != 0) {
      signal.emplace();  // takes the pending KeyboardInterrupt (or the handler's error)
      break;
    }
    if (std::any_of(list.begin(), list.end(), [](PyWorld* w) { return w->gate()->interrupted(); }))
      break;
  }
  // Metrics of every world, then Ctrl-C, or the first world's interrupt or error.
  std::exception_ptr first;
  for (size_t i = 0; i < k; ++i) {
    try {
      list[i]->FinishSteps(name(i));
    } catch (...) {
      if (!first) first = std::current_exception();
    }
  }
  if (signal) {
    PyErr_Clear();
    throw *signal;
  }
  if (first) std::rethrow_exception(first);
  if (PyErr_CheckSignals() != 0) throw py::error_already_set();
}

}  // namespace
}  // namespace swarmsim::python

PYBIND11_MODULE(_swarmsim, m) {
  using swarmsim::python::PyWorld;
  m.doc() = "swarmsim: load a world, step it, read and drive the swarm with numpy";
  py::register_exception_translator(&swarmsim::python::TranslateNonUtf8Messages);
  // Scripts run on Python's thread too: its stack as the program's (a low
  // ulimit -s, raised where allowed, so that deep C recursion in a script
  // is its error, not a segfault).
  (void)swarmsim::RoomForDeepCalls();
  // m, the largest coordinate a world may use (framework/math.h): set_poses's bound.
  m.attr("MAX_COORDINATE") = swarmsim::kMaxCoordinate;

  // --- Robots: what a controller receives (controller.cc) --------------------------------
  swarmsim::python::BindRobots(m);

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
      .def(py::init([](const py::object& path, const py::object& seed, const py::object& set,
                       const py::object& threads, const py::object& controllers,
                       const py::object& package_path, bool keep_scripts) {
             return std::make_unique<PyWorld>(
                 swarmsim::python::FsPath(path, "World(path)"),
                 swarmsim::python::SeedArg(seed, "World(seed=...)"),
                 swarmsim::python::NameMap(set, "World(set=...)"),
                 swarmsim::python::ThreadsArg(threads, "World(threads=...)"),
                 swarmsim::python::NameMap(controllers, "World(controllers=...)"),
                 swarmsim::python::FsPaths(package_path, "World(package_path=...)"), keep_scripts);
           }),
           py::arg("path"), py::arg("seed") = py::none(), py::arg("set") = py::dict(),
           py::arg("threads") = py::int_(0), py::arg("controllers") = py::dict(),
           py::arg("package_path") = py::list(), py::arg("keep_scripts") = true)
      // Stepping and state.
      .def(
          "run",
          [](PyWorld& w, const py::object& steps, const py::object& out_dir, bool quiet,
             bool hash) {
            std::optional<int64_t> n;
            if (!steps.is_none()) n = swarmsim::python::IntArg(steps, "run(steps)");
            std::optional<std::string> dir;
            if (!out_dir.is_none()) dir = swarmsim::python::FsPath(out_dir, "run(out_dir=...)");
            return w.Run(n, dir, quiet, hash);
          },
          py::arg("steps") = py::none(), py::arg("out_dir") = py::none(), py::arg("quiet") = false,
          py::arg("hash") = false,
          "Runs the world as `swarmsim run` does: steps (None: the world's duration), a\n"
          "progress bar and summary table on stderr/stdout unless quiet, 'state-hash: ...'\n"
          "printed when hash, and with out_dir (a folder, made if missing) summary.json and\n"
          "metrics.csv written as the run goes (one run at a time writes into a folder:\n"
          "ValueError while another run, here or `swarmsim run --out`, holds it). The\n"
          "world is stopped at the end (its\n"
          "scripts' cleanups run): it can be read, not stepped. Returns {steps,\n"
          "wall_seconds, start_seconds, peak_rss_mb, state_hash}; raises RuntimeError for\n"
          "the run's error (its outputs written) and KeyboardInterrupt for Ctrl-C.")
      .def(
          "step",
          [](PyWorld& w, const py::object& n) {
            w.Step(swarmsim::python::IntArg(n, "step(n): n"));
          },
          py::arg("n") = 1,
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
           "readings are rows offsets[i] to offsets[i+1]-1, nearest first. ValueError when\n"
           "none of the model's robots has a board.")
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
      .def_property_readonly("metric_names", &PyWorld::metric_names,
                             "The swarm-level metrics the world declares (its metrics:), in\n"
                             "order; robot-level ones are whatever the robots record.")
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
      .def(
          "reset",
          [](PyWorld& w, const py::object& seed) {
            w.reset(swarmsim::python::SeedArg(seed, "reset(seed)"));
          },
          py::arg("seed") = py::none(),
          "Back, in place, to the state a fresh load with `seed` (None: the world's own)\n"
          "leaves: robots placed as the loader places them with that seed, every random\n"
          "stream from it. No file is read again.")
      .def(py::pickle([](PyWorld& w) { return w.getstate(); }, &PyWorld::setstate));

  m.def("_write_load_failure", &swarmsim::python::WriteLoadFailure, py::arg("out_dir"),
        py::arg("world"), py::arg("error"),
        "For python3 -m swarmsim run: summary.json (status error) in out_dir for a world that "
        "did not load.");
  m.def("step_worlds", &swarmsim::python::StepWorlds, py::arg("worlds"), py::arg("n") = 1,
        py::arg("threads") = py::int_(0),
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
