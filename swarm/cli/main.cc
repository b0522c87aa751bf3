// The swarmsim command-line program.
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <iostream>
#include <limits>
#include <span>
#include <sstream>
#include <string_view>

#include "framework/error.h"
#include "framework/plugin_loader.h"
#include "framework/registry.h"
#include "framework/suggest.h"
#include "framework/utf8.h"
#include "modules/builtin.h"
#include "swarm/bench/bench.h"
#include "swarm/bench/scaling.h"
#include "swarm/loader/world_loader.h"
#include "swarm/run/runner.h"
#include "swarm/run/version.h"
#include "swarm/sweep/report.h"
#include "swarm/sweep/results_merge.h"
#include "swarm/sweep/sweep.h"

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

constexpr int64_t kInt64Max = std::numeric_limits<int64_t>::max();
constexpr int64_t kIntMax = std::numeric_limits<int>::max();

// A whole number from `min` to `max`, written in decimal, for transform():
// the text is rewritten in plain decimal, as CLI11 alone would read 010 as
// octal and 1e2 not at all. `what` names what it counts ("steps") in the
// messages; empty: the range is the message ("expected a whole number from 1
// to 1024").
CLI::Validator WholeNumberCheck(int64_t min, int64_t max, const std::string& what = "") {
  const std::string range = std::to_string(min) + " to " + std::to_string(max);
  return CLI::Validator(
      [=](std::string& text) -> std::string {
        int64_t value = 0;
        const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
        const bool whole =
            !text.empty() && end == text.data() + text.size() && ec != std::errc::invalid_argument;
        if (whole && ec == std::errc() && value >= min && value <= max) {
          text = std::to_string(value);
          return "";
        }
        if (what.empty()) return "expected a whole number from " + range + ", got '" + text + "'";
        if (!whole) return "expected a whole number of " + what + ", got '" + text + "'";
        if (text.starts_with('-') || (ec == std::errc() && value < min))
          return "must be >= " + std::to_string(min) + ", got " + text;
        return "must be at most " + std::to_string(max) + ", got " + text;
      },
      max < kIntMax ? std::to_string(min) + ".." + std::to_string(max)
                    : "NUMBER >= " + std::to_string(min));
}
const CLI::Validator kThreadCount = WholeNumberCheck(1, 1024);  // run and bench --threads

// --seed: the world file's `seed` range, 0 .. 2^64-1, in decimal. CLI11 alone
// would read -1 as 2^64-1 and clamp what is past 2^64-1.
const CLI::Validator kSeedCheck(
    [](std::string& text) -> std::string {
      uint64_t value = 0;
      const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
      if (text.empty() || !std::isdigit(static_cast<unsigned char>(text[0])) || ec != std::errc() ||
          end != text.data() + text.size())
        return "expected a whole number from 0 to 18446744073709551615 (2^64-1), got '" + text +
               "'";
      text = std::to_string(value);
      return "";
    },
    "0..2^64-1");

// A file or folder name that must not be empty (`what`: "a folder").
CLI::Validator NonEmpty(const std::string& what) {
  return CLI::Validator(
      [what](std::string& text) -> std::string {
        return text.empty() ? "expected " + what + ", got an empty name" : "";
      },
      "");
}

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

// `name`'s nearest among `candidates` when it is close enough to be a typo
// (the world loader's rule, framework/suggest.h), else "".
std::string Nearest(std::string_view name, std::span<const std::string> candidates) {
  const std::string* nearest = NearestName(name, candidates);
  return nearest != nullptr ? *nearest : std::string();
}

std::string Join(const std::vector<std::string>& items) {
  std::string out;
  for (const std::string& item : items) out += (out.empty() ? "" : ", ") + item;
  return out;
}

