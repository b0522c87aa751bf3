// The swarmsim command-line program.
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <cmath>
#include <filesystem>
#include <iostream>

#include "framework/error.h"
#include "framework/plugin_loader.h"
#include "framework/registry.h"
#include "modules/builtin.h"
#include "swarm/bench.h"
#include "swarm/bench_scaling.h"
#include "swarm/report.h"
#include "swarm/results_merge.h"
#include "swarm/runner.h"
#include "swarm/sweep.h"
#include "swarm/version.h"
#include "swarm/world_loader.h"

namespace swarmsim {
namespace {

// CLI11's own range checks print the whole double range; these say it plainly.
CLI::Validator NumberCheck(bool allow_zero) {
  return CLI::Validator(
      [allow_zero](std::string& text) -> std::string {
        double value = 0;
        try {
          size_t used = 0;
          value = std::stod(text, &used);
          if (used != text.size()) throw std::invalid_argument(text);
        } catch (const std::exception&) {
          return "expected a number, got '" + text + "'";
        }
        if (allow_zero ? !(value >= 0) : !(value > 0))
          return std::string("must be ") + (allow_zero ? ">= 0" : "> 0") + ", got " + text;
        return "";
      },
      allow_zero ? "NUMBER >= 0" : "NUMBER > 0");
}
const CLI::Validator kNonNegative = NumberCheck(true);
const CLI::Validator kPositive = NumberCheck(false);

constexpr int kExitRunError = 1;  // the run failed (script error, physics, outputs)
constexpr int kExitBadInput = 2;  // bad command line or world file

// Where a world's `plugins: [name]` are looked for: plugins/ beside the
// program (the build tree), and lib/swarmsim/plugins of an installed one.
std::vector<std::filesystem::path> PluginDirectories() {
  std::error_code ec;
  const std::filesystem::path exe = std::filesystem::read_symlink("/proc/self/exe", ec);
  if (ec) return {};
  return {exe.parent_path() / "plugins", exe.parent_path().parent_path() / "lib/swarmsim/plugins"};
}

std::vector<std::pair<std::string, std::string>> ParseSets(const std::vector<std::string>& sets) {
  std::vector<std::pair<std::string, std::string>> out;
  for (const std::string& s : sets) {
    const size_t eq = s.find('=');
    if (eq == std::string::npos || eq == 0)
      throw Error("--set expects name=value, got '" + s + "'");
    out.emplace_back(s.substr(0, eq), s.substr(eq + 1));
  }
  return out;
}

// swarmsim describe: the world's settings, then each models entry.
void PrintDescription(const LoadedWorld& w, std::ostream& out) {
  const WorldSettings& s = w.world->settings();
  out << "world: " << s.file << "\n"
      << "physics: " << s.physics << ", time step " << s.time_step << " s, seed " << s.seed << "\n"
      << "main script: " << (s.main_script ? s.main_script->path : "(default step)") << "\n";
  if (!w.world->parameters().empty()) {
    out << "world parameters:\n";
    for (const auto& [name, value] : w.world->parameters())
      out << "  " << name << " = " << ParamToString(value) << "\n";
  }
  for (const ModelSummary& m : w.models) {
    out << "\nmodel " << m.name << " (" << m.file << "): " << m.count
        << (m.count == 1 ? " copy" : " copies") << "\n";
    for (const std::string& script : m.scripts) out << "  script: " << script << "\n";
    if (m.ik_groups > 0) out << "  module: ik (" << m.ik_groups << " IK groups)\n";
    if (m.parameters.empty()) out << "  parameters: none\n";
    for (const ParameterSummary& p : m.parameters) {
      out << "  " << m.name << "." << p.name << " = " << p.value;
      if (!p.unit.empty()) out << " " << p.unit;
      out << "  (default " << p.default_value;
      if (!p.range.empty()) out << ", range " << p.range;
      out << ")";
      if (!p.description.empty()) out << "  " << p.description;
      out << "\n";
    }
    for (const auto& [index, values] : m.instances)
      out << "  copy " << index << " of this entry: " << (values.empty() ? "(as above)" : values)
          << "\n";
  }
}

int Main(int argc, char** argv) {
  CLI::App app{"swarmsim " + std::string(Version()) +
               ": a headless, swarm-scale robot simulator.\n"
               "Lua-controlled robot models, copied by the thousand, stepped in parallel."};
  app.require_subcommand(1);
  app.set_version_flag("--version", Version());

  // run
  CLI::App* run = app.add_subcommand("run", "Run a world and print a summary");
  std::string world_file;
  int64_t steps = -1;
  double duration = -1;
  int threads = 0;
  std::optional<uint64_t> seed;
  std::vector<std::string> sets;
  std::string out_dir;
  bool hash = false, quiet = false;
  bool trust_scripts = false;
  std::vector<std::string> plugins;
  run->add_option("world", world_file, "World file (YAML)")->required();
  auto* steps_opt =
      run->add_option("--steps", steps, "Number of control steps to run")->check(kNonNegative);
  run->add_option("--duration", duration, "Simulated seconds to run")
      ->check(kNonNegative)
      ->excludes(steps_opt);
  run->add_option("--threads", threads, "Worker threads (default: all cores)")
      ->check(CLI::Validator(
          [](std::string& text) -> std::string {
            try {
              size_t used = 0;
              const long n = std::stol(text, &used);
              if (used == text.size() && n >= 1 && n <= 1024) return "";
            } catch (const std::exception&) {
            }
            return "expected a whole number from 1 to 1024, got '" + text + "'";
          },
          "1..1024"));
  run->add_option("--seed", seed, "Random seed (overrides the world's)");
  run->add_option("--set", sets, "Override a parameter: name=value or model.name=value")
      ->allow_extra_args(false);
  run->add_option("--out", out_dir, "Write summary.json and metrics.csv to this folder");
  run->add_flag("--hash", hash, "Print the final state hash");
  run->add_flag("--quiet", quiet, "No progress bar and no summary table");
  run->add_option("--plugin", plugins, "Load a plugin (shared library) before the world")
      ->allow_extra_args(false);
  run->add_flag("--trust-scripts", trust_scripts,
                "Lift the script sandbox: full Lua libraries (os, io, debug, package)");

  // bench
  CLI::App* bench = app.add_subcommand("bench", "Measure robot-ticks/s over robots x threads");
  BenchOptions bench_options;
  std::string bench_child_config;
  int bench_child_robots = 0, bench_child_threads = 1;
  bench->add_option("--robots", bench_options.robots, "Robot counts, e.g. 100,1000,10000")
      ->delimiter(',');
  bench->add_option("--threads", bench_options.threads, "Thread counts, e.g. 1,2")->delimiter(',');
  bench->add_option("--steps", bench_options.steps, "Measured steps per configuration")
      ->check(kPositive);
  bench->add_option("--csv", bench_options.csv, "Write one CSV row per measurement");
  bench->add_option("--world", bench_options.world, "World to measure");
  bench->add_option("--child", bench_child_config)->group("");  // internal: one config
  bench->add_option("--child-robots", bench_child_robots)->group("");
  bench->add_option("--child-threads", bench_child_threads)->group("");
  ScalingOptions scaling_options;  // bench --scaling (issue 5)
  bool bench_scaling = false;
  bench->add_flag("--scaling", bench_scaling,
                  "Speed-up over threads 1..cores and sweep --jobs 1..cores; CSV + PNG");
  bench->add_option("--jobs", scaling_options.jobs, "With --scaling: sweep jobs, e.g. 1,2")
      ->delimiter(',');
  bench->add_option("--sweep-runs", scaling_options.sweep_runs, "With --scaling: runs per sweep")
      ->check(kPositive);
  bench->add_option("--plot", scaling_options.plot, "With --scaling: the PNG plot")
      ->capture_default_str();

  // sweep, report, merge (issue 5)
  CLI::App* sweep = app.add_subcommand("sweep", "Run a world over a grid of parameters x seeds");
  SweepOptions sweep_options;
  std::string sweep_shard;
  int64_t sweep_steps = -1;
  double sweep_duration = -1;
  sweep->add_option("world", sweep_options.world, "World file (YAML)")->required();
  sweep
      ->add_option("--param", sweep_options.params,
                   "NAME=SPEC: a list 100,200,400, a range A:B:N or a log range log:A:B:N")
      ->allow_extra_args(false);
  sweep->add_option("--seeds", sweep_options.seeds, "K (seeds 1..K), A-B, or a list 3,7,11")
      ->capture_default_str();
  auto* sweep_steps_opt =
      sweep->add_option("--steps", sweep_steps, "Control steps per run")->check(kNonNegative);
  sweep->add_option("--duration", sweep_duration, "Simulated seconds per run")
      ->check(kNonNegative)
      ->excludes(sweep_steps_opt);
  sweep->add_option("--jobs", sweep_options.jobs, "Concurrent runs (default: all cores)")
      ->check(kPositive);
  sweep->add_option("--threads", sweep_options.threads_per_run, "Threads per run")
      ->check(kPositive)
      ->capture_default_str();
  sweep->add_option("--timeout", sweep_options.timeout_s, "Per-run time limit, s (0: none)")
      ->check(kNonNegative);
  sweep->add_option("--db", sweep_options.db, "Results database (SQLite)")->required();
  sweep->add_flag("--allow-changed-world", sweep_options.allow_changed_world,
                  "Resume even though the world file changed since the sweep began");
  sweep->add_flag("--retry-failed", sweep_options.retry_failed, "Run failed runs again");
  sweep->add_option("--shard", sweep_shard, "i/n: only runs with id % n == i (Slurm arrays)");
  sweep->add_flag("--mpi", sweep_options.mpi, "Share the runs between MPI ranks (under mpirun)");
  sweep->add_flag("--quiet", sweep_options.quiet, "No progress");

  CLI::App* report = app.add_subcommand("report", "Tables, CSV and a plot from a sweep database");
  ReportOptions report_options;
  std::string report_csv, report_plot;
  report->add_option("db", report_options.db, "Results database")->required();
  report->add_option("--x", report_options.x, "Parameter on the x axis");
  report->add_option("--y", report_options.y, "Metric");
  report->add_option("--by", report_options.by, "One plot line per value of this parameter");
  report->add_option("--csv", report_csv, "Write one row per run");
  report->add_option("--plot", report_plot, "Write a PNG plot (gnuplot)");

  CLI::App* merge = app.add_subcommand("merge", "Merge sweep databases (shards) into one");
  std::string merge_out;
  std::vector<std::string> merge_inputs;
  bool merge_allow_changed = false;
  merge->add_option("out", merge_out, "Output database (created if missing)")->required();
  merge->add_option("inputs", merge_inputs, "Input databases")->required();
  merge->add_flag("--allow-changed-world", merge_allow_changed,
                  "Merge runs made with different versions of the world file");

  CLI::App* modules = app.add_subcommand("modules", "List the registered modules");
  CLI::App* describe =
      app.add_subcommand("describe", "List a world's models, their parameters and scripts");
  std::string describe_world;
  std::vector<std::string> describe_sets;
  describe->add_option("world", describe_world, "World file (YAML)")->required();
  describe
      ->add_option("--set", describe_sets, "Override a parameter: name=value or model.name=value")
      ->allow_extra_args(false);
  CLI::App* version = app.add_subcommand("version", "Print the version");

  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    app.exit(e);
    return kExitBadInput;
  }

