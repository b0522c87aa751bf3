// swarmsim bench: robot-ticks/s over robots x threads, one child process per
// configuration (bench --child is that child); --scaling adds the sweep jobs;
// --scaling-robots measures the cost per robot-tick over robot counts.
#include <CLI/CLI.hpp>
#include <filesystem>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include "framework/error.h"
#include "swarm/bench/bench.h"
#include "swarm/bench/robot_scaling.h"
#include "swarm/bench/scaling.h"
#include "swarm/cli/commands.h"
#include "swarm/cli/options.h"

namespace swarmsim::cli {

CLI::App* AddBenchCommand(CLI::App* app, BenchArgs* args) {
  CLI::App* bench = app->add_subcommand("bench", "Measure robot-ticks/s over robots x threads");
  BenchOptions& options = args->options;
  bench->add_option("--robots", options.robots, "Robot counts, e.g. 100,1000,10000")
      ->delimiter(',')
      ->transform(WholeNumberCheck(1, kIntMax, "robots"));
  bench->add_option("--threads", options.threads, "Thread counts, e.g. 1,2")
      ->delimiter(',')
      ->transform(ThreadCountCheck());
  bench->add_option("--steps", options.steps, "Measured steps per configuration")
      ->transform(WholeNumberCheck(1, kInt64Max, "steps"));
  bench
      ->add_option("--warmup", options.warmup_steps,
                   "Unmeasured steps before the measured ones, e.g. 3000 to measure a swarm "
                   "that has moved (default 20; --scaling-robots: a tenth of the steps, 2 to 20)")
      ->transform(WholeNumberCheck(0, kInt64Max, "warm-up steps"));
  bench->add_option("--csv", options.csv, "Write one CSV row per measurement")
      ->check(NonEmpty("a file"));
  bench
      ->add_option("--world", options.world,
                   "World to measure (default: worlds/diffusion.yaml beside the program)")
      ->check(NonEmpty("a world file"));
  bench->add_option("--child", args->child_config)->group("");  // internal: one config
  bench->add_option("--child-robots", args->child_robots)->group("");
  bench->add_option("--child-threads", args->child_threads)->group("");
  bench->add_option("--child-warmup", options.warmup_steps)->group("");
  ScalingOptions& scaling = args->scaling_options;  // bench --scaling (issue 5)
  bench->add_flag("--scaling", args->scaling,
                  "Speed-up over threads 1..cores and sweep --jobs 1..cores; CSV + PNG");
  bench->add_option("--jobs", scaling.jobs, "With --scaling: sweep jobs, e.g. 1,2")
      ->delimiter(',')
      ->transform(WholeNumberCheck(1, kIntMax, "jobs"));
  bench->add_option("--sweep-runs", scaling.sweep_runs, "With --scaling: runs per sweep")
      ->transform(WholeNumberCheck(1, kIntMax, "runs"));
  bench
      ->add_option("--plot", scaling.plot,
                   "With --scaling or --scaling-robots: the PNG plot (default scaling.png, "
                   "scaling_robots.png)")
      ->check(NonEmpty("a file"));
  // bench --scaling-robots (issue 32): cost per robot-tick over robot counts.
  CLI::Option* robots_flag = bench->add_flag(
      "--scaling-robots", args->scaling_robots,
      "Microseconds per robot-tick by phase, start-up and memory over --robots (default "
      "1000,10000,100000) for the Lua diffusion world, its C++ controller, and both with "
      "the planar backend (--configs); CSV + log-log PNG");
  bench
      ->add_option("--configs", args->configs,
                   "With --scaling-robots: which of lua, cpp, planar-lua, planar-cpp (default all)")
      ->delimiter(',');
  bench
      ->add_option("--repeat", args->repeat,
                   "With --scaling-robots: rounds of every row, one after the other; each row "
                   "reports its median round (default 1)")
      ->transform(WholeNumberCheck(1, 100, "repeat"));
  robots_flag->excludes("--scaling");
  return bench;
}

namespace {

// A value listed twice measured its row twice (and --configs lua,lua gave a
// second "vs 1st" baseline): refused, as sweep refuses it.
template <typename T>
void RefuseRepeats(const std::vector<T>& values, const char* flag) {
  for (size_t i = 0; i < values.size(); ++i)
    for (size_t j = 0; j < i; ++j)
      if (values[i] == values[j]) {
        std::ostringstream v;
        v << values[i];
        throw Error(std::string("bench: ") + flag + ": value '" + v.str() +
                    "' appears twice (each is measured once)");
      }
}

int ScalingRobots(const BenchArgs& args, const CLI::App& command) {
  RobotScalingOptions o;
  o.self_exe = args.options.self_exe;
  if (command.count("--robots") > 0) o.robots = args.options.robots;
  if (command.count("--threads") > 0) o.threads = args.options.threads;
  if (command.count("--steps") > 0) o.steps = args.options.steps;
  if (command.count("--warmup") > 0) o.warmup_steps = args.options.warmup_steps;
  if (args.options.csv) o.csv = *args.options.csv;
  if (command.count("--plot") > 0) o.plot = args.scaling_options.plot;
  o.repeat = args.repeat;
  if (!args.configs.empty() && !args.options.world.empty())
    throw Error("bench: --configs and --world: give one or the other");
  if (!args.configs.empty()) o.configs = SelectScalingConfigs(args.configs);
  if (!args.options.world.empty())
    o.configs = {{std::filesystem::path(args.options.world).stem().string(), args.options.world}};
  return RunRobotScalingBench(o, std::cout, std::cerr);
}

}  // namespace

int BenchCommand(BenchArgs args, const CLI::App& command) {
  args.options.self_exe = "/proc/self/exe";
  // A flag of one kind of bench given to another would be ignored: refused.
  const auto only_with = [&command](const char* flag, bool allowed, const char* kinds) {
    if (command.count(flag) > 0 && !allowed)
      throw Error(std::string("bench: ") + flag + " is for bench " + kinds);
  };
  only_with("--plot", args.scaling || args.scaling_robots, "--scaling and --scaling-robots");
  only_with("--jobs", args.scaling, "--scaling");
  only_with("--sweep-runs", args.scaling, "--scaling");
  only_with("--configs", args.scaling_robots, "--scaling-robots");
  only_with("--repeat", args.scaling_robots, "--scaling-robots");
  RefuseRepeats(args.options.robots, "--robots");
  RefuseRepeats(args.options.threads, "--threads");
  RefuseRepeats(args.configs, "--configs");
  RefuseRepeats(args.scaling_options.jobs, "--jobs");
  if (args.scaling_robots) return ScalingRobots(args, command);
  if (args.scaling) {
    ScalingOptions& scaling = args.scaling_options;
    scaling.bench = args.options;
    scaling.threads_given = command.count("--threads") > 0;
    if (args.options.csv) scaling.csv = *args.options.csv;
    return RunScalingBench(scaling, std::cout, std::cerr);
  }
  if (!args.child_config.empty())
    return RunBenchChild(args.options, args.child_config, args.child_robots, args.child_threads,
                         std::cout);
  return RunBench(args.options, std::cout, std::cerr);
}

}  // namespace swarmsim::cli