// "--stpes" -> "error: unknown option '--stpes' for 'run' (did you mean
// '--steps'?)", against the options `app` shows in its help.
std::string UnknownOption(const CLI::App& app, const std::string& arg) {
  const std::string given = arg.substr(0, arg.find('='));  // --stpes=5
  std::vector<std::string> names;                          // without the dashes
  for (const CLI::Option* option : app.get_options()) {
    if (option->get_group().empty()) continue;  // internal (bench --child)
    for (const std::string& name : option->get_lnames()) names.push_back(name);
  }
  const size_t dashes = std::min(given.find_first_not_of('-'), given.size());
  const std::string nearest = Nearest(given.substr(dashes), names);
  const bool top = app.get_parent() == nullptr;
  return "error: unknown option '" + given + "'" + (top ? "" : " for '" + app.get_name() + "'") +
         (nearest.empty() ? "" : " (did you mean '--" + nearest + "'?)") + "\nRun 'swarmsim " +
         (top ? "" : app.get_name() + " ") + "--help' for the options.\n";
}

// `--set a=1 b=2`: each --set (sweep --param) takes one value, so b=2 was left
// over or taken for the world file. Returns the message, or "" when `args`
// (argv without the program) have no such value; an existing file is a world.
std::string SecondValueOfRepeatable(const std::vector<std::string>& args) {
  for (size_t i = 0; i < args.size(); ++i) {
    // --set a=1 b=2, or --set=a=1 b=2
    const std::string option = args[i].substr(0, args[i].find('='));
    if (option != "--set" && option != "--param") continue;
    const bool joined = option.size() < args[i].size();
    const size_t at = i + (joined ? 1 : 2);
    if (at >= args.size()) break;
    const std::string value = joined ? args[i].substr(option.size() + 1) : args[i + 1];
    const std::string& extra = args[at];
    std::error_code ec;
    if (extra.starts_with('-') || extra.find('=') == std::string::npos ||
        std::filesystem::exists(extra, ec))
      continue;
    const std::string form = option == "--set" ? "NAME=VALUE" : "NAME=SPEC";
    return "error: unexpected '" + extra + "' after " + option + " " + value + ": each " + option +
           " takes one " + form + "; repeat " + option + " for more: " + option + " " + value +
           " " + option + " " + extra + "\n";
  }
  return "";
}

