// `swarmsim bench`: whole-run scaling over robot counts and thread counts.
#pragma once

#include <cstdint>
#include <iosfwd>
#include <optional>
#include <set>
#include <string>
#include <vector>

namespace swarmsim {

struct BenchOptions {
  std::string world;  // empty: worlds/diffusion.yaml (DefaultBenchWorld)
  std::vector<int> robots{100, 1000, 10000};
  std::vector<int> threads{1, 2};
  int64_t steps = 200;        // measured steps per configuration
  int64_t warmup_steps = 20;  // unmeasured steps first (wheel commands settle)
  std::optional<std::string> csv;
  std::string self_exe;  // this program, re-run once per configuration
};

// What a bench output file is, for CheckBenchOutput.
enum class BenchOutput { kCsv, kPng };

// Checks, before anything is measured, that bench may write `path` (the
// value of `flag`, "--csv" or "--plot"): a file that exists must be one
// bench writes (a CSV whose first line is one of bench's headers, a PNG) or
// empty, never a world, a script or notes it would write over; a new one
// must be creatable in its folder (tried, then removed). Throws
// swarmsim::Error naming the flag and the file.
void CheckBenchOutput(const std::string& path, const char* flag, BenchOutput kind);

// One measured configuration (one CSV row).
struct BenchRow {
  std::string config;  // "diffusion" or "box2d-only"
  int robots = 0;
  int threads = 0;
  int64_t steps = 0;
  double wall_s = 0;
  double robot_ticks_per_s = 0;
  double us_per_tick[5] = {0, 0, 0, 0, 0};  // sense, control, actuate, physics, record
  double peak_rss_mb = 0;
  double kb_per_robot = 0;
  double startup_s = 0;  // loading the world and starting it (sysCall_init): load to first step
};

// The world `bench` measures without --world: worlds/diffusion.yaml of the
// source tree the program was built in (build/swarmsim ->
// ../worlds/diffusion.yaml), else of the current folder. Empty when neither
// has it.
std::string DefaultBenchWorld();

// `relative` (a path in the repository, "worlds/diffusion_native.yaml") in
// the source tree the program was built in, else in the current folder, as
// DefaultBenchWorld finds its world. Empty when neither has it.
std::string FindInSourceTree(const std::string& relative);

// What `bench` checks before it prints anything: fills in the default world,
// checks that the world loads and has the `robots` parameter the bench sets
// the robot count through. Throws swarmsim::Error with a message a user can
// act on. Returns the bare-engine row's configuration for the world's
// backend: "box2d-only" or "ode-only".
std::string PrepareBench(BenchOptions* options);

// Runs every configuration, each in a fresh child process (clean peak memory,
// no cache warmed by the previous one), prints the table to `out` and writes
// the CSV. Returns the process exit code; throws swarmsim::Error (before any
// output) for a world PrepareBench rejects.
int RunBench(BenchOptions options, std::ostream& out, std::ostream& err);

// Measures one configuration in a fresh child process (`options.self_exe
// bench --child ...`: options.world, steps and warm-up steps) into `row`.
// False when the child failed (its stderr passes through). The world's
// load-time warnings at that robot count (the large-swarm notes, say) are
// appended to `warnings` if given.
bool MeasureInChild(const BenchOptions& options, const std::string& config, int robots, int threads,
                    BenchRow* row, std::vector<std::string>* warnings = nullptr);

// Prints each of `warnings` ("warning: ..." on `err`) that is not in `said`
// yet, and adds it there: a world's load-time warnings once per bench,
// whatever the rows that bring them.
void SayNewWarnings(const std::vector<std::string>& warnings, std::set<std::string>* said,
                    std::ostream& err);

// The child side: measures one configuration in this process and prints one
// CSV row (no header) to `out`, then a "warning: ..." line for each of the
// world's load-time warnings. `config` is "diffusion" or "box2d-only".
int RunBenchChild(const BenchOptions& options, const std::string& config, int robots, int threads,
                  std::ostream& out);

}  // namespace swarmsim
