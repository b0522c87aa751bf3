#include "swarm/run/runner.h"

#include <fcntl.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <unistd.h>

#include <array>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <functional>
#include <iomanip>
#include <iostream>
#include <map>
#include <memory>
#include <new>
#include <optional>
#include <set>
#include <sstream>
#include <thread>
#include <utility>

#include "framework/csv.h"
#include "framework/error.h"
#include "framework/output_file.h"
#include "framework/registry.h"
#include "framework/regular_file.h"
#include "framework/script_host.h"
#include "framework/start_thread.h"
#include "framework/state_hash.h"
#include "framework/utf8.h"
#include "swarm/run/output_folder.h"
#include "swarm/run/step_progress.h"
#include "swarm/run/stop_signals.h"
#include "swarm/run/summary_file.h"

namespace swarmsim {

double PeakRssMb() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return static_cast<double>(usage.ru_maxrss) / 1024.0;  // ru_maxrss is in KiB on Linux
}

namespace {

using Clock = std::chrono::steady_clock;

// Bytes of memory kept aside for the end of a run that ran out (RunWorld).
constexpr size_t kMemoryRoom = size_t{8} << 20;

// Disk space kept aside for the final summary.json (a summary of a run with
// thousands of snapshots lists each one: ~100 bytes each).
constexpr size_t kSummaryRoom = size_t{1} << 20;

// A CSV field (framework/csv.h), invalid UTF-8 replaced (ValidUtf8).
void WriteUtf8CsvField(std::ostream& os, std::string_view text) {
  if (!IsValidUtf8(text)) return WriteCsvField(os, ValidUtf8(text));
  WriteCsvField(os, text);
}

// Streams metric samples to metrics.csv in tidy (long) form, one row per
// sample: step,time,robot,metric,value. `robot` is empty for swarm metrics.
// Rows reach the file at least every second, so a run killed from outside
// (a sweep's --timeout, the OOM killer) keeps all but the last second.
class MetricsWriter {
 public:
  MetricsWriter(const std::filesystem::path& path, const World& world)
      : world_(world), path_(path) {
    errno = 0;
    file_.open(path);
    if (!file_) Fail();
    file_ << "step,time,robot,metric,value\n";
    file_ << std::setprecision(10);
    Flush();
  }
  void Write(const std::vector<MetricSample>& samples) {
    errno = 0;  // a row that fills the buffer writes it: its failure's errno, kept below
    for (const MetricSample& m : samples) {
      file_ << m.step << ',' << m.time << ',';
      if (m.instance >= 0) WriteUtf8CsvField(file_, world_.scene().instance(m.instance).name);
      file_ << ',';
      WriteUtf8CsvField(file_, m.name);
      file_ << ',';
      if (std::isnan(m.value))
        file_ << "nan";  // not "-nan": one spelling for every reader
      else
        file_ << m.value;
      file_ << '\n';
    }
    // The buffer's write failed (a full disk): its errno, for Flush's message.
    if (!file_ && failed_errno_ == 0) failed_errno_ = errno;
    if (!samples.empty() && Clock::now() - last_flush_ >= std::chrono::seconds(1)) Flush();
  }
  // Throws Error naming the file when the rows could not be written (a full
  // disk): a run must not go on as if its metrics were kept.
  void Flush() {
    errno = 0;
    file_.flush();
    if (!file_) Fail();
    last_flush_ = Clock::now();
  }

 private:
  [[noreturn]] void Fail() {
    int error = failed_errno_ != 0 ? failed_errno_ : errno;
    // No errno (the stream's own calls may clear it): a full disk is the
    // usual reason, and the folder says whether it is.
    std::error_code ec;
    if (error == 0 && std::filesystem::space(path_.parent_path(), ec).available == 0 && !ec)
      error = ENOSPC;
    throw Error("cannot write '" + path_.string() + "'" +
                (error != 0 ? std::string(": ") + std::strerror(error) : std::string()));
  }

