#include "swarm/sweep/coordinator.h"

#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <csignal>
#include <cstdint>
#include <cstring>
#include <deque>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>
#include <thread>

#include "framework/error.h"
#include "framework/memory_forecast.h"
#include "framework/registry.h"
#include "modules/builtin.h"
#include "swarm/loader/values.h"
#include "swarm/loader/world_loader.h"
#include "swarm/run/file_lock.h"
#include "swarm/run/stop_signals.h"
#include "swarm/run/version.h"
#include "swarm/sweep/progress.h"

namespace swarmsim {
namespace {

// Loads the world once with the first run's parameters, so that a misspelt
// --param or a bad value is one clear error instead of every run failing;
// every other value of a world parameter is checked against its type there
// (a number, true/false; text takes anything) as `run --set` would.
void CheckWorld(const SweepOptions& o, const GridRun& first, const std::vector<ParamSpec>& params) {
  ModuleRegistry registry;
  RegisterBuiltinModules(&registry);
  LoadOptions load;
  load.overrides = first.params;
  load.override_option = "--param";
  load.seed = first.seed;
  load.threads = 1;
  LoadedWorld loaded;
  try {
    loaded = LoadWorld(o.world, load, registry);
  } catch (const Error& e) {
    const std::string message = e.what();
    if (message.starts_with(load.override_option + " ")) throw;  // names the --param already
    std::string point;
    for (const auto& [name, value] : first.params) point += name + "=" + value + ", ";
    throw Error("the sweep's first run (" + point + "seed " + std::to_string(first.seed) +
                ") does not load, so the sweep does not start: " + message);
  }
  if (!o.steps && !o.duration && !loaded.steps)
    throw Error(o.world + " gives no run length; pass --steps N or --duration SECONDS");
  // As `run` refuses it, before any run (else every run fails the same way).
  if (!o.steps && o.duration && *o.duration > 0 && *o.duration < loaded.world->settings().time_step)
    throw Error("--duration " + FormatNumber(*o.duration) + " s is shorter than one time step (" +
                FormatNumber(loaded.world->settings().time_step) + " s)");
  for (const ParamSpec& p : params) {
    const auto declared = loaded.world->parameters().find(p.name);
    if (declared == loaded.world->parameters().end()) continue;  // a model's (the first run's)
    for (const std::string& value : p.values)
      if (!loader::AsDeclaredType(value, declared->second))
        throw Error("--param " + p.name + "=" + p.spec + ": parameter '" + p.name + "' is " +
                    loader::TypeName(declared->second) + ", got \"" + value + "\"");
  }
}

}  // namespace

int RunsSideBySide(int jobs, size_t pending) {
  return static_cast<int>(
      std::min<size_t>(static_cast<size_t>(std::max(jobs, 1)), std::max<size_t>(pending, 1)));
}

std::string RunMemoryCap(const std::string& max_memory, int jobs, uint64_t available) {
  if (!max_memory.empty()) return max_memory;
  if (jobs <= 1 || available == UINT64_MAX) return "";
  return std::to_string(std::max<uint64_t>(available / static_cast<uint64_t>(jobs), 1));
}

WorkerConfig MakeWorkerConfig(const SweepOptions& o, int jobs) {
  WorkerConfig c;
  c.self_exe = o.self_exe;
  c.world = o.world;
  c.steps = o.steps;
  c.duration = o.duration;
  c.threads_per_run = o.threads_per_run;
  c.timeout_s = o.timeout_s;
  c.max_memory = RunMemoryCap(o.max_memory, jobs, ReadMemoryRoom(0).available);
  c.scratch =
      std::filesystem::temp_directory_path() / ("swarmsim-sweep-" + std::to_string(getpid()));
  return c;
}

std::string WorldFileHash(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  if (!f) throw Error("cannot read world file '" + path + "'");
  std::ostringstream s;
  s << f.rdbuf();
  // FNV-1a, 64 bits: a change detector, not a security hash.
  uint64_t h = 1469598103934665603ull;
  for (unsigned char c : s.str()) h = (h ^ c) * 1099511628211ull;
  char buf[17];
  std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(h));
  return buf;
}

std::string SweepSpace(const std::vector<ParamSpec>& params, const std::vector<uint64_t>& seeds,
                       const std::optional<int64_t>& steps, const std::optional<double>& duration) {
  nlohmann::json j;
  j["params"] = nlohmann::json::array();
  for (const ParamSpec& p : params)
    j["params"].push_back(
        {{"name", p.name}, {"spec", p.spec}, {"kind", p.kind}, {"values", p.values}});
  j["seeds"] = seeds;
  j["steps"] = steps ? nlohmann::json(*steps) : nlohmann::json(nullptr);
  j["duration"] = duration ? nlohmann::json(*duration) : nlohmann::json(nullptr);
  return j.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
}

