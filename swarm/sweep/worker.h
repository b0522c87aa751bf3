// Runs of a sweep as worker processes: each run is this program's own `run`
// subcommand in a child process, so a crash, a Lua error or a timeout ends
// that run only and is recorded as a failure with its message.
#pragma once

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "swarm/sweep/grid.h"
#include "swarm/sweep/results_db.h"

namespace swarmsim {

struct WorkerConfig {
  std::string self_exe;  // the swarmsim program
  std::string world;
  std::optional<int64_t> steps;    // --steps, else
  std::optional<double> duration;  // --duration, else the world's own length
  int threads_per_run = 1;
  double timeout_s = 0;           // per run; 0: no limit
  std::string max_memory;         // each run's --max-memory ("": none)
  std::filesystem::path scratch;  // run outputs go to scratch/run-<id>, removed after reading
};

// The command line that runs `run` (without the program name): also what
// `swarmsim run` needs to reproduce a sweep run by hand.
std::vector<std::string> RunArguments(const WorkerConfig& config, const GridRun& run,
                                      const std::filesystem::path& out_dir);

// Reads a finished run's folder (summary.json, metrics.csv) and what it
// wrote on stderr into an outcome. `wait_status` is the child's status from
// waitpid.
RunOutcome CollectRun(int64_t id, const std::filesystem::path& out_dir,
                      const std::string& stderr_text, int wait_status, bool timed_out,
                      double timeout_s);

// Whether a run's error is the machine's, not the world's: no space left on
// a disk, no file or thread to be had, the program not started.
bool IsMachineFailure(const std::string& error);

// Up to `slots` concurrent worker processes. Blocks SIGCHLD in this thread
// while it exists (children get an empty mask); kills its children when destroyed.
class RunPool {
 public:
  RunPool(const WorkerConfig& config, int slots);
  ~RunPool();
  RunPool(const RunPool&) = delete;
  RunPool& operator=(const RunPool&) = delete;

  bool HasFreeSlot() const { return static_cast<int>(active_.size()) < slots_; }
  int active() const { return static_cast<int>(active_.size()); }
  void Start(const GridRun& run);
  // Waits up to `wait_s` seconds for runs to end; returns the ended ones.
  std::vector<RunOutcome> Poll(double wait_s);
  // Kills the runs in progress (SIGKILL) and forgets them; returns how many.
  int KillAll();

 private:
  using Clock = std::chrono::steady_clock;
  struct Active {
    int64_t id;
    int pid;
    std::filesystem::path dir;
    Clock::time_point start;
    int err_fd;       // the read end of the run's stderr (a pipe: a full disk kept nothing)
    std::string err;  // what it wrote, its last kErrKeep bytes
  };
  static constexpr size_t kErrKeep = 16384;
  // Reads what `a` wrote on stderr so far; at its end, closes the pipe.
  static void Drain(Active* a);
  WorkerConfig config_;
  int slots_;
  std::vector<Active> active_;
  std::string worker_name_;
  int child_fd_ = -1;  // signalfd: SIGCHLD, beside the runs' stderr pipes in poll()
  bool restore_mask_ = false;
  unsigned char old_mask_[128];  // sigset_t, opaque here
};

// "host:pid" of this process.
std::string WorkerName();

}  // namespace swarmsim