  const World& world_;
  std::filesystem::path path_;
  std::ofstream file_;
  int failed_errno_ = 0;  // errno of the write that failed, if Write saw one
  Clock::time_point last_flush_;
};

std::string Fixed(double v, int digits) {
  std::ostringstream s;
  s << std::fixed << std::setprecision(digits) << v;
  return s.str();
}

// Ends a run whose step does not finish. Lua's hooks stop runaway Lua code
// (the instruction budget, the memory limit) but not a script stuck inside
// one C function, and a stop signal is only looked at between steps. After
// `timeout` seconds (0: never) without progress, or kSignalGrace after a
// stop signal the step did not answer, `end_run(error, signal)` runs on the
// watchdog's thread; it writes the outputs and exits the process, since the
// stuck thread cannot be unwound. The run loop holds io_mutex() while it
// writes outputs and reports progress; end_run runs holding it too, so the
// two never write at once.
class Watchdog {
 public:
  using EndRun = std::function<void(const std::string& error, int signal)>;
  static constexpr double kSignalGrace = 3;        // s, a step's
  static constexpr double kStartSignalGrace = 15;  // s, the start's or the stop's

  // `instruction_budget`: the world's (simulation.instruction_budget), for
  // the message: with none, an endless Lua loop is also stopped only here.
  // A step may take `step_timeout`; the start and the stop of the world
  // (the first unit is the start) `world_timeout`.
  Watchdog(double step_timeout, double world_timeout, int64_t instruction_budget, EndRun end_run)
      : step_timeout_(step_timeout),
        world_timeout_(world_timeout),
        instruction_budget_(instruction_budget),
        end_run_(std::move(end_run)),
        thread_(StartThread("the run's watchdog", [this] { Watch(); })) {}
  ~Watchdog() {
    {
      const std::lock_guard lock(wake_mutex_);
      done_ = true;
    }
    wake_.notify_one();
    thread_.join();
  }
  Watchdog(const Watchdog&) = delete;
  Watchdog& operator=(const Watchdog&) = delete;

  std::mutex& io_mutex() { return io_mutex_; }
  // One more unit of progress (the start, a step, the stop); `what` names
  // the next one for the message ("step 12"), `step` whether it is a step.
  void Progress(std::string what, bool step) {
    const std::lock_guard lock(wake_mutex_);
    ++progress_;
    next_ = std::move(what);
    step_ = step;
  }

 private:
  void Watch() {
    using namespace std::chrono_literals;
    uint64_t seen = ~uint64_t{0};
    Clock::time_point since = Clock::now();
    Clock::time_point signal_since{};
    std::unique_lock lock(wake_mutex_);
    while (!wake_.wait_for(lock, 100ms, [this] { return done_; })) {
      const Clock::time_point now = Clock::now();
      if (progress_ != seen) seen = progress_, since = now, signal_since = {};
      const int sig = StopSignals::Received();
      if (sig != 0 && signal_since == Clock::time_point{}) signal_since = now;
      const double stalled = std::chrono::duration<double>(now - since).count();
      std::string error;
      int end_signal = 0;
      // The start answers a signal between its stages and its robots'
      // Lua states (World::set_stop_check); a stage of a million robots
      // takes seconds (it was ended as stuck, 3 s after the signal).
      const double grace = step_ ? kSignalGrace : kStartSignalGrace;
      if (sig != 0 && now - signal_since >= std::chrono::duration<double>(grace)) {
        error = std::string("interrupted by SIG") + sigabbrev_np(sig) + " during " + next_ +
                ", which did not finish within " + Fixed(grace, 0) + " s of the signal";
        end_signal = sig;
      } else if (const double timeout = step_ ? step_timeout_ : world_timeout_;
                 timeout > 0 && stalled >= timeout) {
        std::ostringstream limit;
        limit << timeout;
        error = next_ + " did not finish within " + limit.str() + " s (simulation.step_timeout" +
                (step_ ? "" : ", for each 10,000 robots") + ")";
      } else {
        continue;
      }
      const std::vector<std::string> calls = ScriptCallsInProgress();
      if (calls.empty()) {
        // Lua calls are the ones recorded: what held the step is native
        // (a native controller such as a Kilobot program with
        // program_timeout 0, a plugin, or swarmsim itself).
        error += "; no Lua script was running (a native controller, a plugin or swarmsim was)";
      } else {
        error += "; running: ";
        for (size_t i = 0; i < calls.size(); ++i) error += (i ? "; " : "") + calls[i];
        error += instruction_budget_ > 0
                     ? " (the instruction budget cannot stop a script inside one C function, "
                       "such as a pattern match that backtracks over a long string or a garbage "
                       "collection of a large heap)"
                     : " (simulation.instruction_budget is 0, no limit: an endless loop in a "
                       "script runs until this timeout)";
      }
      // Outputs are written under io_mutex; progress_ cannot move meanwhile
      // (the loop reports progress only after writing them).
      const uint64_t before = progress_;
      lock.unlock();
      const std::lock_guard io(io_mutex_);
      lock.lock();
      if (progress_ != before) continue;  // it moved on after all
      end_run_(error, end_signal);
    }
  }