// What CLI11 rejected, in this program's words: an unknown option or command
// with the nearest known one, a second value after --set, else CLI11's own
// message. `args` is argv without the program.
std::string ParseErrorMessage(CLI::App& app, const std::vector<std::string>& args,
                              const CLI::ParseError& error) {
  std::vector<std::string> commands;
  for (const CLI::App* command : app.get_subcommands([](CLI::App*) { return true; }))
    commands.push_back(command->get_name());
  const std::string command_list = "commands: " + Join(commands) + " (swarmsim --help)\n";
  const std::vector<CLI::App*> parsed = app.get_subcommands();
  CLI::App* command = parsed.empty() ? nullptr : parsed.front();

  // What no option took ("--" ends the options): first the program's own (an
  // unknown option, or an unknown command before any command), then the command's.
  std::vector<std::string> left_over;
  const auto options_end = std::find(args.begin(), args.end(), "--");
  const auto is_option = [&](const std::string& arg) {
    return arg.starts_with('-') && arg != "-" &&
           std::find(args.begin(), options_end, arg) != options_end;
  };
  const auto command_at = std::find(args.begin(), args.end(), command ? command->get_name() : "");
  for (const std::string& arg : app.remaining()) {
    if (arg == "--") continue;
    if (is_option(arg)) return UnknownOption(app, arg);
    if (command && std::find(command_at, args.end(), arg) != args.end()) {
      left_over.push_back(arg);  // after `run ... --`
      continue;
    }
    const std::string nearest = Nearest(arg, commands);
    return "error: unknown command '" + arg + "'" +
           (nearest.empty() ? "" : " (did you mean '" + nearest + "'?)") + "\n" + command_list;
  }
  if (!command) return "error: no command given\n" + command_list;
  for (const std::string& arg : command->remaining()) {
    if (arg == "--") continue;
    if (is_option(arg)) return UnknownOption(*command, arg);
    left_over.push_back(arg);
  }
  if (std::string message = SecondValueOfRepeatable(args); !message.empty()) return message;
  const std::string help = "Run 'swarmsim " + command->get_name() + " --help' for the options.\n";
  if (!left_over.empty())
    return "error: unexpected argument '" + left_over.front() + "' for '" + command->get_name() +
           "'\n" + help;
  return "error: " + std::string(error.what()) + "\n" + help;
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
      out << "  " << name << " = " << ShowParamValue(value) << "\n";
  }
  for (const ModelSummary& m : w.models) {
    out << "\nmodel " << m.name << " (" << m.file << "): " << m.count
        << (m.count == 1 ? " copy" : " copies");
    if (m.scale != 1) out << ", scale " << m.scale;
    out << "\n";
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
  auto* steps_opt = run->add_option("--steps", steps, "Number of control steps to run")
                        ->transform(WholeNumberCheck(0, kInt64Max, "steps"));
  run->add_option("--duration", duration,
                  "Simulated seconds to run, rounded to the nearest whole number of time steps "
                  "(less than one step is an error)")
      ->check(kNonNegative)
      ->excludes(steps_opt);
  run->add_option("--threads", threads, "Worker threads (default: all cores)")
      ->transform(kThreadCount);
  run->add_option("--seed", seed, "Random seed (overrides the world's)")->transform(kSeedCheck);
  run->add_option("--set", sets,
                  "Override a parameter (world NAME or MODEL.NAME); repeat for more: "
                  "--set a=1 --set b=2")
      ->option_text("NAME=VALUE")
      ->allow_extra_args(false);
  run->add_option("--out", out_dir, "Write summary.json and metrics.csv to this folder")
      ->check(NonEmpty("a folder"));
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
      ->delimiter(',')
      ->transform(WholeNumberCheck(1, kIntMax, "robots"));
  bench->add_option("--threads", bench_options.threads, "Thread counts, e.g. 1,2")
      ->delimiter(',')
      ->transform(kThreadCount);
  bench->add_option("--steps", bench_options.steps, "Measured steps per configuration")
      ->transform(WholeNumberCheck(1, kInt64Max, "steps"));
  bench->add_option("--csv", bench_options.csv, "Write one CSV row per measurement")
      ->check(NonEmpty("a file"));
  bench
      ->add_option("--world", bench_options.world,
                   "World to measure (default: worlds/diffusion.yaml beside the program)")
      ->check(NonEmpty("a world file"));
  bench->add_option("--child", bench_child_config)->group("");  // internal: one config
  bench->add_option("--child-robots", bench_child_robots)->group("");
  bench->add_option("--child-threads", bench_child_threads)->group("");
  ScalingOptions scaling_options;  // bench --scaling (issue 5)
  bool bench_scaling = false;
  bench->add_flag("--scaling", bench_scaling,
                  "Speed-up over threads 1..cores and sweep --jobs 1..cores; CSV + PNG");
  bench->add_option("--jobs", scaling_options.jobs, "With --scaling: sweep jobs, e.g. 1,2")
      ->delimiter(',')
      ->transform(WholeNumberCheck(1, kIntMax, "jobs"));
  bench->add_option("--sweep-runs", scaling_options.sweep_runs, "With --scaling: runs per sweep")
      ->transform(WholeNumberCheck(1, kIntMax, "runs"));
  bench->add_option("--plot", scaling_options.plot, "With --scaling: the PNG plot")
      ->capture_default_str()
      ->check(NonEmpty("a file"));

  // sweep, report, merge (issue 5)
  CLI::App* sweep = app.add_subcommand("sweep", "Run a world over a grid of parameters x seeds");
  SweepOptions sweep_options;
  std::string sweep_shard;
  int64_t sweep_steps = -1;
  double sweep_duration = -1;
  sweep->add_option("world", sweep_options.world, "World file (YAML)")->required();
  sweep
      ->add_option("--param", sweep_options.params,
                   "A list 100,200,400, a range A:B:N or a log range log:A:B:N; repeat for more: "
                   "--param a=1,2 --param b=3,4")
      ->option_text("NAME=SPEC")
      ->allow_extra_args(false);
  sweep->add_option("--seeds", sweep_options.seeds, "K (seeds 1..K), A-B, or a list 3,7,11")
      ->capture_default_str();
  auto* sweep_steps_opt = sweep->add_option("--steps", sweep_steps, "Control steps per run")
                              ->transform(WholeNumberCheck(0, kInt64Max, "steps"));
  sweep
      ->add_option("--duration", sweep_duration,
                   "Simulated seconds per run, rounded to the nearest whole number of time steps "
                   "(less than one step is an error)")
      ->check(kNonNegative)
      ->excludes(sweep_steps_opt);
  sweep->add_option("--jobs", sweep_options.jobs, "Concurrent runs (default: all cores)")
      ->transform(WholeNumberCheck(1, kIntMax, "jobs"));
  sweep->add_option("--threads", sweep_options.threads_per_run, "Threads per run")
      ->transform(kThreadCount)
      ->capture_default_str();
  sweep->add_option("--timeout", sweep_options.timeout_s, "Per-run time limit, s (0: none)")
      ->check(kNonNegative);
  sweep->add_option("--db", sweep_options.db, "Results database (SQLite)")
      ->required()
      ->check(NonEmpty("a database file"));
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
  report->add_option("--csv", report_csv, "Write one row per run")->check(NonEmpty("a file"));
  report->add_option("--plot", report_plot, "Write a PNG plot (gnuplot)")
      ->check(NonEmpty("a file"));

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
      ->add_option("--set", describe_sets,
                   "Override a parameter (world NAME or MODEL.NAME); repeat for more: "
                   "--set a=1 --set b=2")
      ->option_text("NAME=VALUE")
      ->allow_extra_args(false);
  CLI::App* version = app.add_subcommand("version", "Print the version");

  const std::vector<std::string> args(argv + std::min(argc, 1), argv + argc);
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    std::cerr << ParseErrorMessage(app, args, e);
    return kExitBadInput;
  }
  // `run --set a=1 b=2` parses (b=2 as the world) but is the same mistake.
  if (const std::string message = SecondValueOfRepeatable(args); !message.empty()) {
    std::cerr << message;
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
      std::cerr << "error: " << swarmsim::ValidUtf8(e.what()) << "\n";
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
  RunOptions options;
  if (!out_dir.empty()) options.out_dir = out_dir;
  options.world_file = world_file;
  for (int i = 0; i < argc; ++i) options.command_line += (i ? " " : "") + std::string(argv[i]);
  // A world that does not load (or does not fit the command line): with
  // --out, summary.json says so too, for a batch system watching the folder.
  const auto bad_input = [&](const std::string& message) {
    std::cerr << "error: " << swarmsim::ValidUtf8(message) << "\n";
    if (options.out_dir && !WriteErrorSummary(options, message))
      std::cerr << "error: cannot write '" << (*options.out_dir / "summary.json").string() << "'\n";
    return kExitBadInput;
  };
  LoadOptions load;
  load.seed = seed;
  load.threads = threads;
  if (!out_dir.empty()) load.output_directory = out_dir;
  load.trust_scripts = trust_scripts;
  load.plugin_directories = PluginDirectories();
  LoadedWorld loaded;
  try {
    load.overrides = ParseSets(sets);
    options.overrides = load.overrides;
    for (const std::string& plugin : plugins) LoadPlugin(plugin, &registry);
    loaded = LoadWorld(world_file, load, registry);
  } catch (const Error& e) {
    return bad_input(e.what());
  }
  if (steps >= 0) {
    options.steps = steps;
  } else if (duration >= 0) {
    // The nearest whole number of steps; a duration under one step would run none.
    const double time_step = loaded.world->settings().time_step;
    if (duration > 0 && duration < time_step) {
      std::ostringstream message;
      message << "--duration " << duration << " s is shorter than one time step (" << time_step
              << " s)";
      return bad_input(message.str());
    }
    const double step_count = std::round(duration / time_step);
    if (!(step_count <= 1e15)) {
      std::ostringstream message;
      message << "--duration " << duration << " s is " << step_count << " steps of " << time_step
              << " s; at most 1e15 steps";
      return bad_input(message.str());
    }
    options.steps = static_cast<int64_t>(step_count);
  } else if (loaded.steps) {
    options.steps = *loaded.steps;
  } else {
    return bad_input(world_file + " gives no run length; pass --steps N or --duration SECONDS");
  }
  options.print_hash = hash;
  options.quiet = quiet;
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

}  // namespace
}  // namespace swarmsim

int main(int argc, char** argv) {
  try {
    return swarmsim::Main(argc, argv);
  } catch (const swarmsim::Error& e) {
    std::cerr << "error: " << swarmsim::ValidUtf8(e.what()) << "\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "error: " << swarmsim::ValidUtf8(e.what()) << "\n";
    return 1;
  }
}
