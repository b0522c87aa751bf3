// Runs a world for a number of steps: progress, summary, outputs.
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <iosfwd>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "framework/world.h"

namespace swarmsim {

struct RunResult;

struct RunOptions {
  int64_t steps = 0;
  std::optional<std::filesystem::path> out_dir;  // summary.json, metrics.csv
  // The folder out_dir was when the command made it (device, inode; both 0:
  // not known): moved or removed before the run writes into it (a long
  // load), the run says so instead of making a new one.
  uint64_t out_dir_device = 0, out_dir_inode = 0;
  bool print_hash = false;
  // The state hash at the end (RunResult::state_hash, summary.json): a pass
  // over the whole state (0.5 s at a million robots), skipped when false
  // and neither print_hash nor out_dir asks for it (the hash is then 0).
  bool state_hash = true;
  bool quiet = false;      // no progress, no summary table (errors still go to stderr)
  std::string world_file;  // for the summary
  std::string command_line;
  // --set NAME=VALUE, in order, for the summary ("overrides"): world
  // parameters are in "parameters" too, model parameters only here.
  std::vector<std::pair<std::string, std::string>> overrides;
  // What else the run produces, appended to the progress line ("video 120
  // frames"); null: nothing.
  std::function<std::string()> progress_note;
  // Snapshots (framework/world_state.h): the world's state written to
  // `save_state` after step `save_state_at` (the world's step count; -1:
  // at the end of the run); the run resumed from `resumed_from`'s state
  // (the file, for the summary), its steps counted from there.
  std::optional<std::filesystem::path> save_state;
  int64_t save_state_at = -1;
  std::string resumed_from;
  // Seconds the caller spent loading the world (reading the file, building
  // its robots) before handing it to the run: not in the wall time; the
  // table and summary.json's load_time say it. Negative: not known.
  double load_seconds = -1;
  // Called once with how the run ended when the watchdog ends it (a step or
  // the stop stuck past simulation.step_timeout, a stop signal during a
  // stuck step), from the watchdog's thread just before the process exits:
  // the video's end and the recording's end chunk, before summary.json is
  // written. (A run that returns is the caller's to close.)
  std::function<void(const RunResult&)> on_stuck_end;
  // Called last when the watchdog ends the run, after summary.json, just
  // before the process exits: what the caller would release on return (the
  // output folder's lock file).
  std::function<void()> on_stuck_exit;
  // Called with each step's metric samples (after metrics.csv has them),
  // from the run's thread: the Python World keeps its history from them.
  // Null: with out_dir, metrics.csv takes them; else the world keeps them.
  std::function<void(const std::vector<MetricSample>&)> on_metrics;
};

struct RunResult {
  bool ok = false;
  std::string error;  // the message when !ok
  int64_t steps = 0;  // steps completed
  double wall_seconds = 0;
  // Of wall_seconds, starting the world (modules, robots' scripts and their
  // sysCall_init, native controllers) before its first step.
  double start_seconds = 0;
  uint64_t state_hash = 0;
  double peak_rss_mb = 0;
  int signal = 0;           // SIGINT/SIGTERM/SIGHUP that interrupted the run, else 0
  int64_t first_step = 0;   // the world's step count when the run started (--load-state)
  int64_t saved_step = -1;  // the step whose state --save-state wrote, else -1
};

// Steps `world` (starting it if needed), printing progress to `progress`
// (a bar on a terminal, plain lines otherwise) and the summary to `out`.
// Outputs are written as the run goes, so a failing run keeps everything up
// to the failure; the summary records the error. SIGINT, SIGTERM and SIGHUP
// during the run stop it at the next step boundary (status "interrupted",
// outputs written, RunResult::signal set). Never throws for user errors.
RunResult RunWorld(World* world, const RunOptions& options, std::ostream& out,
                   std::ostream& progress);

// summary.json for a run that never started (the world did not load, or the
// command line and world do not agree, or a signal came while it loaded):
// `status` ("error" or "interrupted"), the message, world, command and
// swarmsim_version. Creates `options.out_dir`, removes an earlier run's
// outputs there (RemoveEarlierOutputs, and its metrics.csv: the folder
// holds this run's alone); returns "" or why the file could not be written.
std::string WriteErrorSummary(const RunOptions& options, const std::string& error,
                              const std::string& status = "error");

// Peak resident set size of this process, in MiB.
double PeakRssMb();

}  // namespace swarmsim