  const double step_timeout_, world_timeout_;
  bool step_ = false;  // the unit under way is a step, not the start or stop (wake_mutex_)
  const int64_t instruction_budget_;
  const EndRun end_run_;
  std::mutex io_mutex_;
  std::mutex wake_mutex_;
  std::condition_variable wake_;
  bool done_ = false;
  uint64_t progress_ = 0;
  std::string next_ = "the start of the world";
  std::thread thread_;  // last: starts once the members above exist
};

// "box2d, 10 substeps"; "kinematic" (no physics engine steps: no substeps).
std::string PhysicsLine(const World& world) {
  const WorldSettings& settings = world.settings();
  if (!world.registry().dynamics_capabilities(settings.physics).substeps) return settings.physics;
  return settings.physics + ", " + std::to_string(settings.physics_substeps) +
         (settings.physics_substeps == 1 ? " physics substep" : " physics substeps");
}

// A file descriptor held for the last summary.json: a run whose files (the
// recording, metrics.csv, a plugin's) used up its open files (`ulimit -n`)
// still writes how it ended (it stayed "running").
class SpareDescriptor {
 public:
  SpareDescriptor() = default;
  SpareDescriptor(const SpareDescriptor&) = delete;
  SpareDescriptor& operator=(const SpareDescriptor&) = delete;
  ~SpareDescriptor() { Release(); }
  void Take() {
    if (fd_ < 0) fd_ = ::open("/dev/null", O_RDONLY | O_CLOEXEC);
  }
  void Release() {
    if (fd_ >= 0) ::close(fd_);
    fd_ = -1;
  }