  ModuleRegistry registry;
  RegisterBuiltinModules(&registry);

  if (*version) {
    std::cout << "swarmsim " << Version() << "\n";
    return 0;
  }
  if (*describe) {
    LoadOptions describe_load;
    describe_load.overrides = ParseSets(describe_sets);
    describe_load.plugin_directories = PluginDirectories();
    try {
      const LoadedWorld w = LoadWorld(describe_world, describe_load, registry);
      PrintDescription(w, std::cout);
    } catch (const Error& e) {
      std::cerr << "error: " << e.what() << "\n";
      return kExitBadInput;
    }
    return 0;
  }
  if (*modules) {
    for (const ModuleInfo& m : registry.modules())
      std::cout << m.kind << "\t" << m.name << "\t" << m.version << "\t" << m.description << "\n";
    return 0;
  }
  if (*sweep) {
    if (sweep_steps >= 0) sweep_options.steps = sweep_steps;
    if (sweep_duration >= 0) sweep_options.duration = sweep_duration;
    if (!sweep_shard.empty())
      ParseShard(sweep_shard, &sweep_options.shard_index, &sweep_options.shard_count);
    for (int i = 0; i < argc; ++i)
      sweep_options.command_line += (i ? " " : "") + std::string(argv[i]);
    return RunSweep(sweep_options, std::cout, std::cerr);
  }
  if (*report) {
    if (!report_csv.empty()) report_options.csv = report_csv;
    if (!report_plot.empty()) report_options.plot = report_plot;
    return RunReport(report_options, std::cout, std::cerr);
  }
  if (*merge) return RunMerge(merge_out, merge_inputs, merge_allow_changed, std::cout, std::cerr);
  if (*bench) {
    bench_options.self_exe = "/proc/self/exe";
    if (bench_scaling) {
      scaling_options.bench = bench_options;
      scaling_options.threads_given = bench->count("--threads") > 0;
      if (bench_options.csv) scaling_options.csv = *bench_options.csv;
      return RunScalingBench(scaling_options, std::cout, std::cerr);
    }
    if (!bench_child_config.empty())
      return RunBenchChild(bench_options, bench_child_config, bench_child_robots,
                           bench_child_threads, std::cout);
    return RunBench(bench_options, std::cout, std::cerr);
  }

