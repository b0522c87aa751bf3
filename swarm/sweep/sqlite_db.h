// A thin RAII layer over the SQLite C API: a connection and prepared statements.
// Errors throw swarmsim::Error naming the database file and SQLite's message.
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>

struct sqlite3;
struct sqlite3_stmt;

namespace swarmsim {

class SqliteDb;

class SqliteStatement {
 public:
  SqliteStatement(SqliteDb* db, const std::string& sql);
  ~SqliteStatement();
  SqliteStatement(const SqliteStatement&) = delete;
  SqliteStatement& operator=(const SqliteStatement&) = delete;

  // Parameters are 1-based, as in SQLite.
  SqliteStatement& Bind(int index, int64_t value);
  SqliteStatement& Bind(int index, double value);
  SqliteStatement& Bind(int index, const std::string& value);
  SqliteStatement& BindNull(int index);
  // Advances; true while a row is available.
  bool Step();
  // Steps to completion (for statements that return no rows).
  void Run();
  void Reset();  // clears the bindings as well

  int64_t Int(int column) const;
  double Double(int column) const;
  std::string Text(int column) const;
  bool IsNull(int column) const;

 private:
  SqliteDb* db_;
  sqlite3_stmt* stmt_ = nullptr;
};

class SqliteDb {
 public:
  // Opens (creating unless read_only) the database; WAL journal, busy timeout.
  explicit SqliteDb(const std::filesystem::path& path, bool read_only = false);
  ~SqliteDb();
  SqliteDb(const SqliteDb&) = delete;
  SqliteDb& operator=(const SqliteDb&) = delete;

  void Exec(const std::string& sql);
  [[noreturn]] void Fail(const std::string& what) const;
  std::string SystemError() const;
  sqlite3* handle() { return db_; }
  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
  sqlite3* db_ = nullptr;
};

// BEGIN IMMEDIATE ... COMMIT, rolled back if not committed (an exception).
class SqliteTransaction {
 public:
  explicit SqliteTransaction(SqliteDb* db);
  ~SqliteTransaction();
  void Commit();

 private:
  SqliteDb* db_;
  bool done_ = false;
};

}  // namespace swarmsim
