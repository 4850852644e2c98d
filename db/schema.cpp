#include "db/schema.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <sqlite3.h>

#include <array>
#include <optional>
#include <string>
#include <vector>

namespace psq::db {
namespace {

struct Migration {
  int version;
  const char* description;
  const char* sql;
  /// Drops and recreates a table others refer to: must run with foreign keys off.
  bool rebuilds_tables = false;
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

// Coarse-first sweeps (docs/sweep-format.md): a job may stop at its preview levels in the new
// state 'previewed' until it is promoted. SQLite cannot alter a CHECK constraint, so `jobs` is
// rebuilt (SQLite's documented twelve-step procedure, run with foreign keys off so that dropping
// the old table does not cascade into sweep_jobs and levels). Each finished level records its
// outputs, by which a sweep's rule (sweeps.refine) selects; refine_pending is set when a preview
// finishes and cleared once the rule has been applied to the settled previews.
constexpr const char* kCoarseFirst = R"sql(
CREATE TABLE jobs_with_previews (
  number           INTEGER PRIMARY KEY,
  id               TEXT NOT NULL UNIQUE,
  parameters       TEXT NOT NULL,
  scene            TEXT NOT NULL,
  depth            INTEGER NOT NULL CHECK (depth >= 1),
  state            TEXT NOT NULL DEFAULT 'queued'
                   CHECK (state IN ('queued', 'running', 'done', 'failed', 'cancelled',
                                    'previewed')),
  attempt          INTEGER NOT NULL DEFAULT 0 CHECK (attempt >= 0),
  failures         INTEGER NOT NULL DEFAULT 0 CHECK (failures >= 0),
  max_attempts     INTEGER NOT NULL CHECK (max_attempts >= 1),
  lease_owner      TEXT,
  lease_expiry     REAL,
  heartbeat_at     REAL,
  error            TEXT,
  code_version     TEXT,
  host             TEXT,
  started_at       REAL,
  ended_at         REAL,
  created_at       REAL NOT NULL,
  progress_attempt INTEGER,
  stalls           INTEGER NOT NULL DEFAULT 0 CHECK (stalls >= 0),
  preview_levels   INTEGER CHECK (preview_levels IS NULL OR
                                  (preview_levels >= 1 AND preview_levels < depth)),
  promoted         INTEGER NOT NULL DEFAULT 0 CHECK (promoted IN (0, 1)),
  CHECK ((state = 'running') = (lease_owner IS NOT NULL)),
  CHECK ((state = 'running') = (lease_expiry IS NOT NULL))
);
INSERT INTO jobs_with_previews (number, id, parameters, scene, depth, state, attempt, failures,
  max_attempts, lease_owner, lease_expiry, heartbeat_at, error, code_version, host, started_at,
  ended_at, created_at, progress_attempt, stalls)
SELECT number, id, parameters, scene, depth, state, attempt, failures, max_attempts, lease_owner,
  lease_expiry, heartbeat_at, error, code_version, host, started_at, ended_at, created_at,
  progress_attempt, stalls FROM jobs;
DROP TABLE jobs;
ALTER TABLE jobs_with_previews RENAME TO jobs;
CREATE INDEX jobs_by_state ON jobs (state, number);
CREATE INDEX running_jobs_by_lease_expiry ON jobs (lease_expiry) WHERE state = 'running';
ALTER TABLE levels ADD COLUMN outputs TEXT NOT NULL DEFAULT '{}';
ALTER TABLE sweeps ADD COLUMN refine TEXT NOT NULL DEFAULT '{"kind":"all"}';
ALTER TABLE sweeps ADD COLUMN refine_pending INTEGER NOT NULL DEFAULT 0;
)sql";

// How each attempt obtained each of its hierarchies through the shared cache: a hit (read) or a
// build, and how long it took, so that reports can count hits and the build time they saved.
constexpr const char* kHierarchyCacheUses = R"sql(
CREATE TABLE hierarchy_cache_uses (
  job_id    TEXT NOT NULL REFERENCES jobs (id) ON DELETE CASCADE,
  attempt   INTEGER NOT NULL CHECK (attempt >= 1),
  position  INTEGER NOT NULL CHECK (position >= 0),
  cache_key TEXT NOT NULL,
  hit       INTEGER NOT NULL CHECK (hit IN (0, 1)),
  seconds   REAL NOT NULL CHECK (seconds >= 0),
  PRIMARY KEY (job_id, attempt, position)
) WITHOUT ROWID;
CREATE INDEX hierarchy_cache_uses_by_key ON hierarchy_cache_uses (cache_key);
)sql";

// Per frame of each level, the scale of its loads, and per probe its reading there (a vector:
// a mean displacement or the reaction of a pinned set): load–displacement curves from one run.
// Rows refer to the job, not the level row, which record_level replaces.
constexpr const char* kFrameProbes = R"sql(
CREATE TABLE frames (
  job_id     TEXT NOT NULL REFERENCES jobs (id) ON DELETE CASCADE,
  level      INTEGER NOT NULL CHECK (level >= 0),
  frame      INTEGER NOT NULL CHECK (frame >= 1),
  load_scale REAL NOT NULL,
  PRIMARY KEY (job_id, level, frame)
) WITHOUT ROWID;
CREATE TABLE probe_readings (
  job_id TEXT NOT NULL REFERENCES jobs (id) ON DELETE CASCADE,
  level  INTEGER NOT NULL CHECK (level >= 0),
  frame  INTEGER NOT NULL CHECK (frame >= 1),
  probe  TEXT NOT NULL,
  kind   TEXT NOT NULL CHECK (kind IN ('displacement', 'reaction')),
  x      REAL NOT NULL,
  y      REAL NOT NULL,
  z      REAL NOT NULL,
  PRIMARY KEY (job_id, level, frame, probe)
) WITHOUT ROWID;
)sql";