  // run
  LoadOptions load;
  load.overrides = ParseSets(sets);
  load.seed = seed;
  load.threads = threads;
  if (!out_dir.empty()) load.output_directory = out_dir;
  load.trust_scripts = trust_scripts;
  load.plugin_directories = PluginDirectories();
  LoadedWorld loaded;
  try {
    for (const std::string& plugin : plugins) LoadPlugin(plugin, &registry);
    loaded = LoadWorld(world_file, load, registry);
  } catch (const Error& e) {
    std::cerr << "error: " << e.what() << "\n";
    return kExitBadInput;
  }
  RunOptions options;
  if (steps >= 0) {
    options.steps = steps;
  } else if (duration >= 0) {
    const double step_count = std::round(duration / loaded.world->settings().time_step);
    if (!(step_count <= 1e15)) {
      std::cerr << "error: --duration " << duration << " s is " << step_count << " steps of "
                << loaded.world->settings().time_step << " s; at most 1e15 steps\n";
      return kExitBadInput;
    }
    options.steps = static_cast<int64_t>(step_count);
  } else if (loaded.steps) {
    options.steps = *loaded.steps;
  } else {
    std::cerr << "error: " << world_file
              << " gives no run length; pass --steps N or --duration SECONDS\n";
    return kExitBadInput;
  }
  if (!out_dir.empty()) options.out_dir = out_dir;
  options.print_hash = hash;
  options.quiet = quiet;
  options.world_file = world_file;
  for (int i = 0; i < argc; ++i) options.command_line += (i ? " " : "") + std::string(argv[i]);
  const RunResult result = RunWorld(loaded.world.get(), options, std::cout, std::cerr);
  if (!result.ok) {
    std::cerr << "error: " << result.error << "\n";
    if (options.out_dir && std::filesystem::is_directory(*options.out_dir))
      std::cerr << "outputs up to step " << result.steps << " are in " << options.out_dir->string()
                << "\n";
    return kExitRunError;
  }
  return 0;
}

}  // namespace
}  // namespace swarmsim

int main(int argc, char** argv) {
  try {
    return swarmsim::Main(argc, argv);
  } catch (const swarmsim::Error& e) {
    std::cerr << "error: " << e.what() << "\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "error: " << e.what() << "\n";
    return 1;
  }
}
