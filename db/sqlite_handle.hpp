#pragma once
// Thin RAII wrappers over the SQLite C API: a connection, a prepared statement and a
// transaction. Every failure throws with the database path and the SQL that failed, so a
// message in a log is enough to find the statement and the file.

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>

#include "engine/core/error.hpp"

struct sqlite3;
struct sqlite3_stmt;

namespace psq::db {

/// A SQLite failure that is not the user's to fix: a bug (bad SQL, a violated constraint) or a
/// lock held beyond the busy timeout. Failures the user can fix (not a database, corrupt,
/// cannot open, disk full, I/O error, read-only) are InputError instead.
class DatabaseError : public Error {
 public:
  DatabaseError(const std::string& message, int sqlite_code)
      : Error(message), sqlite_code_(sqlite_code) {}
  /// The extended SQLite result code (SQLITE_BUSY, SQLITE_IOERR_WRITE, ...).
  int sqlite_code() const { return sqlite_code_; }

 private:
  int sqlite_code_;
};

class Statement;

/// One open SQLite connection. Not copyable; not to be shared across threads or carried over
/// fork() (open a new one in the child).
class SqliteConnection {
 public:
  /// Opens (creating if needed) the database file at `path`. `busy_timeout_ms` is how long a
  /// statement waits for another connection's lock before failing with SQLITE_BUSY.
  SqliteConnection(const std::filesystem::path& path, int busy_timeout_ms);
  ~SqliteConnection();
  SqliteConnection(const SqliteConnection&) = delete;
  SqliteConnection& operator=(const SqliteConnection&) = delete;

  /// Runs one or more statements that return no rows of interest.
  void execute(std::string_view sql);
  /// Compiles one statement.
  Statement prepare(std::string_view sql);
  /// Rows changed by the last INSERT, UPDATE or DELETE.
  std::int64_t changes() const;
  /// True outside any explicit transaction.
  bool in_autocommit() const;

  const std::filesystem::path& path() const { return path_; }
  sqlite3* raw() const { return db_; }

  /// Throws the error for result `code` of doing `what` (usually the SQL text): InputError for
  /// what the user can fix, DatabaseError otherwise. Both name the database path.
  [[noreturn]] void fail(int code, std::string_view what) const;

 private:
  std::filesystem::path path_;
  sqlite3* db_ = nullptr;
};

/// A prepared statement. Parameters are numbered from 1, columns from 0.
class Statement {
 public:
  Statement(const SqliteConnection& connection, sqlite3_stmt* statement);
  ~Statement();
  Statement(Statement&& other) noexcept;
  Statement& operator=(Statement&&) = delete;
  Statement(const Statement&) = delete;
  Statement& operator=(const Statement&) = delete;

  Statement& bind(int index, std::int64_t value);
  Statement& bind(int index, int value) { return bind(index, std::int64_t{value}); }
  Statement& bind(int index, double value);
  Statement& bind(int index, std::string_view value);
  Statement& bind(int index, const std::string& value) {
    return bind(index, std::string_view(value));
  }
  Statement& bind(int index, const char* value) { return bind(index, std::string_view(value)); }
  Statement& bind(int index, std::nullopt_t);
  template <class T>
  Statement& bind(int index, const std::optional<T>& value) {
    return value ? bind(index, *value) : bind(index, std::nullopt);
  }
  /// The number of parameters: the largest parameter index the statement uses.
  int parameter_count() const;
  /// Binds `values` to parameters 1, 2, ... in order.
  template <class... Values>
  Statement& bind_all(const Values&... values) {
    int index = 1;
    (bind(index++, values), ...);
    return *this;
  }

  /// Advances to the next row: true if there is one, false when the statement is done.
  bool step();
  /// Steps until done (for statements returning no rows); returns the rows changed.
  std::int64_t run();
  /// Makes the statement ready to run again with new bindings.
  Statement& reset();

  bool is_null(int column) const;
  std::int64_t integer(int column) const;
  double real(int column) const;
  std::string text(int column) const;  ///< "" for NULL
  std::optional<double> optional_real(int column) const;
  std::optional<std::string> optional_text(int column) const;

 private:
  const SqliteConnection* connection_;
  sqlite3_stmt* statement_;
};

/// A transaction that rolls back unless commit() is called. Writers use `immediate` so that
/// the write lock is taken (or waited for) at BEGIN, never by upgrading a read lock later,
/// which in WAL mode fails with SQLITE_BUSY without waiting.
class Transaction {
 public:
  enum class Mode { deferred, immediate };
  Transaction(SqliteConnection& connection, Mode mode);
  ~Transaction();
  Transaction(const Transaction&) = delete;
  Transaction& operator=(const Transaction&) = delete;
  void commit();

 private:
  SqliteConnection& connection_;
  bool open_ = true;
};

}  // namespace psq::db
