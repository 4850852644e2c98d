#include "db/schema.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <array>
#include <string>
#include <vector>

namespace psq::db {
namespace {

struct Migration {
  int version;
  const char* description;
  const char* sql;
};

// Times are REAL seconds since the Unix epoch (sub-second, comparable across processes).
// A job belongs to every sweep that listed it (sweep_jobs), so two sweeps sharing a parameter
// point share its one run.
constexpr const char* kInitialSchema = R"sql(
CREATE TABLE sweeps (
  id         INTEGER PRIMARY KEY,
  name       TEXT NOT NULL UNIQUE,
  source     TEXT NOT NULL,
  created_at REAL NOT NULL
);

CREATE TABLE jobs (
  number       INTEGER PRIMARY KEY,
  id           TEXT NOT NULL UNIQUE,
  parameters   TEXT NOT NULL,
  scene        TEXT NOT NULL,
  depth        INTEGER NOT NULL CHECK (depth >= 1),
  state        TEXT NOT NULL DEFAULT 'queued'
               CHECK (state IN ('queued', 'running', 'done', 'failed', 'cancelled')),
  attempt      INTEGER NOT NULL DEFAULT 0 CHECK (attempt >= 0),
  failures     INTEGER NOT NULL DEFAULT 0 CHECK (failures >= 0),
  max_attempts INTEGER NOT NULL CHECK (max_attempts >= 1),
  lease_owner  TEXT,
  lease_expiry REAL,
  heartbeat_at REAL,
  error        TEXT,
  code_version TEXT,
  host         TEXT,
  started_at   REAL,
  ended_at     REAL,
  created_at   REAL NOT NULL,
  CHECK ((state = 'running') = (lease_owner IS NOT NULL)),
  CHECK ((state = 'running') = (lease_expiry IS NOT NULL))
);
CREATE INDEX jobs_by_state ON jobs (state, number);
CREATE INDEX running_jobs_by_lease_expiry ON jobs (lease_expiry) WHERE state = 'running';

CREATE TABLE sweep_jobs (
  sweep_id INTEGER NOT NULL REFERENCES sweeps (id) ON DELETE CASCADE,
  job_id   TEXT NOT NULL REFERENCES jobs (id) ON DELETE CASCADE,
  PRIMARY KEY (sweep_id, job_id)
) WITHOUT ROWID;
CREATE INDEX sweep_jobs_by_job ON sweep_jobs (job_id);

CREATE TABLE levels (
  job_id              TEXT NOT NULL REFERENCES jobs (id) ON DELETE CASCADE,
  level               INTEGER NOT NULL CHECK (level >= 0),
  status              TEXT NOT NULL CHECK (status IN ('running', 'done', 'failed')),
  iterations          INTEGER NOT NULL CHECK (iterations >= 0),
  residuals           TEXT NOT NULL,
  timings             TEXT NOT NULL,
  checkpoint_path     TEXT,
  checkpoint_checksum TEXT,
  error               TEXT,
  attempt             INTEGER NOT NULL,
  updated_at          REAL NOT NULL,
  PRIMARY KEY (job_id, level)
) WITHOUT ROWID;
)sql";

/// Per frame of a level whose answer was settled, [frame, static residual] (a JSON array of
/// pairs; the residual null when it is not finite).
constexpr const char* kStaticResiduals = R"sql(
ALTER TABLE levels ADD COLUMN static_residuals TEXT NOT NULL DEFAULT '[]';
)sql";

// Jobs run as SLURM array tasks (docs/slurm.md). The job itself stays `running` under a lease
// owned by "slurm:<array>_<index>" while the cluster has it; a row here remembers which array
// task holds which claim (attempt) and what the scheduler last said about it, so that `psq
// status` can show cluster state without asking the cluster.
constexpr const char* kSlurmTasks = R"sql(
CREATE TABLE slurm_tasks (
  job_id       TEXT NOT NULL REFERENCES jobs (id) ON DELETE CASCADE,
  attempt      INTEGER NOT NULL CHECK (attempt >= 1),
  array_id     TEXT NOT NULL,
  task_index   INTEGER NOT NULL CHECK (task_index >= 0),
  manifest     TEXT NOT NULL,
  state        TEXT NOT NULL,
  reason       TEXT NOT NULL DEFAULT '',
  submitted_at REAL NOT NULL,
  synced_at    REAL,
  PRIMARY KEY (job_id, attempt)
) WITHOUT ROWID;
CREATE INDEX slurm_tasks_by_array ON slurm_tasks (array_id, task_index);
)sql";

