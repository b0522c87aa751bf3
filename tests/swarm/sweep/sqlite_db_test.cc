// The SQLite layer of sweep databases (swarm/sweep/sqlite_db.cc): values
// round-trip, errors name the database file, a transaction not committed
// is rolled back, and reading a finished database leaves nothing beside it,
// whatever characters its path holds.
#include "swarm/sweep/sqlite_db.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <functional>
#include <stdexcept>
#include <string>

#include "framework/error.h"
#include "tests/swarm/sweep/sweep_db.h"

namespace swarmsim {
namespace {

namespace fs = std::filesystem;
using sweep_testing::TempDir;

std::string ErrorOf(const std::function<void()>& f) {
  try {
    f();
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

TEST(SqliteDbTest, ValuesReadBackAsBound) {
  const fs::path dir = TempDir("sqlite_values");
  SqliteDb db(dir / "v.db");
  db.Exec("CREATE TABLE t (i INTEGER, d REAL, s TEXT, n TEXT)");
  SqliteStatement insert(&db, "INSERT INTO t VALUES (?, ?, ?, ?)");
  insert.Bind(1, int64_t{-9007199254740993}).Bind(2, 0.1).Bind(3, std::string("a\0b", 3));
  insert.BindNull(4).Run();
  // Run() resets and clears the bindings: unbound parameters are NULL.
  insert.Bind(1, int64_t{2}).Run();
  SqliteStatement q(&db, "SELECT i, d, s, n FROM t ORDER BY rowid");
  ASSERT_TRUE(q.Step());
  EXPECT_EQ(q.Int(0), int64_t{-9007199254740993});
  EXPECT_EQ(q.Double(1), 0.1);
  EXPECT_EQ(q.Text(2), std::string("a\0b", 3));
  EXPECT_TRUE(q.IsNull(3));
  EXPECT_EQ(q.Text(3), "");
  ASSERT_TRUE(q.Step());
  EXPECT_EQ(q.Int(0), 2);
  EXPECT_TRUE(q.IsNull(1));
  EXPECT_TRUE(q.IsNull(2));
  EXPECT_FALSE(q.Step());
  // Text is stored as UTF-8 whatever bytes it was given.
  SqliteStatement bad(&db, "INSERT INTO t (s) VALUES (?)");
  bad.Bind(1, std::string("caf\xe9")).Run();
  SqliteStatement last(&db, "SELECT s FROM t WHERE i IS NULL");
  ASSERT_TRUE(last.Step());
  EXPECT_EQ(last.Text(0), "caf\xef\xbf\xbd");  // U+FFFD for the stray byte
  fs::remove_all(dir);
}

TEST(SqliteDbTest, ErrorsNameTheDatabaseAndWhatWasAsked) {
  const fs::path dir = TempDir("sqlite_errors");
  const fs::path file = dir / "e.db";
  EXPECT_EQ(ErrorOf([&] {
              SqliteDb missing(dir / "none.db", /*read_only=*/true);
            }).rfind("cannot open database '" + (dir / "none.db").string() + "': ", 0),
            0u);
  EXPECT_FALSE(fs::exists(dir / "none.db")) << "read-only opening creates nothing";
  fs::create_directories(dir / "folder.db");  // SQLite said "disk I/O error"
  EXPECT_EQ(
      ErrorOf([&] { SqliteDb folder(dir / "folder.db"); }),
      "cannot open database '" + (dir / "folder.db").string() + "': it is a folder, not a file");
  SqliteDb db(file);
  const std::string exec = ErrorOf([&] { db.Exec("CREATE TABLE"); });
  EXPECT_EQ(exec.rfind("database '" + file.string() + "': ", 0), 0u) << exec;
  EXPECT_NE(exec.find("(in: CREATE TABLE)"), std::string::npos) << exec;
  const std::string prepare = ErrorOf([&] { SqliteStatement s(&db, "SELECT * FROM nosuch"); });
  EXPECT_EQ(prepare, "database '" + file.string() +
                         "': cannot prepare 'SELECT * FROM nosuch': no such "
                         "table: nosuch");
  db.Exec("CREATE TABLE u (k INTEGER PRIMARY KEY)");
  db.Exec("INSERT INTO u VALUES (1)");
  SqliteStatement twice(&db, "INSERT INTO u VALUES (1)");
  const std::string step = ErrorOf([&] { twice.Step(); });
  EXPECT_EQ(step.rfind("database '" + file.string() + "': step: ", 0), 0u) << step;
  EXPECT_NE(step.find("UNIQUE"), std::string::npos) << step;
  fs::remove_all(dir);
}

TEST(SqliteDbTest, ATransactionNotCommittedIsRolledBack) {
  const fs::path dir = TempDir("sqlite_transaction");
  SqliteDb db(dir / "t.db");
  db.Exec("CREATE TABLE t (k INTEGER)");
  const auto count = [&] {
    SqliteStatement q(&db, "SELECT count(*) FROM t");
    return q.Step() ? q.Int(0) : -1;
  };
  try {
    SqliteTransaction tx(&db);
    db.Exec("INSERT INTO t VALUES (1)");
    throw std::runtime_error("a failure half-way");
  } catch (const std::runtime_error&) {
  }
  EXPECT_EQ(count(), 0);
  {
    SqliteTransaction tx(&db);
    db.Exec("INSERT INTO t VALUES (1)");
    db.Exec("INSERT INTO t VALUES (2)");
    tx.Commit();
  }
  EXPECT_EQ(count(), 2);
  fs::remove_all(dir);
}

TEST(SqliteDbTest, AWrittenDatabaseIsWalAndReadingItLeavesNothingBeside) {
  const fs::path dir = TempDir("sqlite_read");
  // Characters a file: URI would otherwise take for its own.
  const fs::path file = dir / "a%25b?c#d.db";
  {
    SqliteDb db(file);
    SqliteStatement mode(&db, "PRAGMA journal_mode");
    ASSERT_TRUE(mode.Step());
    EXPECT_EQ(mode.Text(0), "wal");
    db.Exec("CREATE TABLE t (k INTEGER)");
    db.Exec("INSERT INTO t VALUES (42)");
  }
  ASSERT_FALSE(fs::exists(file.string() + "-wal"));
  {
    SqliteDb reader(file, /*read_only=*/true);
    SqliteStatement q(&reader, "SELECT k FROM t");
    ASSERT_TRUE(q.Step());
    EXPECT_EQ(q.Int(0), 42);
    EXPECT_NE(ErrorOf([&] { reader.Exec("INSERT INTO t VALUES (1)"); }), "");
  }
  EXPECT_FALSE(fs::exists(file.string() + "-wal"));
  EXPECT_FALSE(fs::exists(file.string() + "-shm"));
  size_t files = 0;
  for (const auto& entry : fs::directory_iterator(dir)) files += entry.is_regular_file();
  EXPECT_EQ(files, 1u) << "a file: URI taken literally would make another database";
  fs::remove_all(dir);
}

}  // namespace
}  // namespace swarmsim