 private:
  int fd_ = -1;
};

// What a run has produced so far, shared by its step loop, the watchdog's
// end of a stuck run and the outputs written after the loop.
struct RunRecord {
  RunResult result;
  std::unique_ptr<MetricsWriter> metrics;  // metrics.csv, with an output folder
  // Room for the last summary.json when the disk fills during the run.
  OutputReserve summary_room;
  SpareDescriptor summary_descriptor;  // and a file descriptor for it
  double lua_kib = 0;                  // the scripts' memory when they stopped
  // The output folder as the run found it (device, inode): removed or
  // renamed during the run, the files written into it went with it.
  std::optional<std::pair<dev_t, ino_t>> out_folder;
};

std::optional<std::pair<dev_t, ino_t>> FolderIdentity(const std::filesystem::path& dir) {
  struct stat st {};
  if (::stat(dir.c_str(), &st) != 0 || !S_ISDIR(st.st_mode)) return std::nullopt;
  return std::pair{st.st_dev, st.st_ino};
}

// Starts `world` and steps it options.steps times under a Watchdog, writing
// metrics as it goes. A failure ends up in record->result (ok false, error);
// a step that never finishes ends the process (the Watchdog's end_run).
void StepWatched(World* world, const RunOptions& options, Clock::time_point start,
                 StepProgress* progress_bar, RunRecord* record) {
  RunResult& result = record->result;
  std::unique_ptr<MetricsWriter>& metrics = record->metrics;
  double& lua_kib = record->lua_kib;
  // Room for the error message, taken now: out of memory, composing it
  // must not need more (it threw std::bad_alloc from the handler, and the
  // run ended as "error: std::bad_alloc").
  result.error.reserve(1024);
  StepProgress& progress = *progress_bar;
  const auto seconds = [start] {
    return std::chrono::duration<double>(Clock::now() - start).count();
  };
  // A step that never finishes: write what a failed run writes and exit.
  const auto end_stuck_run = [&](const std::string& error, int signal) {
    RunResult stuck = result;
    stuck.ok = false;
    stuck.error = error;
    stuck.signal = signal;
    stuck.wall_seconds = std::chrono::duration<double>(Clock::now() - start).count();
    stuck.peak_rss_mb = PeakRssMb();
    try {
      if (metrics) metrics->Flush();
    } catch (const Error&) {  // the summary says what stopped the run
    }
    if (options.on_stuck_end) options.on_stuck_end(stuck);  // the recording's end chunk
    record->summary_room.Release();
    record->summary_descriptor.Release();
    if (options.out_dir && std::filesystem::is_directory(*options.out_dir))
      WriteSummary(*world, options, stuck, 0, /*complete=*/false);
    progress.Finish();
    world->FlushPrintsOfStuckStep();  // what the scripts printed before they got stuck
    std::fflush(stdout);
    std::cerr << "error: " << ValidUtf8(error) << "\n";
    if (options.out_dir && std::filesystem::is_directory(*options.out_dir))
      std::cerr << OutputsOfFinishedSteps(stuck.steps, *options.out_dir) << "\n";
    std::cerr.flush();
    if (options.on_stuck_exit) options.on_stuck_exit();
    std::_Exit(signal != 0 ? 128 + signal : 1);  // 1: the run failed, as main's
  };
  // A step may take simulation.step_timeout; the start and the stop of the
  // world, whose work grows with the robots (a million Lua robots start in
  // about 45 s on a 2-core VM), that much for each 10,000 robots.
  const double step_timeout = world->settings().step_timeout;
  // No thread to watch the steps (a process limit): the run does not start,
  // and ends as a failed run does, with its summary.json (the earlier
  // run's, "ok", stayed in the folder whose other files were removed).
  std::optional<Watchdog> watching;
  try {
    watching.emplace(
        step_timeout,
        step_timeout * std::max(1.0, static_cast<double>(world->robot_count()) / 10000.0),
        world->settings().instruction_budget, end_stuck_run);
  } catch (const std::exception& e) {
    result.error.assign(e.what());
    if (options.out_dir) {  // the earlier run's, which this run's would have replaced
      std::error_code ec;
      std::filesystem::remove(*options.out_dir / "metrics.csv", ec);
    }
    return;
  }
  Watchdog& watchdog = *watching;
  // Outputs of the step just done, then the next unit of work for the
  // watchdog's message; under its lock, so it never writes at the same time.
  // --save-state: the samples taken before the state is saved, which it
  // carries (a run resumed from it writes the whole history to its
  // metrics.csv; it held the rows from the saved step on only).
  std::vector<MetricSample> taken;
  bool state_saved = false;
  const auto take_metrics = [&] {
    if (!metrics && !options.on_metrics) return;  // kept in the world
    const std::vector<MetricSample> samples = world->TakeMetrics();
    if (metrics) metrics->Write(samples);
    if (options.on_metrics) options.on_metrics(samples);
    if (options.save_state && !state_saved)
      taken.insert(taken.end(), samples.begin(), samples.end());
  };
  const auto done = [&](std::string next, bool step) {
    const std::lock_guard lock(watchdog.io_mutex());
    take_metrics();
    watchdog.Progress(std::move(next), step);
  };
  bool started = false;  // for the out-of-memory message
  const auto step_name = [&] {
    return "step " + std::to_string(result.steps + 1) + " of " + std::to_string(options.steps);
  };
  try {
    if (options.out_dir) {
      // Moved or removed while the world loaded: said, and no new folder
      // (a new one held an "ok" summary, the old the lock alone).
      if (options.out_dir_inode != 0) {
        record->out_folder = std::pair{static_cast<dev_t>(options.out_dir_device),
                                       static_cast<ino_t>(options.out_dir_inode)};
        if (FolderIdentity(*options.out_dir) != record->out_folder)
          throw Error("the output folder '" + options.out_dir->string() +
                      "' was removed or renamed while the world loaded");
      }
      CreateOutputFolder(*options.out_dir);
      const std::lock_guard lock(watchdog.io_mutex());
      // summary.json first (status "running"), so that the folder says what
      // it is from the start and a full disk stops the run before step 1.
      if (const std::string reason =
              WriteSummary(*world, options, result, 0, /*complete=*/false, "running");
          !reason.empty())
        throw Error("cannot write '" + (*options.out_dir / "summary.json").string() +
                    "': " + reason);
      record->summary_room.Reserve(*options.out_dir, kSummaryRoom);
      record->summary_descriptor.Take();
      if (!record->out_folder) record->out_folder = FolderIdentity(*options.out_dir);
      metrics = std::make_unique<MetricsWriter>(*options.out_dir / "metrics.csv", *world);
    }
    const Clock::time_point starting = Clock::now();
    // A stop signal ends the start between its stages and its robots' Lua
    // states, as one ends the load between model copies.
    int start_signal = 0;
    world->set_stop_check([&start_signal] {
      if (const int sig = StopSignals::Received(); sig != 0) {
        start_signal = sig;
        throw Error(std::string("interrupted by SIG") + sigabbrev_np(sig) +
                    " while the world was starting");
      }
    });
    try {
      world->Start();
    } catch (...) {
      result.signal = start_signal;
      result.start_seconds = std::chrono::duration<double>(Clock::now() - starting).count();
      world->set_stop_check(nullptr);
      throw;
    }
    world->set_stop_check(nullptr);  // (model copies a script adds start in a step)
    started = true;
    // What a started world alone shows (its modules: a camera's renderer,
    // graphs) refuses the snapshot now, before the first step, not after
    // the last.
    if (options.save_state)
      if (const std::string why = world->SnapshotRefusal(); !why.empty())
        throw Error("--save-state: " + why);
    result.start_seconds = std::chrono::duration<double>(Clock::now() - starting).count();
    result.first_step = world->step_count();
    progress.Begin(world->time(), seconds());
    // --save-state: the world's state after step save_state_at (-1: the last).
    const auto save_state = [&] {
      if (!options.save_state) return;
      const int64_t at =
          options.save_state_at >= 0 ? options.save_state_at : result.first_step + options.steps;
      if (world->step_count() != at) return;
      const std::string bytes = world->SaveState(taken);
      if (const std::string reason = TryWriteFileAtomically(*options.save_state, bytes);
          !reason.empty())
        throw Error("--save-state: cannot write '" + options.save_state->string() + "': " + reason);
      result.saved_step = at;
      state_saved = true;
      std::vector<MetricSample>().swap(taken);
    };
    save_state();
    done(options.steps > 0 ? step_name() : "the stop of the world", options.steps > 0);
    for (int64_t i = 0; i < options.steps; ++i) {
      if (const int sig = StopSignals::Received(); sig != 0) {
        result.signal = sig;
        throw Error(std::string("interrupted by SIG") + sigabbrev_np(sig) + " after " +
                    std::to_string(result.steps) + " of " + std::to_string(options.steps) +
                    " steps");
      }
      world->Step();
      {
        const std::lock_guard lock(watchdog.io_mutex());
        ++result.steps;
      }
      save_state();
      done(result.steps < options.steps ? step_name() : "the stop of the world",
           result.steps < options.steps);
      progress.Update(result.steps, world->time(), seconds());
    }
    lua_kib =
        static_cast<double>(world->script_memory_bytes()) / 1024.0;  // before the states close
    world->Stop();
    done("writing the outputs", false);
    result.ok = true;
  } catch (const std::exception& e) {
    const std::lock_guard lock(watchdog.io_mutex());
    result.error.assign(e.what());
    // "std::bad_alloc" named nothing. Composed in the room reserved above
    // (std::to_string's few digits fit its inline buffer).
    if (dynamic_cast<const std::bad_alloc*>(&e) != nullptr) {
      result.error.assign("out of memory ");
      if (!started) {
        result.error.append("as the world started");
      } else if (result.steps < options.steps) {
        result.error.append("in step ");
        result.error.append(std::to_string(world->step_count() + 1));
      } else {
        result.error.append("at the end of the run");
      }
      result.error.append(
          " (the machine, a ulimit or --max-memory gave no more; what grows besides "
          "the robots: cameras' and vision sensors' images, paint, graphs, the "
          "scripts' data)");
    }
    // The states are still open after an error: what they held then.
    lua_kib = static_cast<double>(world->script_memory_bytes()) / 1024.0;
    take_metrics();  // whatever was recorded before the error
  }
}

// The summary table a run prints unless --quiet.
void PrintSummaryTable(const World& world, const RunOptions& options, const RunResult& result,
                       double lua_kib, std::ostream& out) {
  const int robots = world.live_robot_count();  // removed robots are not counted
  const double sim_time = FinishedTime(world, result);
  const double robot_ticks = static_cast<double>(robots) * static_cast<double>(result.steps);
  const double rtf =
      result.wall_seconds > 0 ? SimulatedThisRun(world, result) / result.wall_seconds : 0;
  const double ticks_per_s = result.wall_seconds > 0 ? robot_ticks / result.wall_seconds : 0;
  if (result.first_step > 0)
    out << "resumed at      step " << result.first_step << " (--load-state)\n";
  if (result.saved_step >= 0) out << "state saved     after step " << result.saved_step << "\n";
  out << "robots          " << robots << "\n"
      << "steps           " << result.steps << " (time step " << world.settings().time_step
      << " s, " << PhysicsLine(world) << ")\n"
      << "simulated time  " << Fixed(sim_time, 2) << " s\n"
      << "wall time       " << Fixed(result.wall_seconds, 3) << " s on " << world.threads()
      << (world.threads() == 1 ? " thread" : " threads") << ", of which "
      << Fixed(result.start_seconds, 3) << " s starting the world\n";
  if (options.load_seconds >= 0)
    out << "load time       " << Fixed(options.load_seconds, 3)
        << " s before that (reading the world, building its robots)\n";
  out << "real-time factor " << RealTimeFactorText(rtf) << "x\n"
      << "robot-ticks/s   " << Fixed(ticks_per_s, 0) << "\n"
      << "peak memory     " << Fixed(result.peak_rss_mb, 1) << " MiB ("
      << Fixed(robots > 0 ? result.peak_rss_mb * 1024 / robots : 0, 1)
      << " KiB per robot, of which Lua " << Fixed(robots > 0 ? lua_kib / robots : 0, 1) << ")\n"
      << "time per phase  (ms total, us per robot-tick)\n";
  for (size_t p = 0; p < static_cast<size_t>(Phase::kCount); ++p) {
    const double t = world.phase_times()[p];
    out << "  " << std::left << std::setw(9) << ToString(static_cast<Phase>(p)) << std::right
        << std::setw(10) << Fixed(1e3 * t, 1) << std::setw(10)
        << Fixed(robot_ticks > 0 ? 1e6 * t / robot_ticks : 0, 3) << "\n";
  }
  if (const auto& disabled = world.disabled_scripts(); !disabled.empty())
    out << "disabled scripts " << disabled.size()
        << " (on_script_error: disable_script), first: " << disabled.front() << "\n";
}

}  // namespace

