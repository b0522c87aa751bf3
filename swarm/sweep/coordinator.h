// The coordinator of a sweep, shared by local and MPI sweeps: it owns the
// results database, hands this shard's pending runs to worker processes (and,
// under MPI, to the other ranks) and records what they return.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <iosfwd>
#include <optional>
#include <string>
#include <vector>

#include "swarm/sweep/grid.h"
#include "swarm/sweep/worker.h"

namespace swarmsim {

struct SweepOptions {
  std::string world;
  std::vector<std::string> params;  // NAME=SPEC
  std::string seeds = "1";          // K, A-B or a list
  std::optional<int64_t> steps;
  std::optional<double> duration;
  int jobs = 0;  // concurrent runs; <= 0: all cores (1 per rank with --mpi)
  int threads_per_run = 1;
  double timeout_s = 0;  // per run; 0: none
  // --max-memory SIZE for every run ("8G"); empty: with more than one job,
  // each run gets an equal share of the memory available when the sweep
  // starts (a large world refused with a message instead of the jobs
  // together running the machine out of memory).
  std::string max_memory;
  std::string db;
  bool allow_changed_world = false;
  bool retry_failed = false;
  int shard_index = 0, shard_count = 1;  // --shard i/n: runs with id % n == i
  bool mpi = false;
  bool quiet = false;
  std::string self_exe = "/proc/self/exe";
  std::string command_line;
};

// How the worker processes of a sweep run (shared by local and MPI sweeps),
// `jobs` of them at once on this machine.
WorkerConfig MakeWorkerConfig(const SweepOptions& options, int jobs);

// How many runs can be side by side: the jobs, but no more than the runs
// left (at least 1). The memory is shared between these: --jobs 8 for 2
// runs gives each half, not an eighth.
int RunsSideBySide(int jobs, size_t pending);

// Each run's --max-memory: `max_memory` if given, else with more than one
// job `available` (bytes the machine or cgroup has; UINT64_MAX: unknown)
// shared equally between the jobs, as bytes; "" for none.
std::string RunMemoryCap(const std::string& max_memory, int jobs, uint64_t available);

// The content hash of a world file (hex), as stored in the sweep table.
std::string WorldFileHash(const std::string& path);

// The canonical description of the sweep's run grid (JSON text).
std::string SweepSpace(const std::vector<ParamSpec>& params, const std::vector<uint64_t>& seeds,
                       const std::optional<int64_t>& steps, const std::optional<double>& duration);

// Ranks other than this one that take runs (MPI). The coordinator calls
// Service() often; it answers requests with `next()` (nullopt: no more) and
// hands results to `done`.
class RemoteWorkers {
 public:
  virtual ~RemoteWorkers() = default;
  virtual void Service(const std::function<std::optional<GridRun>()>& next,
                       const std::function<void(RunOutcome)>& done) = 0;
  virtual bool Busy() const = 0;  // some rank still holds a run or has not been told to stop
  virtual int Running() const = 0;
};

// The coordinator loop shared by local and MPI sweeps.
int CoordinateSweep(const SweepOptions& options, RemoteWorkers* remote, std::ostream& out,
                    std::ostream& err);

}  // namespace swarmsim