int CoordinateSweep(const SweepOptions& o, RemoteWorkers* remote, std::ostream& out,
                    std::ostream& err) {
  // SIGINT, SIGTERM and SIGHUP stop a sweep between runs: the runs in
  // progress are killed and stay claimed (a resume runs them again), the
  // finished ones are kept.
  const StopSignals stop_signals;
  // The grid and the sweep's identity.
  std::vector<ParamSpec> params;
  for (const std::string& p : o.params) params.push_back(ParseParamSpec(p));
  const std::vector<uint64_t> seeds = ParseSeeds(o.seeds);
  const std::vector<GridRun> grid = ExpandGrid(params, seeds);
  const std::string world_hash = WorldFileHash(o.world);
  const std::string space = SweepSpace(params, seeds, o.steps, o.duration);
  if (o.db.empty()) throw Error("sweep needs --db FILE for the results");
  // DB.lock (flock, not the database file: SQLite locks that with fcntl). A
  // second sweep on the same database would reset the first's runs in
  // progress as if it had stopped, and run them again beside it.
  const FileLock lock(o.db + ".lock");
  if (!lock.held())
    throw Error("another sweep" +
                (lock.holder().empty() ? std::string() : " (process " + lock.holder() + ")") +
                " is running on '" + o.db +
                "'; wait for it to finish (a sweep that stopped is resumed by running the same "
                "command again), or use another --db");

  // A new sweep: check the world and parameters before creating the database.
  if (!std::filesystem::exists(o.db)) CheckWorld(o, grid.front(), params);
  ResultsDb db(o.db);
  if (std::optional<SweepRecord> existing = db.ReadSweep()) {
    if (existing->space_json != space)
      throw Error("'" + o.db + "' holds another sweep (different parameters, seeds or run " +
                  "length); resume it with the same command or use another --db");
    if (existing->world_hash != world_hash) {
      if (!o.allow_changed_world)
        throw Error((existing->world_path == o.world
                         ? "world file '" + o.world + "' has changed since this sweep began (" +
                               existing->started_at + ")"
                         : "'" + o.db + "' holds a sweep of world file '" + existing->world_path +
                               "' (begun " + existing->started_at + "), and '" + o.world +
                               "' differs from it") +
                    "; its runs would mix two worlds. Pass " +
                    "--allow-changed-world to continue anyway, or use another --db");
      err << "warning: world file changed since the sweep began; continuing as asked (the "
          << "runs it runs record its new hash in runs.world_hash; the sweep keeps its first)\n";
    }
    if (const int64_t n = db.ResetInterrupted(); n > 0)
      err << "resuming: " << n << " run" << (n == 1 ? " was" : "s were")
          << " in progress when the sweep stopped; running again\n";
  } else {
    SweepRecord record{o.world, world_hash, space, UtcNow(), Version(), o.command_line};
    db.CreateSweep(record, grid);
  }
  db.set_run_world_hash(world_hash);
  if (o.retry_failed) {
    if (const int64_t n = db.ResetFailed(); n > 0) err << "retrying " << n << " failed runs\n";
  }

  // This shard's pending runs.
  std::deque<GridRun> pending;
  for (GridRun& r : db.PendingRuns())
    if ((r.id - 1) % o.shard_count == o.shard_index) pending.push_back(std::move(r));
  const RunCounts before = db.Counts();
  const int64_t shard_total =
      o.shard_count == 1 ? before.total
                         : (before.total - o.shard_index + o.shard_count - 1) / o.shard_count;
  const int64_t already = shard_total - static_cast<int64_t>(pending.size());
  const int jobs =
      o.jobs > 0 ? o.jobs : (remote ? 1 : std::max(1u, std::thread::hardware_concurrency()));
  if (!o.quiet)
    err << "sweep: " << before.total << " runs (" << grid.size() / seeds.size() << " points x "
        << seeds.size() << " seeds)"
        << (o.shard_count > 1
                ? ", shard " + std::to_string(o.shard_index) + "/" + std::to_string(o.shard_count)
                : std::string())
        << ", " << already << " already finished, " << pending.size() << " to run on " << jobs
        << (jobs == 1 ? " job" : " jobs") << (remote ? " here plus the other ranks" : "") << "\n";

  const int side_by_side = RunsSideBySide(jobs, pending.size());
  const WorkerConfig config = MakeWorkerConfig(o, side_by_side);
  // A cap the user did not give shows up in a refused run's message as
  // "--max-memory ...": say here where it comes from.
  if (!o.quiet && o.max_memory.empty() && !config.max_memory.empty())
    err << "sweep: each run may take up to "
        << FormatSize(static_cast<double>(std::stoull(config.max_memory)))
        << " (the memory available now, shared by " << side_by_side
        << " runs side by side; sweep --max-memory sets it)\n";

  SweepProgress progress(err, shard_total, already, db.CountFailed(o.shard_count, o.shard_index),
                         isatty(STDERR_FILENO) != 0, !o.quiet);
  RunPool pool(config, jobs);
  const std::string me = WorkerName();
  auto next = [&]() -> std::optional<GridRun> {
    if (pending.empty()) return std::nullopt;
    GridRun r = std::move(pending.front());
    pending.pop_front();
    db.Claim(r.id, me);
    return r;
  };
  auto running = [&] { return pool.active() + (remote ? remote->Running() : 0); };
  int stop_signal = 0;
  // The first run the machine failed (a full disk): the sweep stops there.
  std::optional<RunOutcome> machine_failure;
  auto done = [&](RunOutcome outcome) {
    // After a stop signal, a run that did not finish (the signal reached it
    // too) is no result: it stays claimed and runs again on resume.
    if (!outcome.ok && (stop_signal != 0 || StopSignals::Received() != 0)) return;
    // Nor is a run the machine failed (every run after it would fail the
    // same way, and be recorded as failed for good: a full TMPDIR burnt
    // through the grid in seconds). No new runs; those in progress finish.
    if (outcome.machine) {
      if (!machine_failure) machine_failure = std::move(outcome);
      pending.clear();
      return;
    }
    db.Complete(outcome);
    progress.RunEnded(outcome.id, outcome.ok, outcome.error, running());
  };
  // Out of room for the database, or no scratch folder or process to be
  // had: the finished runs are in the database; the same command resumes.
  try {
    while (!pending.empty() || pool.active() > 0 || (remote && remote->Busy())) {
      if (stop_signal == 0 && StopSignals::Received() != 0) {
        // Stop: no new runs (the other ranks are told so as they ask), the
        // local runs in progress killed.
        stop_signal = StopSignals::Received();
        pending.clear();
        pool.KillAll();
        continue;
      }
      while (pool.HasFreeSlot() && !pending.empty()) pool.Start(*next());
      if (remote) remote->Service(next, done);
      for (RunOutcome& outcome : pool.Poll(remote ? 0.002 : 0.5)) done(std::move(outcome));
    }
  } catch (const Error& e) {
    pool.KillAll();
    progress.Finish();
    throw Error(std::string(e.what()) +
                "; the runs finished before it are kept in the database: mend this and run the "
                "same command to resume");
  }
  progress.Finish();
  const RunCounts after = db.Counts();
  out << "sweep: " << after.ok << " ok, " << after.failed << " failed, "
      << after.pending + after.running << " not run, of " << after.total << " runs; results in "
      << o.db << "\n"
      << std::flush;
  if (stop_signal != 0) {
    err << "sweep: interrupted by SIG" << sigabbrev_np(stop_signal) << ": "
        << after.ok + after.failed << " of " << after.total << " runs done (" << after.failed
        << " failed)";
    if (after.running > 0)
      err << ", " << after.running << (after.running == 1 ? " run" : " runs")
          << " in progress stopped (run again on resume)";
    err << ". Run the same command to resume; finished runs are kept.\n" << std::flush;
    return 128 + stop_signal;
  }
  if (machine_failure) {
    // The run's error line, not the notes before it (lines of its stderr
    // joined by " | ").
    std::string why = machine_failure->error;
    if (const size_t at = why.rfind("error: "); at != std::string::npos) why.erase(0, at + 7);
    const bool disk = why.find("No space left") != std::string::npos ||
                      why.find("quota") != std::string::npos ||
                      why.find("Read-only") != std::string::npos;
    err << "sweep: stopped: run " << machine_failure->id
        << " could not run on this machine, and the next ones would not either: " << why
        << (disk ? " (the runs write their outputs under " + config.scratch.parent_path().string() +
                       ", $TMPDIR)"
                 : std::string())
        << ". It is not recorded as failed: " << (disk ? "free the room" : "raise the limit")
        << " and run the same command to resume; finished runs are kept.\n"
        << std::flush;
    return 1;
  }
  if (after.failed > 0) {
    err << "sweep: " << after.failed << (after.failed == 1 ? " run" : " runs")
        << " failed or timed out (exit status 1): `swarmsim report " << o.db
        << "` lists them; --retry-failed runs them again\n"
        << std::flush;
    return 1;
  }
  return 0;
}

}  // namespace swarmsim
