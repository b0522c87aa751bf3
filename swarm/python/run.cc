// World.run(): the program's run loop (swarm/run/runner.h) over a world
// loaded from Python, so that worlds whose models name a python_controller
// (which `swarmsim run` refuses) get the same progress, summary table,
// summary.json and metrics.csv (`python3 -m swarmsim run --out DIR`).
#include <pybind11/stl.h>

#include <filesystem>
#include <iostream>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "framework/error.h"
#include "framework/state_hash.h"
#include "framework/utf8.h"
#include "swarm/python/world.h"
#include "swarm/run/file_lock.h"
#include "swarm/run/output_folder.h"
#include "swarm/run/runner.h"

namespace swarmsim::python {

namespace {

// The command that is running, for summary.json: the interpreter's argv.
std::string CommandLine() {
  std::string line = "python3";
  try {
    bool first = true;
    for (const py::handle arg : py::module_::import("sys").attr("argv")) {
      std::string text = py::str(arg).cast<std::string>();
      // `python3 -m swarmsim`: argv[0] is the package's __main__.py.
      const std::filesystem::path path(text);
      if (first && path.filename() == "__main__.py" && path.parent_path().filename() == "swarmsim")
        text = "-m swarmsim";
      line.append(" ").append(text);
      first = false;
    }
  } catch (const py::error_already_set&) {
    // An embedding without sys.argv: the interpreter alone.
  }
  return line;
}

void FlushPythonStreams() {
  py::module_ sys = py::module_::import("sys");
  for (const char* stream : {"stdout", "stderr"}) {
    const py::object s = sys.attr(stream);
    if (!s.is_none()) s.attr("flush")();
  }
}

// Makes `dir` and takes its lock (DIR/.swarmsim-lock, as `swarmsim run
// --out` does) into `lock`; ValueError starting with `what` when the folder
// cannot be made or another run holds it.
void LockOutputFolder(const std::filesystem::path& dir, const std::string& what,
                      std::optional<FileLock>* lock) {
  try {
    CreateOutputFolder(dir);
    lock->emplace((dir / ".swarmsim-lock").string());
  } catch (const Error& e) {
    throw py::value_error(what + ": " + e.what());
  }
  if (!(*lock)->held())
    throw py::value_error(
        what + ": another run" +
        ((*lock)->holder().empty() ? std::string() : " (process " + (*lock)->holder() + ")") +
        " is writing into '" + ValidUtf8(dir.string()) + "'; wait for it to end" +
        (what == "--out" ? "" : ", or pass another out_dir"));
}

}  // namespace

void WriteLoadFailure(const std::string& out, const std::string& world_file,
                      const std::string& error) {
  const std::filesystem::path dir(out);
  std::optional<FileLock> out_lock;
  LockOutputFolder(dir, "--out", &out_lock);
  RunOptions options;
  options.out_dir = dir;
  options.world_file = world_file;
  options.command_line = CommandLine();
  if (const std::string reason = WriteErrorSummary(options, error); !reason.empty())
    throw py::value_error("cannot write '" + ValidUtf8((dir / "summary.json").string()) +
                          "': " + reason);
}

py::dict PyWorld::Run(std::optional<int64_t> steps, const std::optional<std::string>& out,
                      bool quiet, bool hash) {
  NotFromController("run()");
  GateLock lock(gate_.get());
  World& world = Live();
  if (!steps) steps = loaded_.steps;
  if (!steps)
    throw py::value_error("run(): " + file() +
                          " gives no duration (simulation.duration): pass steps=N");
  if (*steps < 0) throw py::value_error("run(): steps must be >= 0, got " + std::to_string(*steps));
  RunOptions options;
  options.steps = *steps;
  options.print_hash = hash;
  options.state_hash = hash || out.has_value();
  options.quiet = quiet;
  options.world_file = file();
  options.command_line = CommandLine();
  options.overrides = loaded_overrides_;
  options.load_seconds = load_seconds_;
  options.on_metrics = [this](const std::vector<MetricSample>& samples) { KeepMetrics(samples); };
  // One run at a time writes into a folder, as with `swarmsim run --out`
  // (the same DIR/.swarmsim-lock), held until the run returns.
  std::optional<FileLock> out_lock;
  if (out) {
    const std::filesystem::path dir(*out);
    LockOutputFolder(dir, "run(out_dir=...)", &out_lock);
    if (const std::string note = RemoveEarlierOutputs(dir); !note.empty())
      std::cerr << "note: " << ValidUtf8(note) << std::endl;
    options.out_dir = dir;
    // A stuck step ends the process without returning here (its lock stayed).
    options.on_stuck_exit = [&out_lock] { out_lock->Release(); };
  }
  FlushPythonStreams();  // before the run's own lines
  RunResult result;
  {
    struct InRun {  // however RunWorld returns
      WorldGate* gate;
      explicit InRun(WorldGate* g) : gate(g) { gate->in_run = true; }
      ~InRun() { gate->in_run = false; }
    } in_run(gate_.get());
    py::gil_scoped_release release;
    result = RunWorld(&world, options, std::cout, std::cerr);
    std::cout.flush();
  }
  ran_ = true;                 // stopped at its end, or failed partway
  if (gate_->interrupted()) {  // a controller's KeyboardInterrupt or SystemExit, as itself
    PyErr_Restore(gate_->interrupt_type.release().ptr(), gate_->interrupt_value.release().ptr(),
                  gate_->interrupt_trace.release().ptr());
    throw py::error_already_set();
  }
  if (!result.ok) {
    failed_ = result.error;
    reported_ = true;
    std::string message = result.error;
    if (options.out_dir && std::filesystem::exists(*options.out_dir / "summary.json"))
      message += "\n" + OutputsOfFinishedSteps(result.steps, *options.out_dir);
    if (result.signal != 0) {  // KeyboardInterrupt, its .signal the number (SIGTERM: 15)
      py::object error =
          py::reinterpret_borrow<py::object>(PyExc_KeyboardInterrupt)(py::str(ValidUtf8(message)));
      error.attr("signal") = result.signal;
      PyErr_SetObject(PyExc_KeyboardInterrupt, error.ptr());
      throw py::error_already_set();
    }
    throw std::runtime_error(message);
  }
  py::dict figures;
  figures["steps"] = result.steps;
  figures["wall_seconds"] = result.wall_seconds;
  figures["start_seconds"] = result.start_seconds;
  figures["peak_rss_mb"] = result.peak_rss_mb;
  figures["state_hash"] = options.state_hash
                              ? py::object(py::str(StateHasher::ToHex(result.state_hash)))
                              : py::object(py::none());
  return figures;
}

}  // namespace swarmsim::python