// A worker that dies is only counted against a job's retry bound if its attempt made no
// progress: `progress_attempt` is the last attempt that recorded a new checkpoint, `stalls` the
// deaths without progress since then (docs/job-store.md, "Job states").
constexpr const char* kProgressAwareRetries = R"sql(
ALTER TABLE jobs ADD COLUMN progress_attempt INTEGER;
ALTER TABLE jobs ADD COLUMN stalls INTEGER NOT NULL DEFAULT 0 CHECK (stalls >= 0);
)sql";

// What the refinement into each level did (safe initialization, strain-limit correction), by
// name: a JSON object of numbers.
constexpr const char* kRefinementStatistics = R"sql(
ALTER TABLE levels ADD COLUMN refinement TEXT NOT NULL DEFAULT '{}';
)sql";

// Append new migrations here; never edit one that has shipped.
constexpr std::array kMigrations{
    Migration{1, "sweeps, jobs with leases, per-level records", kInitialSchema},
    Migration{2, "static residuals of the settled frames of each level", kStaticResiduals},
    Migration{3, "SLURM array tasks holding jobs", kSlurmTasks},
    Migration{4, "progress-aware retries: progress_attempt, stalls", kProgressAwareRetries},
    Migration{5, "refinement statistics of each level", kRefinementStatistics},
};

constexpr const char* kVersionTable = R"sql(
CREATE TABLE IF NOT EXISTS schema_version (
  version     INTEGER PRIMARY KEY,
  description TEXT NOT NULL,
  applied_at  TEXT NOT NULL DEFAULT (strftime('%Y-%m-%dT%H:%M:%fZ', 'now'))
))sql";

bool has_version_table(SqliteConnection& connection) {
  auto query = connection.prepare(
      "SELECT 1 FROM sqlite_schema WHERE type = 'table' AND name = 'schema_version'");
  return query.step();
}

std::vector<std::string> user_tables(SqliteConnection& connection) {
  auto query = connection.prepare(
      "SELECT name FROM sqlite_schema WHERE type = 'table' AND name NOT LIKE 'sqlite_%' "
      "ORDER BY name");
  std::vector<std::string> names;
  while (query.step()) names.push_back(query.text(0));
  return names;
}

/// Refuses a database this build must not touch: one written by a newer psq, or one that
/// belongs to another program (tables, but no schema_version).
void check_compatible(SqliteConnection& connection, int version) {
  const std::string path = connection.path().string();
  if (version > latest_schema_version())
    throw InputError(fmt::format(
        "{} has schema version {} but this psq understands up to {}; upgrade psq", path,
        version, latest_schema_version()));
  if (version == 0) {
    const auto tables = user_tables(connection);
    if (!tables.empty())
      throw InputError(fmt::format(
          "{} is a SQLite database but not a psq job store (it has the tables {} and no "
          "schema_version); choose another --db path",
          path, fmt::join(tables, ", ")));
  }
}

}  // namespace

int latest_schema_version() { return kMigrations.back().version; }

int schema_version(SqliteConnection& connection) {
  if (!has_version_table(connection)) return 0;
  auto query = connection.prepare("SELECT COALESCE(MAX(version), 0) FROM schema_version");
  query.step();
  return static_cast<int>(query.integer(0));
}

void migrate(SqliteConnection& connection) {
  {
    // The common case, an up-to-date store, must not take the write lock.
    Transaction read(connection, Transaction::Mode::deferred);
    const int version = schema_version(connection);
    check_compatible(connection, version);
    if (version == latest_schema_version()) return;
  }
  for (const auto& migration : kMigrations) {
    Transaction write(connection, Transaction::Mode::immediate);
    // Read again under the write lock: another process may have migrated meanwhile.
    const int version = schema_version(connection);
    check_compatible(connection, version);
    if (version >= migration.version) continue;
    connection.execute(kVersionTable);
    connection.execute(migration.sql);
    connection.prepare("INSERT INTO schema_version (version, description) VALUES (?, ?)")
        .bind_all(migration.version, migration.description)
        .run();
    write.commit();
  }
}

}  // namespace psq::db
