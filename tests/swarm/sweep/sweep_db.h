// A sweep's results database as the sweep tests read it (runs, their
// parameters, counts), and the sweep world they run.
#pragma once

#include <unistd.h>

#include <cstdint>
#include <filesystem>
#include <map>
#include <string>

#include "swarm/sweep/sqlite_db.h"

namespace swarmsim::sweep_testing {

namespace fs = std::filesystem;

// A few bots, a Lua error or busy work on request (its parameters fail_at, spin).
inline const std::string kWorld = std::string(SWARMSIM_SOURCE_DIR) + "/tests/data/sweep/sweep.yaml";

// An empty folder of this process's own, `name` in its name.
inline fs::path TempDir(const std::string& name) {
  const fs::path dir =
      fs::temp_directory_path() / ("swarmsim_sweep_" + name + "_" + std::to_string(getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

struct RunRow {
  std::string status, error, hash, finished_at;
  int64_t attempts = 0;
  std::map<std::string, std::string> params;
  uint64_t seed = 0;
};

inline std::map<int64_t, RunRow> ReadRuns(const fs::path& db_path) {
  SqliteDb db(db_path, /*read_only=*/true);
  std::map<int64_t, RunRow> runs;
  SqliteStatement q(&db,
                    "SELECT id, status, coalesce(error, ''), coalesce(state_hash, ''), attempts, "
                    "coalesce(finished_at, ''), seed FROM runs");
  while (q.Step())
    runs[q.Int(0)] = {
        q.Text(1), q.Text(2), q.Text(3), q.Text(5), q.Int(4), {}, static_cast<uint64_t>(q.Int(6))};
  SqliteStatement p(&db, "SELECT run, name, value FROM run_params");
  while (p.Step()) runs[p.Int(0)].params[p.Text(1)] = p.Text(2);
  return runs;
}

inline int64_t Count(const fs::path& db_path, const std::string& sql) {
  SqliteDb db(db_path, /*read_only=*/true);
  SqliteStatement q(&db, sql);
  return q.Step() ? q.Int(0) : -1;
}

}  // namespace swarmsim::sweep_testing
