#include "swarm/sweep/results_db.h"

#include <ctime>
#include <nlohmann/json.hpp>
#include <string>
#include <system_error>
#include <vector>

#include "framework/error.h"

namespace swarmsim {
namespace {

constexpr const char* kSchema = R"sql(
CREATE TABLE IF NOT EXISTS sweep (
  id INTEGER PRIMARY KEY CHECK (id = 1),
  world_path TEXT NOT NULL, world_hash TEXT NOT NULL, space TEXT NOT NULL,
  started_at TEXT NOT NULL, version TEXT NOT NULL, command TEXT NOT NULL);
CREATE TABLE IF NOT EXISTS runs (
  id INTEGER PRIMARY KEY, point INTEGER NOT NULL, seed INTEGER NOT NULL,
  params TEXT NOT NULL,
  status TEXT NOT NULL DEFAULT 'pending'
    CHECK (status IN ('pending', 'running', 'ok', 'failed')),
  error TEXT, wall_s REAL, steps INTEGER, robots INTEGER, state_hash TEXT,
  attempts INTEGER NOT NULL DEFAULT 0, worker TEXT, started_at TEXT, finished_at TEXT);
CREATE INDEX IF NOT EXISTS runs_status ON runs (status);
CREATE TABLE IF NOT EXISTS run_params (
  run INTEGER NOT NULL REFERENCES runs (id), name TEXT NOT NULL, value TEXT NOT NULL,
  PRIMARY KEY (run, name));
CREATE TABLE IF NOT EXISTS final_metrics (
  run INTEGER NOT NULL REFERENCES runs (id), metric TEXT NOT NULL, value REAL,
  PRIMARY KEY (run, metric));
CREATE TABLE IF NOT EXISTS series (
  run INTEGER NOT NULL REFERENCES runs (id), metric TEXT NOT NULL, step INTEGER NOT NULL,
  time REAL NOT NULL, value REAL);
CREATE INDEX IF NOT EXISTS series_run ON series (run, metric, step);
)sql";

}  // namespace

std::string UtcNow() {
  const std::time_t now = std::time(nullptr);
  std::tm tm{};
  gmtime_r(&now, &tm);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%SZ", &tm);
  return buf;
}

namespace {

// `path`, once a look at it without writing shows it is new, empty or a
// sweep's: a database of something else is refused before the sweep's
// tables (and WAL mode) would be added to it.
const std::filesystem::path& SweepDatabase(const std::filesystem::path& path) {
  std::error_code ec;
  if (!std::filesystem::exists(path, ec) || std::filesystem::file_size(path, ec) == 0) return path;
  SqliteDb look(path, /*read_only=*/true);
  SqliteStatement tables(&look, "SELECT name FROM sqlite_master WHERE type = 'table'");
  std::vector<std::string> names;
  bool sweep = false;
  while (tables.Step()) {
    names.push_back(tables.Text(0));
    sweep = sweep || names.back() == "sweep";
  }
  if (!names.empty() && !sweep) {
    std::string list;
    for (size_t i = 0; i < names.size() && i < 5; ++i) list += (i ? ", " : "") + names[i];
    if (names.size() > 5) list += ", ...";
    throw Error("database '" + path.string() + "' is not a sweep's (it holds the tables " + list +
                "): name a new file for --db, or one a sweep made");
  }
  return path;
}

}  // namespace

ResultsDb::ResultsDb(const std::filesystem::path& path, bool read_only)
    : db_(SweepDatabase(path), read_only) {
  if (read_only) return;
  db_.Exec(kSchema);
  // Databases of sweeps from before runs recorded their world file's hash.
  if (!HasColumn(&db_, "main", "runs", "world_hash"))
    db_.Exec("ALTER TABLE runs ADD COLUMN world_hash TEXT");
}

bool HasColumn(SqliteDb* db, const std::string& schema, const std::string& table,
               const std::string& column) {
  SqliteStatement q(db, "PRAGMA " + schema + ".table_info(" + table + ")");
  while (q.Step())
    if (q.Text(1) == column) return true;
  return false;
}

int64_t ResultsDb::CountFailed(int count, int index) {
  SqliteStatement q(&db_, "SELECT count(*) FROM runs WHERE status = 'failed' AND (id - 1) % ? = ?");
  q.Bind(1, static_cast<int64_t>(count)).Bind(2, static_cast<int64_t>(index));
  q.Step();
  return q.Int(0);
}

int64_t ResultsDb::WorldVersions() {
  if (!HasColumn(&db_, "main", "runs", "world_hash")) return 1;
  SqliteStatement q(&db_,
                    "SELECT count(DISTINCT coalesce(r.world_hash, s.world_hash)) FROM runs r, "
                    "sweep s WHERE r.status IN ('ok', 'failed')");
  q.Step();
  return q.Int(0);
}

std::optional<SweepRecord> ResultsDb::ReadSweep() {
  SqliteStatement has(&db_, "SELECT count(*) FROM sqlite_master WHERE name = 'sweep'");
  if (!has.Step() || has.Int(0) == 0) return std::nullopt;
  SqliteStatement q(
      &db_, "SELECT world_path, world_hash, space, started_at, version, command FROM sweep");
  if (!q.Step()) return std::nullopt;
  return SweepRecord{q.Text(0), q.Text(1), q.Text(2), q.Text(3), q.Text(4), q.Text(5)};
}

