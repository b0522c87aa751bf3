// The results database of a sweep (SQLite, WAL journal).
//
// Tables:
//   sweep          one row: world path and content hash, parameter space (JSON),
//                  run length, start time, swarmsim version, command
//   runs           one row per run of the grid: point, seed, parameters (JSON),
//                  status pending | running | ok | failed, error, wall time,
//                  steps, robots, state hash, attempts, worker
//   run_params     (run, name, value): the parameters, one row each
//   final_metrics  (run, metric, value): each metric's last recorded value
//   series         (run, metric, step, time, value): metric time series; a
//                  per-robot metric is stored as its mean over the robots
//
// A run is claimed (running) before it starts and completed (ok/failed, with
// its metrics and series) in one transaction. A run found `running` when a
// sweep starts was interrupted: it is put back to pending and run again.
#pragma once

#include <cstdint>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "swarm/sweep/grid.h"
#include "swarm/sweep/sqlite_db.h"

namespace swarmsim {

struct SweepRecord {
  std::string world_path;
  std::string world_hash;
  std::string space_json;  // parameters, seeds, run length: the sweep's identity
  std::string started_at;  // UTC, ISO 8601
  std::string version;
  std::string command;
};

struct SeriesPoint {
  std::string metric;
  int64_t step = 0;
  double time = 0;
  double value = 0;
};

// What one finished run produced.
struct RunOutcome {
  int64_t id = 0;
  bool ok = false;
  std::string error;
  // The machine, not the world, failed the run (its disk full, no file or
  // thread left to open or start): not recorded; the sweep stops there.
  bool machine = false;
  double wall_s = 0;
  int64_t steps = 0;
  int64_t robots = 0;
  std::string state_hash;
  std::string worker;  // host:pid that ran it
  std::map<std::string, double> final_metrics;
  std::vector<SeriesPoint> series;
};

struct RunCounts {
  int64_t total = 0, pending = 0, running = 0, ok = 0, failed = 0;
};

class ResultsDb {
 public:
  explicit ResultsDb(const std::filesystem::path& path, bool read_only = false);

  std::optional<SweepRecord> ReadSweep();
  // Creates the tables, the sweep row and one pending row per run (one transaction).
  void CreateSweep(const SweepRecord& sweep, const std::vector<GridRun>& runs);
  // The world file's hash each run completed from now on is stored with
  // (runs.world_hash): a sweep resumed with --allow-changed-world keeps its
  // first hash in the sweep row and records which runs ran the edited file.
  void set_run_world_hash(std::string hash) { run_world_hash_ = std::move(hash); }
  // How many runs of shard `index` of `count` (ids (id - 1) % count == index) failed.
  int64_t CountFailed(int count, int index);
  // How many different world files the finished runs ran (runs.world_hash,
  // a run without one counted as the sweep's first).
  int64_t WorldVersions();
  // running -> pending; returns how many.
  int64_t ResetInterrupted();
  // failed -> pending; returns how many.
  int64_t ResetFailed();
  RunCounts Counts();
  // Pending runs, in id order, with their parameters.
  std::vector<GridRun> PendingRuns();
  void Claim(int64_t id, const std::string& worker);
  // Stores the outcome, its metrics and series; one transaction.
  void Complete(const RunOutcome& outcome);

  SqliteDb& db() { return db_; }

 private:
  SqliteDb db_;
  std::string run_world_hash_;
};

// Whether `table` (of schema `schema`: "main", or an attached one) has `column`.
bool HasColumn(SqliteDb* db, const std::string& schema, const std::string& table,
               const std::string& column);

// Current UTC time as ISO 8601.
std::string UtcNow();

}  // namespace swarmsim
