#include "db/sqlite_handle.hpp"

#include <fmt/format.h>
#include <sqlite3.h>

#include <stdexcept>

namespace psq::db {

namespace {

/// Throws InputError for the failures a user can fix, DatabaseError for the rest.
[[noreturn]] void throw_sqlite_error(const std::filesystem::path& database, int code,
                                     std::string_view what, const std::string& detail) {
  const std::string path = database.string();
  switch (code & 0xff) {
    case SQLITE_NOTADB:
      throw InputError(fmt::format(
          "{}: not a SQLite database ({}); point --db or PSQ_DB at a psq job store, or move "
          "this file away",
          path, detail));
    case SQLITE_CORRUPT:
      throw InputError(fmt::format(
          "{}: the database is corrupt ({} while {}); restore it from a backup or start a new "
          "store",
          path, detail, what));
    case SQLITE_CANTOPEN:
      throw InputError(fmt::format(
          "{}: cannot open the database ({}); check that its directory exists and is writable",
          path, detail));
    case SQLITE_FULL:
      throw InputError(fmt::format(
          "{}: disk full while {} ({}); the change was rolled back, free some space and retry",
          path, what, detail));
    case SQLITE_IOERR:
      throw InputError(fmt::format(
          "{}: input/output error while {} ({}); check the disk (space, quota, file size "
          "limit) and retry",
          path, what, detail));
    case SQLITE_READONLY:
    case SQLITE_PERM:
    case SQLITE_AUTH:
      throw InputError(fmt::format(
          "{}: the database cannot be written ({} while {}); check the file's permissions", path,
          detail, what));
    default:
      throw DatabaseError(
          fmt::format("{}: {} failed: {} ({})", path, what, detail, sqlite3_errstr(code)), code);
  }
}

/// How a failed statement is described in messages.
std::string running(std::string_view sql) { return fmt::format("running `{}`", sql); }

}  // namespace

SqliteConnection::SqliteConnection(const std::filesystem::path& path, int busy_timeout_ms)
    : path_(path) {
  const int flags = SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE | SQLITE_OPEN_EXRESCODE;
  const int code = sqlite3_open_v2(path.c_str(), &db_, flags, nullptr);
  if (code != SQLITE_OK) {
    // The handle exists even on failure and carries the message; it must still be closed.
    const std::string detail = db_ ? sqlite3_errmsg(db_) : sqlite3_errstr(code);
    sqlite3_close(db_);
    db_ = nullptr;
    throw_sqlite_error(path_, code, "opening the database", detail);
  }
  sqlite3_busy_timeout(db_, busy_timeout_ms);
}

SqliteConnection::~SqliteConnection() { sqlite3_close(db_); }

void SqliteConnection::execute(std::string_view sql) {
  const std::string text(sql);
  const int code = sqlite3_exec(db_, text.c_str(), nullptr, nullptr, nullptr);
  if (code != SQLITE_OK) fail(code, running(text));
}

Statement SqliteConnection::prepare(std::string_view sql) {
  sqlite3_stmt* statement = nullptr;
  const char* tail = nullptr;
  const int code =
      sqlite3_prepare_v2(db_, sql.data(), static_cast<int>(sql.size()), &statement, &tail);
  if (code != SQLITE_OK) fail(code, running(sql));
  Statement prepared(*this, statement);
  if (std::string_view(tail, sql.data() + sql.size() - tail).find_first_not_of(" \t\n;") !=
      std::string_view::npos)
    throw std::logic_error(fmt::format("more than one statement given to prepare: {}", sql));
  return prepared;
}

std::int64_t SqliteConnection::changes() const { return sqlite3_changes64(db_); }

bool SqliteConnection::in_autocommit() const { return sqlite3_get_autocommit(db_) != 0; }

void SqliteConnection::fail(int code, std::string_view what) const {
  throw_sqlite_error(path_, code, what, sqlite3_errmsg(db_));
}

Statement::Statement(const SqliteConnection& connection, sqlite3_stmt* statement)
    : connection_(&connection), statement_(statement) {}

Statement::~Statement() { sqlite3_finalize(statement_); }

Statement::Statement(Statement&& other) noexcept
    : connection_(other.connection_), statement_(other.statement_) {
  other.statement_ = nullptr;
}

namespace {

[[noreturn]] void fail_on(const SqliteConnection& connection, sqlite3_stmt* statement, int code) {
  connection.fail(code, running(sqlite3_sql(statement)));
}

}  // namespace

Statement& Statement::bind(int index, std::int64_t value) {
  if (const int code = sqlite3_bind_int64(statement_, index, value); code != SQLITE_OK)
    fail_on(*connection_, statement_, code);
  return *this;
}

int Statement::parameter_count() const { return sqlite3_bind_parameter_count(statement_); }

Statement& Statement::bind(int index, double value) {
  if (const int code = sqlite3_bind_double(statement_, index, value); code != SQLITE_OK)
    fail_on(*connection_, statement_, code);
  return *this;
}

Statement& Statement::bind(int index, std::string_view value) {
  const int code = sqlite3_bind_text64(statement_, index, value.data(), value.size(),
                                       SQLITE_TRANSIENT, SQLITE_UTF8);
  if (code != SQLITE_OK) fail_on(*connection_, statement_, code);
  return *this;
}

Statement& Statement::bind(int index, std::nullopt_t) {
  if (const int code = sqlite3_bind_null(statement_, index); code != SQLITE_OK)
    fail_on(*connection_, statement_, code);
  return *this;
}

bool Statement::step() {
  const int code = sqlite3_step(statement_);
  if (code == SQLITE_ROW) return true;
  if (code == SQLITE_DONE) return false;
  fail_on(*connection_, statement_, code);
}

std::int64_t Statement::run() {
  while (step()) {
  }
  return connection_->changes();
}

Statement& Statement::reset() {
  // sqlite3_reset repeats the last step's error, already reported by step().
  sqlite3_reset(statement_);
  sqlite3_clear_bindings(statement_);
  return *this;
}

bool Statement::is_null(int column) const {
  return sqlite3_column_type(statement_, column) == SQLITE_NULL;
}

std::int64_t Statement::integer(int column) const {
  return sqlite3_column_int64(statement_, column);
}

double Statement::real(int column) const { return sqlite3_column_double(statement_, column); }

std::string Statement::text(int column) const {
  const auto* bytes = sqlite3_column_text(statement_, column);
  if (!bytes) return {};
  return std::string(reinterpret_cast<const char*>(bytes),
                     static_cast<std::size_t>(sqlite3_column_bytes(statement_, column)));
}

std::optional<double> Statement::optional_real(int column) const {
  if (is_null(column)) return std::nullopt;
  return real(column);
}

std::optional<std::string> Statement::optional_text(int column) const {
  if (is_null(column)) return std::nullopt;
  return text(column);
}

Transaction::Transaction(SqliteConnection& connection, Mode mode) : connection_(connection) {
  connection_.execute(mode == Mode::immediate ? "BEGIN IMMEDIATE" : "BEGIN DEFERRED");
}

Transaction::~Transaction() {
  // SQLite may already have rolled back by itself (after SQLITE_FULL, for instance).
  if (open_ && !connection_.in_autocommit())
    sqlite3_exec(connection_.raw(), "ROLLBACK", nullptr, nullptr, nullptr);
}

void Transaction::commit() {
  connection_.execute("COMMIT");
  open_ = false;
}

}  // namespace psq::db