void ResultsDb::CreateSweep(const SweepRecord& sweep, const std::vector<GridRun>& runs) {
  SqliteTransaction txn(&db_);
  SqliteStatement s(&db_,
                    "INSERT INTO sweep (id, world_path, world_hash, space, started_at, version, "
                    "command) VALUES (1, ?, ?, ?, ?, ?, ?)");
  s.Bind(1, sweep.world_path).Bind(2, sweep.world_hash).Bind(3, sweep.space_json);
  s.Bind(4, sweep.started_at).Bind(5, sweep.version).Bind(6, sweep.command).Run();
  SqliteStatement r(&db_, "INSERT INTO runs (id, point, seed, params) VALUES (?, ?, ?, ?)");
  SqliteStatement p(&db_, "INSERT INTO run_params (run, name, value) VALUES (?, ?, ?)");
  for (const GridRun& run : runs) {
    nlohmann::json params = nlohmann::json::object();
    for (const auto& [name, value] : run.params) params[name] = value;
    r.Bind(1, run.id).Bind(2, run.point).Bind(3, static_cast<int64_t>(run.seed));
    r.Bind(4, params.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace)).Run();
    for (const auto& [name, value] : run.params)
      p.Bind(1, run.id).Bind(2, name).Bind(3, value).Run();
  }
  txn.Commit();
}

int64_t ResultsDb::ResetInterrupted() {
  db_.Exec("UPDATE runs SET status = 'pending' WHERE status = 'running'");
  SqliteStatement q(&db_, "SELECT changes()");
  q.Step();
  return q.Int(0);
}

int64_t ResultsDb::ResetFailed() {
  SqliteTransaction txn(&db_);
  db_.Exec("DELETE FROM final_metrics WHERE run IN (SELECT id FROM runs WHERE status = 'failed')");
  db_.Exec("DELETE FROM series WHERE run IN (SELECT id FROM runs WHERE status = 'failed')");
  db_.Exec("UPDATE runs SET status = 'pending', error = NULL WHERE status = 'failed'");
  SqliteStatement q(&db_, "SELECT changes()");
  q.Step();
  const int64_t n = q.Int(0);
  txn.Commit();
  return n;
}

RunCounts ResultsDb::Counts() {
  RunCounts c;
  SqliteStatement q(&db_, "SELECT status, count(*) FROM runs GROUP BY status");
  while (q.Step()) {
    const std::string status = q.Text(0);
    const int64_t n = q.Int(1);
    c.total += n;
    if (status == "pending")
      c.pending = n;
    else if (status == "running")
      c.running = n;
    else if (status == "ok")
      c.ok = n;
    else if (status == "failed")
      c.failed = n;
  }
  return c;
}

std::vector<GridRun> ResultsDb::PendingRuns() {
  std::vector<GridRun> runs;
  SqliteStatement q(
      &db_, "SELECT id, point, seed, params FROM runs WHERE status = 'pending' ORDER BY id");
  SqliteStatement p(&db_, "SELECT name, value FROM run_params WHERE run = ?");
  while (q.Step()) {
    GridRun r;
    r.id = q.Int(0);
    r.point = q.Int(1);
    r.seed = static_cast<uint64_t>(q.Int(2));
    p.Bind(1, r.id);
    while (p.Step()) r.params.emplace_back(p.Text(0), p.Text(1));
    p.Reset();
    runs.push_back(std::move(r));
  }
  return runs;
}

void ResultsDb::Claim(int64_t id, const std::string& worker) {
  SqliteStatement s(&db_,
                    "UPDATE runs SET status = 'running', attempts = attempts + 1, worker = ?, "
                    "started_at = ? WHERE id = ? AND status = 'pending'");
  s.Bind(1, worker).Bind(2, UtcNow()).Bind(3, id).Run();
}

void ResultsDb::Complete(const RunOutcome& o) {
  SqliteTransaction txn(&db_);
  SqliteStatement del_m(&db_, "DELETE FROM final_metrics WHERE run = ?");
  del_m.Bind(1, o.id).Run();
  SqliteStatement del_s(&db_, "DELETE FROM series WHERE run = ?");
  del_s.Bind(1, o.id).Run();
  SqliteStatement u(&db_,
                    "UPDATE runs SET status = ?, error = ?, wall_s = ?, steps = ?, robots = ?, "
                    "state_hash = ?, worker = coalesce(?, worker), finished_at = ?, world_hash = ? "
                    "WHERE id = ?");
  u.Bind(1, std::string(o.ok ? "ok" : "failed"));
  if (o.ok)
    u.BindNull(2);
  else
    u.Bind(2, o.error);
  u.Bind(3, o.wall_s).Bind(4, o.steps).Bind(5, o.robots);
  if (o.state_hash.empty())
    u.BindNull(6);
  else
    u.Bind(6, o.state_hash);
  if (o.worker.empty())
    u.BindNull(7);
  else
    u.Bind(7, o.worker);
  u.Bind(8, UtcNow());
  if (run_world_hash_.empty())
    u.BindNull(9);
  else
    u.Bind(9, run_world_hash_);
  u.Bind(10, o.id).Run();
  SqliteStatement m(&db_, "INSERT INTO final_metrics (run, metric, value) VALUES (?, ?, ?)");
  for (const auto& [name, value] : o.final_metrics)
    m.Bind(1, o.id).Bind(2, name).Bind(3, value).Run();
  SqliteStatement s(&db_,
                    "INSERT INTO series (run, metric, step, time, value) VALUES (?, ?, ?, ?, ?)");
  for (const SeriesPoint& p : o.series)
    s.Bind(1, o.id).Bind(2, p.metric).Bind(3, p.step).Bind(4, p.time).Bind(5, p.value).Run();
  txn.Commit();
}

}  // namespace swarmsim
