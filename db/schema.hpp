#pragma once
// The job store's schema and its versioned migrations. Each migration runs in its own
// transaction and records itself in the table schema_version, so a store is always at one
// well-defined version, even after a crash in the middle of an upgrade.

#include "db/sqlite_handle.hpp"

namespace psq::db {

/// The newest schema version this build of psq understands.
int latest_schema_version();

/// The schema version recorded in the database: 0 for a new, empty file.
int schema_version(SqliteConnection& connection);

/// Brings the database up to latest_schema_version(), one transaction per migration (two
/// processes migrating at once are serialized by BEGIN IMMEDIATE; the second finds the work
/// done). Throws InputError, naming the file, if the database is newer than this build or is a
/// SQLite database of some other program.
void migrate(SqliteConnection& connection);

}  // namespace psq::db
