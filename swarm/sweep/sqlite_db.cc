#include "swarm/sweep/sqlite_db.h"

#include <sqlite3.h>
#include <sys/resource.h>

#include <cerrno>
#include <cstring>

#include "framework/error.h"
#include "framework/utf8.h"

namespace swarmsim {

namespace {

// A file: URI for `path` (RFC 3986: '%', '?' and '#' escaped).
std::string FileUri(const std::filesystem::path& path) {
  std::string uri = "file:";
  for (const char c : std::filesystem::absolute(path).string()) {
    if (c == '%' || c == '?' || c == '#') {
      static constexpr char kHex[] = "0123456789ABCDEF";
      uri += '%';
      uri += kHex[static_cast<unsigned char>(c) >> 4];
      uri += kHex[static_cast<unsigned char>(c) & 15];
    } else {
      uri += c;
    }
  }
  return uri;
}

}  // namespace

SqliteDb::SqliteDb(const std::filesystem::path& path, bool read_only) : path_(path) {
  int flags = read_only ? SQLITE_OPEN_READONLY : (SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE);
  std::string name = path.string();
  // A reader of a WAL database makes its -wal and -shm files and, being
  // read-only, cannot remove them again: `report` left two empty files
  // beside a finished sweep's database. With no writer (neither file there)
  // the database is read as immutable, which makes none.
  std::error_code ec;
  if (read_only && !std::filesystem::exists(name + "-wal", ec) &&
      !std::filesystem::exists(name + "-shm", ec)) {
    name = FileUri(path) + "?immutable=1";
    flags |= SQLITE_OPEN_URI;
  }
  // A folder gave SQLite's "disk I/O error".
  if (std::filesystem::is_directory(path, ec))
    throw Error("cannot open database '" + path.string() + "': it is a folder, not a file");
  if (sqlite3_open_v2(name.c_str(), &db_, flags, nullptr) != SQLITE_OK) {
    const std::string message = db_ ? sqlite3_errmsg(db_) : "out of memory";
    sqlite3_close(db_);
    db_ = nullptr;
    throw Error("cannot open database '" + path.string() + "': " + message);
  }
  sqlite3_busy_timeout(db_, 10000);
  if (!read_only) {
    // WAL: a commit is durable once written; a killed writer loses only its
    // open transaction. NORMAL sync is safe against process death.
    Exec("PRAGMA journal_mode=WAL");
    Exec("PRAGMA synchronous=NORMAL");
  }
  Exec("PRAGMA foreign_keys=ON");
}

SqliteDb::~SqliteDb() { sqlite3_close_v2(db_); }

// " (No space left on device)": what the system said to SQLite's last
// failed call, which SQLite's own text ("disk I/O error") does not. A write
// past the process's file size limit (ulimit -f) often leaves SQLite no
// errno at all: the limit is named when there is one and a write failed.
std::string SqliteDb::SystemError() const {
  const int error = sqlite3_system_errno(db_);
  std::string out = error != 0 ? std::string(" (") + std::strerror(error) + ")" : std::string();
  const int code = sqlite3_extended_errcode(db_) & 0xff;
  rlimit limit{};
  if ((code == SQLITE_IOERR || code == SQLITE_FULL || error == EFBIG) &&
      getrlimit(RLIMIT_FSIZE, &limit) == 0 && limit.rlim_cur != RLIM_INFINITY)
    out += " (this process may write no file past " + std::to_string(limit.rlim_cur) +
           " bytes: its file size limit, `ulimit -f`)";
  return out;
}

void SqliteDb::Exec(const std::string& sql) {
  char* message = nullptr;
  if (sqlite3_exec(db_, sql.c_str(), nullptr, nullptr, &message) != SQLITE_OK) {
    const std::string text = (message ? message : "unknown error") + SystemError();
    sqlite3_free(message);
    // The statement on one line (the schema's span several).
    std::string statement;
    for (const char c : sql.substr(0, 160)) {
      const bool space = c == '\n' || c == ' ' || c == '\t';
      if (space && (statement.empty() || statement.back() == ' ')) continue;
      statement += space ? ' ' : c;
      if (statement.size() >= 80) break;
    }
    throw Error("database '" + path_.string() + "': " + text + " (in: " + statement + ")");
  }
}

void SqliteDb::Fail(const std::string& what) const {
  throw Error("database '" + path_.string() + "': " + what + ": " + sqlite3_errmsg(db_) +
              SystemError());
}

SqliteStatement::SqliteStatement(SqliteDb* db, const std::string& sql) : db_(db) {
  if (sqlite3_prepare_v2(db->handle(), sql.c_str(), -1, &stmt_, nullptr) != SQLITE_OK)
    db->Fail("cannot prepare '" + sql.substr(0, 80) + "'");
}

SqliteStatement::~SqliteStatement() { sqlite3_finalize(stmt_); }

SqliteStatement& SqliteStatement::Bind(int index, int64_t value) {
  if (sqlite3_bind_int64(stmt_, index, value) != SQLITE_OK) db_->Fail("bind");
  return *this;
}
SqliteStatement& SqliteStatement::Bind(int index, double value) {
  if (sqlite3_bind_double(stmt_, index, value) != SQLITE_OK) db_->Fail("bind");
  return *this;
}
SqliteStatement& SqliteStatement::Bind(int index, const std::string& raw) {
  // TEXT is UTF-8 to every reader (Python's sqlite3 fails on anything else).
  const std::string value = ValidUtf8(raw);
  if (sqlite3_bind_text(stmt_, index, value.data(), static_cast<int>(value.size()),
                        SQLITE_TRANSIENT) != SQLITE_OK)
    db_->Fail("bind");
  return *this;
}
SqliteStatement& SqliteStatement::BindNull(int index) {
  if (sqlite3_bind_null(stmt_, index) != SQLITE_OK) db_->Fail("bind");
  return *this;
}

bool SqliteStatement::Step() {
  const int rc = sqlite3_step(stmt_);
  if (rc == SQLITE_ROW) return true;
  if (rc == SQLITE_DONE) return false;
  db_->Fail("step");
}

void SqliteStatement::Run() {
  while (Step()) {
  }
  Reset();
}

void SqliteStatement::Reset() {
  sqlite3_reset(stmt_);
  sqlite3_clear_bindings(stmt_);
}

int64_t SqliteStatement::Int(int column) const { return sqlite3_column_int64(stmt_, column); }
double SqliteStatement::Double(int column) const { return sqlite3_column_double(stmt_, column); }
std::string SqliteStatement::Text(int column) const {
  const unsigned char* text = sqlite3_column_text(stmt_, column);
  return text ? std::string(reinterpret_cast<const char*>(text),
                            static_cast<size_t>(sqlite3_column_bytes(stmt_, column)))
              : std::string();
}
bool SqliteStatement::IsNull(int column) const {
  return sqlite3_column_type(stmt_, column) == SQLITE_NULL;
}

SqliteTransaction::SqliteTransaction(SqliteDb* db) : db_(db) { db_->Exec("BEGIN IMMEDIATE"); }
SqliteTransaction::~SqliteTransaction() {
  if (!done_) sqlite3_exec(db_->handle(), "ROLLBACK", nullptr, nullptr, nullptr);
}
void SqliteTransaction::Commit() {
  db_->Exec("COMMIT");
  done_ = true;
}

}  // namespace swarmsim