// Version 9: each job's solution method (docs/sweep-format.md, "Methods"). A job stored before
// methods existed was direct at depth 1 and progressive above it.
constexpr const char* kJobMethods = R"sql(
ALTER TABLE jobs ADD COLUMN method TEXT NOT NULL DEFAULT 'direct'
  CHECK (method IN ('direct', 'direct_final', 'progressive', 'coarse_prolonged'));
UPDATE jobs SET method = 'progressive' WHERE depth > 1;
)sql";

// Append new migrations here; never edit one that has shipped.
constexpr std::array kMigrations{
    Migration{1, "sweeps, jobs with leases, per-level records", kInitialSchema},
    Migration{2, "static residuals of the settled frames of each level", kStaticResiduals},
    Migration{3, "SLURM array tasks holding jobs", kSlurmTasks},
    Migration{4, "progress-aware retries: progress_attempt, stalls", kProgressAwareRetries},
    Migration{5, "refinement statistics of each level", kRefinementStatistics},
    Migration{6, "coarse-first sweeps: previewed jobs, level outputs, refine rules", kCoarseFirst,
              true},
    Migration{7, "hierarchy cache uses: hits, builds and their seconds", kHierarchyCacheUses},
    Migration{8, "per-frame load scale and probe readings", kFrameProbes},
    Migration{9, "the solution method of each job", kJobMethods},
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

/// Foreign keys off while it lives. SQLite ignores the pragma inside a transaction, so this
/// wraps the migration's transaction, not the other way round.
class ForeignKeysOff {
 public:
  explicit ForeignKeysOff(SqliteConnection& connection) : connection_(connection) {
    connection_.execute("PRAGMA foreign_keys = OFF");
  }
  ~ForeignKeysOff() {
    try {
      connection_.execute("PRAGMA foreign_keys = ON");
    } catch (...) {
      // The connection is then unusable anyway; its next statement reports why.
    }
  }
  ForeignKeysOff(const ForeignKeysOff&) = delete;
  ForeignKeysOff& operator=(const ForeignKeysOff&) = delete;

 private:
  SqliteConnection& connection_;
};

/// A rebuilt table must leave every reference to it whole; otherwise the migration is rolled
/// back.
void check_foreign_keys(SqliteConnection& connection) {
  auto problems = connection.prepare("PRAGMA foreign_key_check");
  if (problems.step())
    throw DatabaseError(fmt::format("{}: a migration left row {} of {} referring to a missing "
                                    "row of {}; it was rolled back",
                                    connection.path().string(), problems.integer(1),
                                    problems.text(0), problems.text(2)),
                        SQLITE_CONSTRAINT_FOREIGNKEY);
}

/// Applies `migration` in its own write transaction unless another process already has.
void apply(SqliteConnection& connection, const Migration& migration) {
  std::optional<ForeignKeysOff> foreign_keys_off;
  if (migration.rebuilds_tables) foreign_keys_off.emplace(connection);
  Transaction write(connection, Transaction::Mode::immediate);
  // Read again under the write lock: another process may have migrated meanwhile.
  const int version = schema_version(connection);
  check_compatible(connection, version);
  if (version >= migration.version) return;
  connection.execute(kVersionTable);
  connection.execute(migration.sql);
  if (migration.rebuilds_tables) check_foreign_keys(connection);
  connection.prepare("INSERT INTO schema_version (version, description) VALUES (?, ?)")
      .bind_all(migration.version, migration.description)
      .run();
  write.commit();
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
  for (const auto& migration : kMigrations) apply(connection, migration);
}

}  // namespace psq::db
