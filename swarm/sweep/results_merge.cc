#include "swarm/sweep/results_merge.h"

#include <filesystem>
#include <ostream>

#include "framework/error.h"
#include "framework/regular_file.h"
#include "swarm/sweep/results_db.h"

namespace swarmsim {

int RunMerge(const std::string& out_db, const std::vector<std::string>& inputs,
             bool allow_changed_world, std::ostream& out, std::ostream& err) {
  // Every input is checked before the output is touched: one that does not
  // fit left the output holding the inputs before it (or an empty database).
  {
    std::optional<SweepRecord> first;
    std::string first_name = out_db;
    if (std::filesystem::exists(out_db)) first = ResultsDb(out_db, /*read_only=*/true).ReadSweep();
    for (const std::string& input : inputs) {
      if (!std::filesystem::exists(input)) throw Error("no database '" + input + "'");
      if (SameFile(input, out_db)) throw Error("'" + input + "' is the output database");
      const std::optional<SweepRecord> theirs = ResultsDb(input, /*read_only=*/true).ReadSweep();
      if (!theirs) throw Error("'" + input + "' holds no sweep");
      if (!first) {
        first = theirs;
        first_name = input;
        continue;
      }
      if (first->space_json != theirs->space_json)
        throw Error("'" + input + "' holds another sweep (different parameters, seeds or " +
                    "run length) than '" + first_name + "'");
      if (first->world_hash != theirs->world_hash && !allow_changed_world)
        throw Error("'" + input + "' ran a different version of the world file than '" +
                    first_name + "'; pass --allow-changed-world to merge anyway");
    }
  }
  ResultsDb results(out_db);
  SqliteDb& db = results.db();
  for (const std::string& input : inputs) {
    {
      ResultsDb in(input, /*read_only=*/true);
      const std::optional<SweepRecord> theirs = in.ReadSweep();
      if (!theirs) throw Error("'" + input + "' holds no sweep");
      std::optional<SweepRecord> ours = results.ReadSweep();
      if (!ours) {
        // The first input gives the sweep and its grid; every run starts pending.
        SqliteStatement attach(&db, "ATTACH DATABASE ? AS src");
        attach.Bind(1, input).Run();
        SqliteTransaction txn(&db);
        db.Exec("INSERT INTO sweep SELECT * FROM src.sweep");
        db.Exec(
            "INSERT INTO runs (id, point, seed, params) SELECT id, point, seed, params "
            "FROM src.runs");
        db.Exec("INSERT INTO run_params SELECT * FROM src.run_params");
        txn.Commit();
        db.Exec("DETACH DATABASE src");
      } else {
        if (ours->space_json != theirs->space_json)
          throw Error("'" + input + "' holds another sweep (different parameters, seeds or " +
                      "run length) than '" + out_db + "'");
        if (ours->world_hash != theirs->world_hash && !allow_changed_world)
          throw Error("'" + input + "' ran a different version of the world file than '" + out_db +
                      "'; pass --allow-changed-world to merge anyway");
      }
    }
    SqliteStatement attach(&db, "ATTACH DATABASE ? AS src");
    attach.Bind(1, input).Run();
    SqliteTransaction txn(&db);
    db.Exec("DROP TABLE IF EXISTS temp.take");
    db.Exec(
        "CREATE TEMP TABLE take AS SELECT s.id AS id FROM src.runs s JOIN main.runs m "
        "ON m.id = s.id WHERE (s.status IN ('ok', 'failed') AND m.status IN ('pending', "
        "'running')) OR (s.status = 'ok' AND m.status = 'failed')");
    // A run that finished here and failed there (or both): kept as it is.
    // One that failed here and finished ok there: the ok one, counted.
    SqliteStatement dup(&db,
                        "SELECT count(*) FROM src.runs s JOIN main.runs m ON m.id = s.id "
                        "WHERE s.status IN ('ok', 'failed') AND m.status IN ('ok', 'failed') "
                        "AND NOT (s.status = 'ok' AND m.status = 'failed')");
    dup.Step();
    const int64_t duplicates = dup.Int(0);
    dup.Reset();
    SqliteStatement over(&db,
                         "SELECT count(*) FROM src.runs s JOIN main.runs m ON m.id = s.id "
                         "WHERE s.status = 'ok' AND m.status = 'failed'");
    over.Step();
    const int64_t replaced = over.Int(0);
    over.Reset();
    db.Exec("DELETE FROM main.final_metrics WHERE run IN (SELECT id FROM take)");
    db.Exec("DELETE FROM main.series WHERE run IN (SELECT id FROM take)");
    // The world file each run ran: its own record, or (a sweep from before
    // runs recorded one) its sweep's.
    const std::string world_hash = HasColumn(&db, "src", "runs", "world_hash")
                                       ? "coalesce(world_hash, (SELECT world_hash FROM src.sweep))"
                                       : "(SELECT world_hash FROM src.sweep)";
    db.Exec(
        "UPDATE main.runs SET (status, error, wall_s, steps, robots, state_hash, attempts, "
        "worker, started_at, finished_at, world_hash) = (SELECT status, error, wall_s, steps, "
        "robots, state_hash, attempts, worker, started_at, finished_at, " +
        world_hash + " FROM src.runs s WHERE s.id = runs.id) WHERE id IN (SELECT id FROM take)");
    db.Exec(
        "INSERT INTO main.final_metrics SELECT * FROM src.final_metrics WHERE run IN "
        "(SELECT id FROM take)");
    db.Exec("INSERT INTO main.series SELECT * FROM src.series WHERE run IN (SELECT id FROM take)");
    SqliteStatement taken(&db, "SELECT count(*) FROM take");
    taken.Step();
    const int64_t copied = taken.Int(0);
    taken.Reset();
    db.Exec("DROP TABLE temp.take");
    txn.Commit();
    db.Exec("DETACH DATABASE src");
    out << "merge: " << input << ": " << copied << " runs copied";
    if (replaced > 0)
      out << " (" << replaced << " of them ok where " << out_db << " had them failed)";
    if (duplicates > 0) out << ", " << duplicates << " already in " << out_db << " (kept once)";
    out << "\n";
  }
  const RunCounts c = results.Counts();
  out << "merge: " << out_db << " has " << c.ok + c.failed << " of " << c.total
      << " runs finished (" << c.failed << " failed)";
  if (c.pending + c.running > 0)
    out << "; run the sweep again with --db " << out_db << " for the other "
        << c.pending + c.running;
  out << "\n";
  (void)err;
  return 0;
}

}  // namespace swarmsim