RunResult RunWorld(World* world, const RunOptions& options, std::ostream& out,
                   std::ostream& progress_stream) {
  RunRecord record;
  RunResult& result = record.result;
  // Memory kept aside for the end of a run that ran out of it: given back
  // before the state hash and summary.json of a failed run are made (they
  // need some; without it the summary stayed "running" and the message was
  // main()'s generic one).
  // Not written, so not resident: address space, which is what a ulimit
  // counts and malloc gives back (a mapping of its own at this size). The
  // asm keeps the compiler from eliding the allocation.
  std::unique_ptr<char[]> memory_room(new char[kMemoryRoom]);
  asm volatile("" : : "r"(memory_room.get()) : "memory");
  const auto start = Clock::now();
  const bool tty = isatty(STDERR_FILENO) && &progress_stream == &std::cerr;
  StepProgress progress(progress_stream, options.steps, !options.quiet, tty, options.progress_note);
  // SIGINT, SIGTERM and SIGHUP end the run at the next step boundary, with
  // its outputs written (or, for a stuck step, through the Watchdog).
  const StopSignals stop_signals;
  // The steps, watched for one that never finishes.
  StepWatched(world, options, start, &progress, &record);
  progress.Finish();
  if (record.metrics) {
    try {
      record.metrics->Flush();
    } catch (const Error& e) {
      if (result.ok) {
        result.ok = false;
        result.error = e.what();
      }
    }
  }
  // Observers' files (paint.png), also after an error: the outputs so far.
  if (options.out_dir && world->started()) {
    try {
      world->WriteOutputs(*options.out_dir);
    } catch (const std::exception& e) {
      if (result.ok) {
        result.ok = false;
        result.error = e.what();
      }
    }
  }
  // A stop signal after the last step's check (while the world stopped or
  // the outputs were written: a large video's end takes seconds) is not
  // lost: the run ends as interrupted, saying that every step was run.
  if (const int sig = StopSignals::Received(); sig != 0 && result.ok) {
    result.ok = false;
    result.signal = sig;
    result.error = std::string("interrupted by SIG") + sigabbrev_np(sig) + " after all " +
                   std::to_string(result.steps) + " steps, while the run wrote its outputs";
  }
  result.wall_seconds = std::chrono::duration<double>(Clock::now() - start).count();
  if (!result.ok) memory_room.reset();
  // Out of memory after a failure (a script that filled it), the hash's
  // copies cannot be had: the run's own error stands, without a hash.
  if (options.state_hash || options.print_hash || options.out_dir) {
    try {
      result.state_hash = world->StateHash();
    } catch (const std::bad_alloc&) {
      if (result.ok) {
        result.ok = false;
        result.error.assign("out of memory while hashing the world's state at the end");
      }
    }
  }
  result.peak_rss_mb = PeakRssMb();

  // The summary.
  // (Not for a run that failed before its first step: the error says it all.)
  if (!options.quiet && (result.ok || result.steps > 0))
    PrintSummaryTable(*world, options, result, record.lua_kib, out);
  if (options.print_hash) out << "state-hash: " << StateHasher::ToHex(result.state_hash) << "\n";
  out << std::flush;

  // The last file: the room kept for it is given back first (a full disk).
  record.summary_room.Release();
  record.summary_descriptor.Release();
  // The folder removed or renamed while the run wrote into it (exit 0 and
  // no word before, the outputs gone or elsewhere): said, and no new
  // folder holding a summary.json without the files it lists.
  if (record.out_folder && FolderIdentity(*options.out_dir) != record.out_folder) {
    if (result.error.find("the output folder '") != std::string::npos) return result;  // said
    const std::string message = "the output folder '" + options.out_dir->string() +
                                "' was removed or renamed during the run; the outputs written "
                                "into it went with it, and its summary.json is not written";
    if (result.ok) {
      result.ok = false;
      result.error = message;
    } else {
      result.error += "; " + message;
    }
    return result;
  }
  if (options.out_dir && std::filesystem::is_directory(*options.out_dir)) {
    if (const std::string reason =
            WriteSummary(*world, options, result, record.lua_kib, /*complete=*/true);
        !reason.empty()) {
      const std::string message =
          "cannot write '" + (*options.out_dir / "summary.json").string() + "': " + reason;
      if (result.ok) {
        result.ok = false;
        result.error = message;
      } else if (result.error.find(message) == std::string::npos) {
        result.error += "; " + message;  // said once (the first summary's failure may be it)
      }
    }
  }
  return result;
}

}  // namespace swarmsim
