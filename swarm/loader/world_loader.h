// Loading a world file (worlds/*.yaml) and the model files it names into a
// placed, not yet started World. The format is described, key by key, in
// worlds/README.md.
//
// Every mistake in a file throws swarmsim::Error with "file:line:column:
// message" (1-based) saying what was expected; unknown keys and names come
// with the nearest known one ("did you mean 'radius'?").
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "framework/world.h"

namespace swarmsim {

class ModuleRegistry;

struct LoadOptions {
  // --set name=value, applied in order. `name` is a world parameter, or
  // `model.parameter` for a model parameter of every copy of that model.
  // The value is read as a YAML scalar (number, true/false, else text) and
  // must have the type of the parameter's value in the file.
  std::vector<std::pair<std::string, std::string>> overrides;
  // How errors name an override, as the user gave it: "--set" (run),
  // "--param" (sweep), "World(set=...)" (Python).
  std::string override_option = "--set";
  std::optional<uint64_t> seed;  // --seed: replaces simulation.seed
  int threads = 0;               // --threads: <= 0 all cores
  // The run's output folder (--out), where sandboxed scripts may write;
  // --trust-scripts lifts the sandbox (WorldSettings).
  std::filesystem::path output_directory;
  bool trust_scripts = false;
  // Folders searched for a plugin the world names without a path
  // (`plugins: [example_plugin]` -> example_plugin.so); the program passes
  // the `plugins/` folder beside its executable.
  std::vector<std::filesystem::path> plugin_directories;
  // --package-path: folders searched for the ROS packages a URDF model's
  // package:// URIs name, after the world's own `package_path`.
  std::vector<std::filesystem::path> package_path;
  // Whether the caller runs `python_controller:` entries (swarm/python does;
  // the program does not, and a world naming one is an error there).
  bool python_controllers = false;
  // Models whose Lua scripts are dropped, every entry's (a Python caller
  // drives them: World(..., controllers=..., keep_scripts=False)).
  std::vector<std::string> drop_scripts;
  // Called now and then while the world loads (between model copies); may
  // throw swarmsim::Error to abandon the load (the program's stop signals).
  // Empty: never.
  std::function<void()> check_stop;
  // Called with a line as a slow part of the load starts (a mesh file of
  // 8 MiB or more: "reading mesh file 'rock.stl' (62 MiB)"); the program
  // prints it on stderr. Empty: not said.
  std::function<void(const std::string&)> note;
  // What a large world's load is doing, for a progress line (the program
  // prints one on stderr), over every models entry. Empty: never told.
  //   kPlacing: `done` copies of `total` placed (every 4,096, and after the
  //     last; the copies of `distribute` entries drawn at random);
  //   kPopulating: `done` bytes of the `total` bytes of the copies' arrays
  //     populated (framework/prefault.h; now and then, and after the last);
  //   kBuilding: `done` copies of `total` built (every 256, and after the
  //     last; every copy).
  // Always called on the thread that loads.
  enum class LoadStage { kPlacing, kPopulating, kBuilding };
  std::function<void(LoadStage stage, int64_t done, int64_t total)> progress;
  // --max-memory: bytes the whole process may hold (0: what the machine
  // has). Copies that will not fit end the load with an error
  // (framework/memory_forecast.h); WorldSettings::max_memory for the rest.
  uint64_t max_memory = 0;
};

// A models entry's `python_controller:` (swarm/python runs it; the program
// cannot): a function called once per step with the arrays of all the
// entry's robots.
struct PythonController {
  std::filesystem::path file;  // absolute; empty: the entry has none
  std::string function = "control";
  bool keep_scripts = false;  // false: the model's Lua scripts are dropped
  std::string where;          // "file:line:column" of the key, for messages
};

// What `swarmsim describe` lists about one `models:` entry.
struct ParameterSummary {
  std::string name, value, default_value, unit, range, description;  // range: "[a, b]" or ""
  std::optional<std::pair<double, double>> bounds;                   // the range's [min, max]
};
struct ModelSummary {
  std::string name;  // "footbot"
  std::string file;  // the model file, as the world names it
  int64_t count = 0;
  std::vector<ParameterSummary> parameters;                // values of every copy (after --set)
  std::vector<std::pair<int64_t, std::string>> instances;  // copy index -> "name=value, ..."
  // Script files in tree order, each with the objects it is on, as paths
  // from the model root: "bot.lua on :, :/arm (explicit)".
  std::vector<std::string> scripts;
  double scale = 1;            // `scale:` of the entry
  bool spatial_order = false;  // distribute: {order: spatial}: copies numbered along a curve
  // What the model's sections (framework/model_section.h) add to each
  // copy: "ik (2 IK groups)".
  std::vector<std::string> modules;
  std::vector<std::string> imported;  // a URDF model: what was imported (links, joints, meshes)
  PythonController python;            // python_controller:, if any
  std::string native_controller;      // native_controller:, if any
};

struct LoadedWorld {
  std::unique_ptr<World> world;  // placed, not started
  std::filesystem::path file;    // the world file, as given
  // The world's default run length: simulation.steps, or
  // round(simulation.duration / simulation.time_step). Empty if it gives neither.
  std::optional<int64_t> steps;
  // The metrics the world's `metrics:` asked for (already added to the
  // world as modules of kind "metric"), in file order.
  std::vector<std::string> metric_names;
  // The models entries, for `swarmsim describe`.
  std::vector<ModelSummary> models;
  // What may surprise without being an error ("file:line:col: ..."), for the
  // program to print: e.g. an environment map without occupied voxels.
  std::vector<std::string> warnings;
  // The world's `record:` setting: a step record every N steps; 0: not asked for.
  int64_t record_every = 0;
  // The distributed robots' root poses (robot index, world pose) as a load
  // of the same file and options with another seed places them (World.reset,
  // swarm/python/snapshot.h): the loader's parsed files, kept. Throws
  // swarmsim::Error when the copies do not fit with that seed.
  std::function<std::vector<std::pair<int, Pose>>(uint64_t seed)> placement;
};

// Reads `file`, resolves parameters (after `options.overrides`), builds the
// arena, obstacles and model copies, and adds the metrics. A world naming
// `plugins` gets a registry of its own (a copy of `registry` plus the
// plugins), which the World keeps alive. Throws
// swarmsim::Error on any mistake in the files or the options.
LoadedWorld LoadWorld(const std::filesystem::path& file, const LoadOptions& options,
                      const ModuleRegistry& registry);

// The steps of `time_step` in `duration` (s), rounded half up as their
// decimals read (0.15 / 0.1 is 1.4999999999999998 in binary: 2 steps here,
// as 2.55 s of 0.1 s is 26; it was 1 and 25). As a double (it may be huge).
double StepsInDuration(double duration, double time_step);

}  // namespace swarmsim
