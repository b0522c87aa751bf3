// swarmsim run WORLD: load the world, decide the run length, run it.
#include <CLI/CLI.hpp>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <sstream>

#include "framework/error.h"
#include "framework/plugin_loader.h"
#include "framework/registry.h"
#include "framework/utf8.h"
#include "swarm/cli/commands.h"
#include "swarm/cli/options.h"
#include "swarm/loader/world_loader.h"
#include "swarm/run/runner.h"

namespace swarmsim::cli {
namespace {

// The number of steps: --steps, else --duration rounded to whole time steps,
// else the world's own; nullopt and `*error` set when none fits.
std::optional<int64_t> RunLength(const RunArgs& args, const LoadedWorld& loaded,
                                 std::string* error) {
  if (args.steps >= 0) return args.steps;
  if (args.duration >= 0) {
    // The nearest whole number of steps; a duration under one step would run none.
    const double time_step = loaded.world->settings().time_step;
    if (args.duration > 0 && args.duration < time_step) {
      std::ostringstream message;
      message << "--duration " << args.duration << " s is shorter than one time step (" << time_step
              << " s)";
      *error = message.str();
      return std::nullopt;
    }
    const double step_count = std::round(args.duration / time_step);
    if (!(step_count <= 1e15)) {
      std::ostringstream message;
      message << "--duration " << args.duration << " s is " << step_count << " steps of "
              << time_step << " s; at most 1e15 steps";
      *error = message.str();
      return std::nullopt;
    }
    return static_cast<int64_t>(step_count);
  }
  if (loaded.steps) return *loaded.steps;
  *error = args.world_file + " gives no run length; pass --steps N or --duration SECONDS";
  return std::nullopt;
}

}  // namespace

CLI::App* AddRunCommand(CLI::App* app, RunArgs* args) {
  CLI::App* run = app->add_subcommand("run", "Run a world and print a summary");
  run->add_option("world", args->world_file, "World file (YAML)")->required();
  auto* steps_opt = run->add_option("--steps", args->steps, "Number of control steps to run")
                        ->transform(WholeNumberCheck(0, kInt64Max, "steps"));
  run->add_option("--duration", args->duration,
                  "Simulated seconds to run, rounded to the nearest whole number of time steps "
                  "(less than one step is an error)")
      ->check(NonNegativeCheck())
      ->excludes(steps_opt);
  run->add_option("--threads", args->threads, "Worker threads (default: all cores)")
      ->transform(ThreadCountCheck());
  run->add_option("--seed", args->seed, "Random seed (overrides the world's)")
      ->transform(SeedCheck());
  run->add_option("--set", args->sets,
                  "Override a parameter (world NAME or MODEL.NAME); repeat for more: "
                  "--set a=1 --set b=2")
      ->option_text("NAME=VALUE")
      ->allow_extra_args(false);
  run->add_option("--out", args->out_dir, "Write summary.json and metrics.csv to this folder")
      ->check(NonEmpty("a folder"));
  run->add_flag("--hash", args->hash, "Print the final state hash");
  run->add_flag("--quiet", args->quiet, "No progress bar and no summary table");
  run->add_option("--plugin", args->plugins, "Load a plugin (shared library) before the world")
      ->allow_extra_args(false);
  run->add_flag("--trust-scripts", args->trust_scripts,
                "Lift the script sandbox: full Lua libraries (os, io, debug, package)");
  return run;
}

int RunCommand(const RunArgs& args, const std::string& command_line, ModuleRegistry* registry) {
  RunOptions options;
  if (!args.out_dir.empty()) options.out_dir = args.out_dir;
  options.world_file = args.world_file;
  options.command_line = command_line;
  // A world that does not load (or does not fit the command line): with
  // --out, summary.json says so too, for a batch system watching the folder.
  const auto bad_input = [&](const std::string& message) {
    std::cerr << "error: " << swarmsim::ValidUtf8(message) << "\n";
    if (options.out_dir && !WriteErrorSummary(options, message))
      std::cerr << "error: cannot write '" << (*options.out_dir / "summary.json").string() << "'\n";
    return kExitBadInput;
  };
  LoadOptions load;
  load.seed = args.seed;
  load.threads = args.threads;
  if (!args.out_dir.empty()) load.output_directory = args.out_dir;
  load.trust_scripts = args.trust_scripts;
  load.plugin_directories = PluginDirectories();
  LoadedWorld loaded;
  try {
    load.overrides = ParseSets(args.sets);
    options.overrides = load.overrides;
    for (const std::string& plugin : args.plugins) LoadPlugin(plugin, registry);
    loaded = LoadWorld(args.world_file, load, *registry);
  } catch (const Error& e) {
    return bad_input(e.what());
  }
  for (const std::string& warning : loaded.warnings)
    std::cerr << "warning: " << swarmsim::ValidUtf8(warning) << "\n";
  std::string length_error;
  const std::optional<int64_t> steps = RunLength(args, loaded, &length_error);
  if (!steps) return bad_input(length_error);
  options.steps = *steps;
  options.print_hash = args.hash;
  options.quiet = args.quiet;
  const RunResult result = RunWorld(loaded.world.get(), options, std::cout, std::cerr);
  if (!result.ok) {
    std::cerr << "error: " << swarmsim::ValidUtf8(result.error) << "\n";
    if (options.out_dir && std::filesystem::is_directory(*options.out_dir))
      std::cerr << "outputs up to step " << result.steps << " are in " << options.out_dir->string()
                << "\n";
    // The shell's convention for a run ended by a signal: 128 + its number.
    return result.signal != 0 ? 128 + result.signal : kExitRunError;
  }
  return 0;
}

}  // namespace swarmsim::cli
