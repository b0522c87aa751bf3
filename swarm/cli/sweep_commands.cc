// swarmsim sweep, report and merge (issue 5): a world over a grid of
// parameters x seeds into a results database, what the database says, and
// shards' databases joined into one.
#include <CLI/CLI.hpp>
#include <iostream>

#include "swarm/cli/commands.h"
#include "swarm/cli/options.h"
#include "swarm/sweep/report.h"
#include "swarm/sweep/results_merge.h"
#include "swarm/sweep/sweep.h"

namespace swarmsim::cli {

CLI::App* AddSweepCommand(CLI::App* app, SweepArgs* args) {
  CLI::App* sweep = app->add_subcommand("sweep", "Run a world over a grid of parameters x seeds");
  SweepOptions& options = args->options;
  sweep->add_option("world", options.world, "World file (YAML)")->required();
  sweep
      ->add_option("--param", options.params,
                   "A list 100,200,400, a range A:B:N or a log range log:A:B:N; repeat for more: "
                   "--param a=1,2 --param b=3,4")
      ->option_text("NAME=SPEC")
      ->allow_extra_args(false);
  sweep->add_option("--seeds", options.seeds, "K (seeds 1..K), A-B, or a list 3,7,11")
      ->capture_default_str();
  auto* steps_opt = sweep->add_option("--steps", args->steps, "Control steps per run")
                        ->transform(WholeNumberCheck(0, kInt64Max, "steps"));
  sweep
      ->add_option("--duration", args->duration,
                   "Simulated seconds per run, rounded to the nearest whole number of time steps "
                   "(less than one step is an error)")
      ->check(NonNegativeCheck())
      ->excludes(steps_opt);
  sweep->add_option("--jobs", options.jobs, "Concurrent runs (default: all cores)")
      ->transform(WholeNumberCheck(1, kIntMax, "jobs"));
  sweep->add_option("--threads", options.threads_per_run, "Threads per run")
      ->transform(ThreadCountCheck())
      ->capture_default_str();
  sweep->add_option("--timeout", options.timeout_s, "Per-run time limit, s (0: none)")
      ->check(NonNegativeCheck());
  sweep
      ->add_option("--max-memory", options.max_memory,
                   "Each run's --max-memory (e.g. 8G); default with several jobs: the memory "
                   "available at the start shared between them")
      ->check(MemorySizeCheck());
  sweep->add_option("--db", options.db, "Results database (SQLite)")
      ->required()
      ->check(NonEmpty("a database file"));
  sweep->add_flag("--allow-changed-world", options.allow_changed_world,
                  "Resume even though the world file changed since the sweep began");
  sweep->add_flag("--retry-failed", options.retry_failed, "Run failed runs again");
  sweep->add_option("--shard", args->shard, "i/n: only runs with id % n == i (Slurm arrays)");
  sweep->add_flag("--mpi", options.mpi, "Share the runs between MPI ranks (under mpirun)");
  sweep->add_flag("--quiet", options.quiet, "No progress");
  return sweep;
}

int SweepCommand(SweepArgs args, const std::string& command_line) {
  SweepOptions& options = args.options;
  if (args.steps >= 0) options.steps = args.steps;
  if (args.duration >= 0) options.duration = args.duration;
  if (!args.shard.empty()) ParseShard(args.shard, &options.shard_index, &options.shard_count);
  options.command_line = command_line;
  return RunSweep(options, std::cout, std::cerr);
}

CLI::App* AddReportCommand(CLI::App* app, ReportArgs* args) {
  CLI::App* report = app->add_subcommand("report", "Tables, CSV and a plot from a sweep database");
  ReportOptions& options = args->options;
  report->add_option("db", options.db, "Results database")->required();
  report->add_option("--x", options.x, "Parameter on the x axis");
  report->add_option("--y", options.y, "Metric");
  report->add_option("--by", options.by, "One plot line per value of this parameter");
  report->add_option("--csv", args->csv, "Write one row per run")->check(NonEmpty("a file"));
  report->add_option("--plot", args->plot, "Write a PNG plot (gnuplot)")->check(NonEmpty("a file"));
  return report;
}

int ReportCommand(ReportArgs args) {
  if (!args.csv.empty()) args.options.csv = args.csv;
  if (!args.plot.empty()) args.options.plot = args.plot;
  return RunReport(args.options, std::cout, std::cerr);
}

CLI::App* AddMergeCommand(CLI::App* app, MergeArgs* args) {
  CLI::App* merge = app->add_subcommand("merge", "Merge sweep databases (shards) into one");
  merge->add_option("out", args->out, "Output database (created if missing)")->required();
  merge->add_option("inputs", args->inputs, "Input databases")->required();
  merge->add_flag("--allow-changed-world", args->allow_changed_world,
                  "Merge runs made with different versions of the world file");
  return merge;
}

int MergeCommand(const MergeArgs& args) {
  return RunMerge(args.out, args.inputs, args.allow_changed_world, std::cout, std::cerr);
}

}  // namespace swarmsim::cli
