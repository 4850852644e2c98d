#include "db/job_store.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <sqlite3.h>

#include <chrono>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <thread>

#include "db/schema.hpp"

namespace psq::db {
namespace {

const std::filesystem::path& with_parent_directories(const std::filesystem::path& path) {
  std::error_code failure;
  if (const auto parent = path.parent_path(); !parent.empty()) {
    std::filesystem::create_directories(parent, failure);
    if (failure)
      throw InputError(fmt::format("{}: cannot create the directory {} for the job store ({})",
                                   path.string(), parent.string(), failure.message()));
  }
  return path;
}

/// WAL lets readers (status, reports) run beside one writer. synchronous=NORMAL syncs the WAL
/// at checkpoints, not at every commit: a killed process loses nothing, and a power loss can
/// only roll back the last commits, which the lease protocol absorbs (a job reverts to running
/// and is rerun once its lease expires).
///
/// Switching a new database to WAL needs an exclusive lock, and SQLite answers SQLITE_BUSY at
/// once (without the busy handler) while another process is creating the same file, so the
/// switch is retried for up to the busy timeout.
std::string enable_wal(SqliteConnection& connection, int busy_timeout_ms) {
  const auto deadline =
      std::chrono::steady_clock::now() + std::chrono::milliseconds(busy_timeout_ms);
  for (;;) {
    try {
      auto journal = connection.prepare("PRAGMA journal_mode = WAL");
      return journal.step() ? journal.text(0) : std::string();
    } catch (const DatabaseError& e) {
      if ((e.sqlite_code() & 0xff) != SQLITE_BUSY || std::chrono::steady_clock::now() > deadline)
        throw;
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
  }
}

void configure(SqliteConnection& connection, int busy_timeout_ms) {
  if (enable_wal(connection, busy_timeout_ms) != "wal")
    throw InputError(fmt::format(
        "{}: the job store needs SQLite's WAL mode, which this file system refused; keep the "
        "database on a local disk",
        connection.path().string()));
  connection.execute("PRAGMA synchronous = NORMAL; PRAGMA foreign_keys = ON");
}

/// SET clause putting a running job back in the queue with its lease ended.
constexpr const char* kBackToTheQueue = "state = 'queued', lease_owner = NULL, lease_expiry = NULL";

constexpr const char* kJobColumns =
    "jobs.id, jobs.parameters, jobs.scene, jobs.depth, jobs.state, jobs.attempt, jobs.failures, "
    "jobs.max_attempts, jobs.lease_owner, jobs.lease_expiry, jobs.heartbeat_at, jobs.error, "
    "jobs.code_version, jobs.host, jobs.started_at, jobs.ended_at, jobs.created_at, "
    "jobs.preview_levels, jobs.promoted, jobs.method";

Job read_job(const Statement& row) {
  Job job;
  job.id = row.text(0);
  job.parameters = nlohmann::json::parse(row.text(1));
  job.scene = row.text(2);
  job.depth = static_cast<int>(row.integer(3));
  job.state = job_state_from_string(row.text(4));
  job.attempt = row.integer(5);
  job.failures = row.integer(6);
  job.max_attempts = row.integer(7);
  job.lease_owner = row.text(8);
  job.lease_expiry = row.optional_real(9);
  job.heartbeat_at = row.optional_real(10);
  job.error = row.text(11);
  job.provenance = {row.text(12), row.text(13), row.optional_real(14), row.optional_real(15)};
  job.created_at = row.real(16);
  if (!row.is_null(17)) job.preview_levels = static_cast<int>(row.integer(17));
  job.promoted = row.integer(18) != 0;
  job.method = method_from_string(row.text(19));
  return job;
}

constexpr const char* kLevelColumns =
    "level, status, iterations, residuals, timings, checkpoint_path, checkpoint_checksum, "
    "error, attempt, updated_at, static_residuals, refinement, outputs";

/// A stored number: JSON has no NaN or infinity, nlohmann writes them as null, read back as NaN.
double stored_number(const nlohmann::json& value) {
  return value.is_number() ? value.get<double>() : std::numeric_limits<double>::quiet_NaN();
}

/// Named numbers as the text of a JSON object ({} when there are none).
std::string named_numbers_json(const std::map<std::string, double>& named) {
  nlohmann::json object = nlohmann::json::object();
  for (const auto& [name, value] : named) object[name] = value;
  return object.dump();
}

/// A JSON object of named numbers (timings, refinement statistics).
std::map<std::string, double> stored_named_numbers(const std::string& text) {
  std::map<std::string, double> named;
  const nlohmann::json object = nlohmann::json::parse(text);
  for (const auto& [name, value] : object.items())
    named[name] = stored_number(value);
  return named;
}

/// Reads the level columns starting at column `first`.
LevelRecord read_level(const Statement& row, int first) {
  LevelRecord level;
  level.level = static_cast<int>(row.integer(first));
  level.status = level_status_from_string(row.text(first + 1));
  level.iterations = row.integer(first + 2);
  for (const auto& residual : nlohmann::json::parse(row.text(first + 3)))
    level.residuals.push_back(stored_number(residual));
  level.timings = stored_named_numbers(row.text(first + 4));
  level.checkpoint_path = row.text(first + 5);
  level.checkpoint_checksum = row.text(first + 6);
  level.error = row.text(first + 7);
  level.attempt = row.integer(first + 8);
  level.updated_at = row.real(first + 9);
  for (const auto& frame : nlohmann::json::parse(row.text(first + 10)))
    level.static_residuals.emplace_back(frame.at(0).get<int>(), stored_number(frame.at(1)));
  level.refinement = stored_named_numbers(row.text(first + 11));
  level.outputs = stored_named_numbers(row.text(first + 12));
  return level;
}

/// Empty text is stored as NULL.
std::optional<std::string> unless_empty(const std::string& text) {
  if (text.empty()) return std::nullopt;
  return text;
}

/// SQL condition on `jobs` selecting `which`; its one parameter is ?1 (see selection_value).
std::string selection_condition(const JobSelection& which) {
  switch (which.kind()) {
    case JobSelection::Kind::sweep:
      return "jobs.id IN (SELECT sweep_jobs.job_id FROM sweep_jobs JOIN sweeps ON sweeps.id = "
             "sweep_jobs.sweep_id WHERE sweeps.name = ?1)";
    case JobSelection::Kind::job:
      return "jobs.id = ?1";
    case JobSelection::Kind::all:
      break;
  }
  return "?1 IS NULL";
}

std::optional<std::string> selection_value(const JobSelection& which) {
  if (which.kind() == JobSelection::Kind::all) return std::nullopt;
  return which.name();
}

/// `SELECT <columns> FROM <table>` restricted to the rows of the jobs `which` selects, ordered
/// by `order`, prepared and bound: the per-job tables that results() reads.
Statement rows_of_jobs(SqliteConnection& connection, const std::string& columns,
                       const std::string& table, const std::string& order,
                       const JobSelection& which) {
  auto rows = connection.prepare(fmt::format(
      "SELECT {} FROM {} WHERE job_id IN (SELECT jobs.id FROM jobs WHERE {}) ORDER BY {}",
      columns, table, selection_condition(which), order));
  rows.bind_all(selection_value(which));
  return rows;
}

void validate_new_job(const std::string& sweep, const NewJob& job) {
  const auto fail = [&](const std::string& problem) {
    throw InputError(fmt::format("sweep '{}': job {}: {}", sweep, job.id, problem));
  };
  if (job.id.empty()) fail("empty job id (ids are hashes of the canonical parameters)");
  if (job.depth < 1)
    fail(fmt::format("depth {} is not a number of levels; use 1 or more", job.depth));
  if (job.max_attempts < 1)
    fail(fmt::format("max attempts {} must be at least 1", job.max_attempts));
  // A progressive job records every level of its hierarchy; the others solve one mesh.
  if ((job.method == Method::progressive) != (job.depth > 1))
    fail(fmt::format("a {} job solves {}, not {}", to_string(job.method),
                     job.method == Method::progressive ? "2 levels or more" : "1 level",
                     job.depth));
}

}  // namespace

JobStore::JobStore(const std::filesystem::path& path, JobStoreOptions options)
    : options_(std::move(options)),
      connection_(with_parent_directories(path), options_.busy_timeout_ms) {
  configure(connection_, options_.busy_timeout_ms);
  migrate(connection_);
}

double JobStore::now() const {
  if (options_.clock) return options_.clock();
  return std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
}

SweepAddition JobStore::add_sweep(const std::string& name, const std::string& source,
                                  const std::vector<NewJob>& jobs, const RefineRule& refine) {
  return add_jobs(name, source, jobs, refine, true);
}

SweepAddition JobStore::preview_sweep(const std::string& name, const std::vector<NewJob>& jobs) {
  // The same code as add_sweep, rolled back: the preview cannot disagree with the real thing.
  return add_jobs(name, "", jobs, {}, false);
}

SweepAddition JobStore::add_jobs(const std::string& name, const std::string& source,
                                 const std::vector<NewJob>& jobs, const RefineRule& refine,
                                 bool commit) {
  if (name.empty()) throw InputError("a sweep needs a non-empty name");
  for (const auto& job : jobs) validate_new_job(name, job);
  Transaction transaction(connection_, Transaction::Mode::immediate);
  const double time = now();
  std::int64_t sweep_id = 0;
  {
    // A selecting rule is armed: it is applied once the sweep's previews are in, which may be
    // at the next claim if they already are.
    auto upsert = connection_.prepare(
        "INSERT INTO sweeps (name, source, created_at, refine, refine_pending) "
        "VALUES (?1, ?2, ?3, ?4, ?5) ON CONFLICT (name) DO UPDATE SET source = excluded.source, "
        "refine = excluded.refine, refine_pending = excluded.refine_pending RETURNING id");
    upsert.bind_all(name, source, time, to_json(refine).dump(), int{refine.selects()}).step();
    sweep_id = upsert.integer(0);
  }
  auto stored = connection_.prepare("SELECT parameters FROM jobs WHERE id = ?1");
  auto insert = connection_.prepare(
      "INSERT INTO jobs (id, parameters, scene, depth, max_attempts, created_at, preview_levels, "
      "method) VALUES (?1, ?2, ?3, ?4, ?5, ?6, ?7, ?8)");
  // A job listed again keeps the most levels any sweep asks of it: none stops it earlier, and
  // one that wants more (all of them: NULL) sends a waiting preview back to the queue.
  auto widen = connection_.prepare(
      "UPDATE jobs SET preview_levels = CASE WHEN ?2 IS NULL THEN NULL "
      "ELSE MAX(preview_levels, ?2) END, state = CASE WHEN state = 'previewed' AND "
      "(?2 IS NULL OR ?2 > preview_levels) THEN 'queued' ELSE state END "
      "WHERE id = ?1 AND preview_levels IS NOT NULL AND promoted = 0");
  auto link =
      connection_.prepare("INSERT OR IGNORE INTO sweep_jobs (sweep_id, job_id) VALUES (?1, ?2)");
  SweepAddition addition;
  for (const auto& job : jobs) {
    const std::string parameters = job.parameters.dump();
    if (stored.reset().bind_all(job.id).step()) {
      if (stored.text(0) != parameters)
        throw InputError(fmt::format(
            "sweep '{}': job id {} is already stored with other parameters ({} instead of {}); "
            "job ids must be hashes of the canonical parameters",
            name, job.id, stored.text(0), parameters));
      ++addition.already_present;
      widen.reset().bind_all(job.id, job.preview_levels).run();
    } else {
      insert.reset().bind_all(job.id, parameters, job.scene, job.depth, job.max_attempts, time,
                              job.preview_levels, std::string(to_string(job.method)));
      insert.run();
      addition.added.push_back(job.id);
    }
    link.reset().bind_all(sweep_id, job.id).run();
  }
  if (commit) {
    stored.reset();
    transaction.commit();
  }
  return addition;
}

void JobStore::expire_leases(double time) {
  // An attempt that recorded a new checkpoint was interrupted, not crash-looping: its job goes
  // back to the queue as `psq resume` would put it, with no failure counted.
  connection_
      .prepare(fmt::format("UPDATE jobs SET {} WHERE state = 'running' AND lease_expiry <= ?1 AND "
                           "progress_attempt = attempt",
                           kBackToTheQueue))
      .bind_all(time)
      .run();
  // The others died without progress: each such death counts, so a job that kills its worker
  // every time (out of memory, a time limit) is stopped after max_attempts.
  connection_
      .prepare(
          "UPDATE jobs SET failures = failures + 1, stalls = stalls + 1, "
          "state = CASE WHEN failures + 1 >= max_attempts THEN 'failed' ELSE 'queued' END, "
          "ended_at = CASE WHEN failures + 1 >= max_attempts THEN ?1 ELSE ended_at END, "
          "error = printf('attempt %d by worker %s stopped sending heartbeats (last at %s UTC) "
          "and its lease expired; its worker died %s without progress (no new checkpoint)%s', "
          "attempt, lease_owner, strftime('%Y-%m-%d %H:%M:%S', heartbeat_at, 'unixepoch'), "
          "CASE WHEN stalls = 0 THEN 'once' ELSE printf('%d times in a row', stalls + 1) END, "
          "CASE WHEN failures + 1 >= max_attempts THEN printf(', which makes %d of the %d failed "
          "attempts allowed; find what kills the worker (memory? a time limit?), then run psq "
          "retry', failures + 1, max_attempts) ELSE '' END), "
          "lease_owner = NULL, lease_expiry = NULL "
          "WHERE state = 'running' AND lease_expiry <= ?1")
      .bind_all(time)
      .run();
}

std::optional<Claim> JobStore::claim_next(const WorkerInfo& worker, double lease_seconds) {
  return claim_next(worker, lease_seconds, JobSelection::all());
}

std::optional<Claim> JobStore::claim_next(const WorkerInfo& worker, double lease_seconds,
                                          const JobSelection& which) {
  if (worker.id.empty()) throw std::invalid_argument("claim_next: empty worker id");
  if (!(lease_seconds > 0))
    throw std::invalid_argument(fmt::format("claim_next: lease of {} s", lease_seconds));
  Transaction transaction(connection_, Transaction::Mode::immediate);
  check_selection_exists(which);
  const double time = now();
  expire_leases(time);
  apply_settled_rules();
  std::string id;
  {
    auto next = connection_.prepare("SELECT id FROM jobs WHERE state = 'queued' AND " +
                                    selection_condition(which) + " ORDER BY number LIMIT 1");
    if (!next.bind_all(selection_value(which)).step()) {
      next.reset();
      transaction.commit();
      return std::nullopt;
    }
    id = next.text(0);
  }
  if (options_.inside_claim_transaction) options_.inside_claim_transaction();
  connection_
      .prepare(
          "UPDATE jobs SET state = 'running', attempt = attempt + 1, lease_owner = ?2, "
          "lease_expiry = ?3, heartbeat_at = ?4, host = ?5, code_version = ?6, started_at = ?4, "
          "ended_at = NULL WHERE id = ?1")
      .bind_all(id, worker.id, time + lease_seconds, time, worker.host, worker.code_version)
      .run();
  auto claimed = jobs_where("1", JobSelection::job(id));
  transaction.commit();
  Job& job = claimed.front();
  Lease lease{job.id, job.attempt, lease_seconds};
  return Claim{std::move(job), std::move(lease)};
}

bool JobStore::heartbeat(const Lease& lease) {
  const double time = now();
  return connection_
             .prepare(
                 "UPDATE jobs SET lease_expiry = ?3, heartbeat_at = ?4 "
                 "WHERE id = ?1 AND attempt = ?2 AND state = 'running'")
             .bind_all(lease.job_id, lease.attempt, time + lease.seconds, time)
             .run() == 1;
}

int JobStore::check_lease(const Lease& lease) {
  auto job = connection_.prepare("SELECT state, attempt, depth FROM jobs WHERE id = ?1");
  if (!job.bind_all(lease.job_id).step())
    throw LeaseLostError(
        fmt::format("job {} is not in {}; the write was refused", lease.job_id, path().string()));
  if (job.text(0) != to_string(JobState::running) || job.integer(1) != lease.attempt)
    throw LeaseLostError(fmt::format(
        "job {}: attempt {} no longer holds the lease (the job is {} at attempt {}); the write "
        "was refused",
        lease.job_id, lease.attempt, job.text(0), job.integer(1)));
  return static_cast<int>(job.integer(2));
}

void JobStore::record_level(const Lease& lease, const LevelRecord& level) {
  Transaction transaction(connection_, Transaction::Mode::immediate);
  const int depth = check_lease(lease);
  if (level.level < 0 || level.level >= depth)
    throw std::invalid_argument(
        fmt::format("job {}: level {} outside [0, {})", lease.job_id, level.level, depth));
  const auto path = unless_empty(level.checkpoint_path);
  const auto checksum = unless_empty(level.checkpoint_checksum);
  // Progress is a checkpoint the level's row did not hold yet. A resumed attempt records again
  // the finished level it resumed from; that repeats the row and is no progress. New progress
  // also forgives the deaths without progress before it: they were interruptions.
  connection_
      .prepare(
          "UPDATE jobs SET progress_attempt = ?2, failures = failures - stalls, stalls = 0 "
          "WHERE id = ?1 AND ?5 IS NOT NULL AND NOT EXISTS (SELECT 1 FROM levels "
          "WHERE job_id = ?1 AND level = ?3 AND status = ?4 AND checkpoint_path IS ?5 "
          "AND checkpoint_checksum IS ?6)")
      .bind_all(lease.job_id, lease.attempt, level.level, to_string(level.status), path, checksum)
      .run();
  connection_
      .prepare(
          "REPLACE INTO levels (job_id, level, status, iterations, residuals, timings, "
          "checkpoint_path, checkpoint_checksum, error, attempt, updated_at, static_residuals, "
          "refinement, outputs) VALUES (?1, ?2, ?3, ?4, ?5, ?6, ?7, ?8, ?9, ?10, ?11, ?12, ?13, "
          "?14)")
      .bind_all(lease.job_id, level.level, to_string(level.status), level.iterations,
                nlohmann::json(level.residuals).dump(), named_numbers_json(level.timings),
                path, checksum, unless_empty(level.error), lease.attempt, now(),
                nlohmann::json(level.static_residuals).dump(),
                named_numbers_json(level.refinement), named_numbers_json(level.outputs))
      .run();
  write_frames(lease.job_id, level);
  if (options_.inside_record_transaction) options_.inside_record_transaction();
  transaction.commit();
}

void JobStore::write_frames(const std::string& job_id, const LevelRecord& level) {
  auto frame = connection_.prepare(
      "REPLACE INTO frames (job_id, level, frame, load_scale) VALUES (?1, ?2, ?3, ?4)");
  auto probe = connection_.prepare(
      "REPLACE INTO probe_readings (job_id, level, frame, probe, kind, x, y, z) "
      "VALUES (?1, ?2, ?3, ?4, ?5, ?6, ?7, ?8)");
  for (const FrameReadings& readings : level.frames) {
    frame.reset().bind_all(job_id, level.level, readings.frame, readings.load_scale).run();
    for (const ProbeValue& value : readings.probes)
      probe.reset()
          .bind_all(job_id, level.level, readings.frame, value.probe, value.kind, value.value[0],
                    value.value[1], value.value[2])
          .run();
  }
}

void JobStore::read_frames(const JobSelection& which, std::vector<JobResult>& results) {
  std::map<std::pair<std::string, int>, LevelRecord*> level_of;
  for (JobResult& result : results)
    for (LevelRecord& level : result.levels) level_of[{result.job.id, level.level}] = &level;
  const auto level_record = [&](const std::string& job, int level) -> LevelRecord* {
    const auto found = level_of.find({job, level});
    return found == level_of.end() ? nullptr : found->second;
  };
  auto frames = rows_of_jobs(connection_, "job_id, level, frame, load_scale", "frames",
                             "job_id, level, frame", which);
  while (frames.step())
    if (LevelRecord* level = level_record(frames.text(0), static_cast<int>(frames.integer(1))))
      level->frames.push_back({static_cast<int>(frames.integer(2)), frames.real(3), {}});
  auto probes = rows_of_jobs(connection_, "job_id, level, frame, probe, kind, x, y, z",
                             "probe_readings", "job_id, level, frame, probe", which);
  while (probes.step()) {
    LevelRecord* level = level_record(probes.text(0), static_cast<int>(probes.integer(1)));
    if (!level) continue;
    const int number = static_cast<int>(probes.integer(2));
    const auto frame = std::find_if(level->frames.begin(), level->frames.end(),
                                    [&](const FrameReadings& f) { return f.frame == number; });
    if (frame == level->frames.end()) continue;
    frame->probes.push_back(
        {probes.text(3), probes.text(4), {probes.real(5), probes.real(6), probes.real(7)}});
  }
}

void JobStore::record_hierarchy_uses(const Lease& lease,
                                     const std::vector<HierarchyCacheUse>& uses) {
  Transaction transaction(connection_, Transaction::Mode::immediate);
  check_lease(lease);
  for (std::size_t position = 0; position < uses.size(); ++position)
    connection_
        .prepare(
            "REPLACE INTO hierarchy_cache_uses (job_id, attempt, position, cache_key, hit, "
            "seconds) VALUES (?1, ?2, ?3, ?4, ?5, ?6)")
        .bind_all(lease.job_id, lease.attempt, static_cast<std::int64_t>(position),
                  uses[position].key, static_cast<int>(uses[position].hit), uses[position].seconds)
        .run();
  transaction.commit();
}

void JobStore::finish(const Lease& lease, Outcome outcome, const std::string& error) {
  Transaction transaction(connection_, Transaction::Mode::immediate);
  check_lease(lease);
  if (outcome == Outcome::done || outcome == Outcome::previewed) {
    connection_
        .prepare(
            "UPDATE jobs SET state = ?3, error = NULL, lease_owner = NULL, "
            "lease_expiry = NULL, ended_at = ?2 WHERE id = ?1")
        .bind_all(lease.job_id, now(),
                  to_string(outcome == Outcome::done ? JobState::done : JobState::previewed))
        .run();
  } else {
    const int permanent = outcome == Outcome::failed_permanently;
    connection_
        .prepare(
            "UPDATE jobs SET failures = failures + 1, state = CASE WHEN ?4 OR failures + 1 >= "
            "max_attempts THEN 'failed' ELSE 'queued' END, error = ?3, lease_owner = NULL, "
            "lease_expiry = NULL, ended_at = ?2 WHERE id = ?1")
        .bind_all(lease.job_id, now(), unless_empty(error), permanent)
        .run();
  }
  if (outcome == Outcome::previewed)
    connection_
        .prepare(
            "UPDATE sweeps SET refine_pending = 1 WHERE id IN "
            "(SELECT sweep_id FROM sweep_jobs WHERE job_id = ?1)")
        .bind_all(lease.job_id)
        .run();
  // In the same transaction as the job's end, so that the last preview of a sweep (or its last
  // failure) and the promotion it triggers are one step that a killed worker cannot split.
  apply_settled_rules();
  if (options_.inside_finish_transaction) options_.inside_finish_transaction();
  transaction.commit();
}

bool JobStore::release(const Lease& lease, const std::string& reason) {
  // A clean release leaves the error alone: it still tells of the last failure, if any.
  return connection_
             .prepare(fmt::format("UPDATE jobs SET {}, error = COALESCE(?3, error) "
                                  "WHERE id = ?1 AND attempt = ?2 AND state = 'running'",
                                  kBackToTheQueue))
             .bind_all(lease.job_id, lease.attempt, unless_empty(reason))
             .run() == 1;
}

void JobStore::check_selection_exists(const JobSelection& which) {
  if (which.kind() == JobSelection::Kind::all) return;
  const bool is_sweep = which.kind() == JobSelection::Kind::sweep;
  auto found = connection_.prepare(is_sweep ? "SELECT 1 FROM sweeps WHERE name = ?1"
                                            : "SELECT 1 FROM jobs WHERE id = ?1");
  if (found.bind_all(which.name()).step()) return;
  if (!is_sweep)
    throw InputError(fmt::format("{}: no job with id {}", path().string(), which.name()));
  std::vector<std::string> names;
  auto sweeps = connection_.prepare("SELECT name FROM sweeps ORDER BY id");
  while (sweeps.step()) names.push_back(sweeps.text(0));
  if (names.empty()) names.push_back("no sweeps");
  throw InputError(fmt::format("{}: no sweep named '{}' (the store has: {})", path().string(),
                               which.name(), fmt::join(names, ", ")));
}

std::int64_t JobStore::update_selected(const JobSelection& which, const std::string& update) {
  Transaction transaction(connection_, Transaction::Mode::immediate);
  check_selection_exists(which);
  Statement statement = connection_.prepare(update + " AND " + selection_condition(which));
  statement.bind(1, selection_value(which));
  if (statement.parameter_count() >= 2) statement.bind(2, now());
  const std::int64_t changed = statement.run();
  transaction.commit();
  return changed;
}

std::int64_t JobStore::cancel(const JobSelection& which) {
  return update_selected(which,
                         "UPDATE jobs SET state = 'cancelled', lease_owner = NULL, "
                         "lease_expiry = NULL, ended_at = ?2 WHERE state IN ('queued', 'running')");
}

std::int64_t JobStore::requeue_interrupted(const JobSelection& which) {
  return update_selected(
      which, fmt::format("UPDATE jobs SET {} WHERE state = 'running' AND lease_expiry <= ?2",
                         kBackToTheQueue));
}

std::int64_t JobStore::retry(const JobSelection& which, bool include_cancelled) {
  const std::string states = include_cancelled ? "('failed', 'cancelled')" : "('failed')";
  return update_selected(
      which,
      "UPDATE jobs SET state = 'queued', failures = 0, stalls = 0, error = NULL, "
      "ended_at = NULL WHERE state IN " +
          states);
}

std::vector<PreviewPoint> JobStore::preview_points(std::int64_t sweep_id) {
  // Every job of the sweep that has its preview: waiting at it, or promoted past it. The last
  // preview level's outputs, and the one before it for rules on the change between the two.
  auto rows = connection_.prepare(
      "SELECT jobs.id, jobs.parameters, jobs.preview_levels, levels.level, levels.outputs, "
      "jobs.depth "
      "FROM jobs JOIN sweep_jobs ON sweep_jobs.job_id = jobs.id "
      "JOIN levels ON levels.job_id = jobs.id AND levels.status = 'done' "
      "AND levels.level >= jobs.preview_levels - 2 AND levels.level < jobs.preview_levels "
      "WHERE sweep_jobs.sweep_id = ?1 AND jobs.preview_levels IS NOT NULL "
      "AND (jobs.state = 'previewed' OR jobs.promoted = 1) ORDER BY jobs.number, levels.level");
  rows.bind_all(sweep_id);
  std::vector<PreviewPoint> points;
  while (rows.step()) {
    if (points.empty() || points.back().job_id != rows.text(0)) {
      PreviewPoint& point = points.emplace_back();
      point.job_id = rows.text(0);
      const nlohmann::json parameters = nlohmann::json::parse(rows.text(1));
      point.parameters["depth"] = static_cast<double>(rows.integer(5));
      const nlohmann::json overrides = parameters.value("overrides", nlohmann::json::object());
      for (const auto& [path, value] : overrides.items())
        if (value.is_number()) point.parameters[path] = value.get<double>();
    }
    const bool last = rows.integer(3) == rows.integer(2) - 1;
    (last ? points.back().outputs : points.back().earlier_outputs) =
        stored_named_numbers(rows.text(4));
  }
  // A job whose last preview level is not recorded as done has no preview to judge.
  std::erase_if(points, [](const PreviewPoint& point) { return point.outputs.empty(); });
  return points;
}

Promotion JobStore::promote_in_transaction(std::int64_t sweep_id, const RefineRule& rule) {
  const std::vector<PreviewPoint> points = preview_points(sweep_id);
  Promotion promotion;
  promotion.candidates = static_cast<std::int64_t>(points.size());
  promotion.selected = select_points(rule, points);
  auto promote = connection_.prepare(
      "UPDATE jobs SET state = 'queued', promoted = 1, ended_at = NULL "
      "WHERE id = ?1 AND state = 'previewed'");
  for (const std::string& id : promotion.selected)
    if (promote.reset().bind_all(id).run() == 1) promotion.promoted.push_back(id);
  return promotion;
}

void JobStore::apply_settled_rules() {
  struct Pending {
    std::int64_t id;
    std::string refine;
  };
  std::vector<Pending> settled;
  {
    auto rows = connection_.prepare(
        "SELECT sweeps.id, sweeps.refine FROM sweeps WHERE refine_pending = 1 AND NOT EXISTS "
        "(SELECT 1 FROM sweep_jobs JOIN jobs ON jobs.id = sweep_jobs.job_id "
        "WHERE sweep_jobs.sweep_id = sweeps.id AND jobs.preview_levels IS NOT NULL "
        "AND jobs.promoted = 0 AND jobs.state IN ('queued', 'running'))");
    while (rows.step()) settled.push_back({rows.integer(0), rows.text(1)});
  }
  auto applied = connection_.prepare("UPDATE sweeps SET refine_pending = 0 WHERE id = ?1");
  for (const Pending& sweep : settled) {
    const RefineRule rule = refine_rule_from_json(nlohmann::json::parse(sweep.refine));
    if (rule.selects()) promote_in_transaction(sweep.id, rule);
    applied.reset().bind_all(sweep.id).run();
  }
}

Promotion JobStore::promote(const std::string& sweep, const RefineRule& rule) {
  Transaction transaction(connection_, Transaction::Mode::immediate);
  check_selection_exists(JobSelection::sweep(sweep));
  auto found = connection_.prepare("SELECT id FROM sweeps WHERE name = ?1");
  found.bind_all(sweep).step();
  const std::int64_t sweep_id = found.integer(0);
  found.reset();
  Promotion promotion = promote_in_transaction(sweep_id, rule);
  transaction.commit();
  return promotion;
}

std::vector<SweepStatus> JobStore::status() {
  auto rows = connection_.prepare(
      "SELECT sweeps.name, sweeps.source, sweeps.created_at, jobs.state, COUNT(jobs.id), "
      "COALESCE(SUM(jobs.state = 'running' AND jobs.lease_expiry <= ?1), 0), sweeps.refine "
      "FROM sweeps LEFT JOIN sweep_jobs ON sweep_jobs.sweep_id = sweeps.id "
      "LEFT JOIN jobs ON jobs.id = sweep_jobs.job_id "
      "GROUP BY sweeps.id, jobs.state ORDER BY sweeps.id");
  rows.bind_all(now());
  std::vector<SweepStatus> sweeps;
  while (rows.step()) {
    if (sweeps.empty() || sweeps.back().name != rows.text(0)) {
      SweepStatus& sweep = sweeps.emplace_back();
      sweep.name = rows.text(0);
      sweep.source = rows.text(1);
      sweep.created_at = rows.real(2);
      sweep.refine = refine_rule_from_json(nlohmann::json::parse(rows.text(6)));
      for (const JobState state : kAllJobStates) sweep.counts[state] = 0;
    }
    if (rows.is_null(3)) continue;  // a sweep without jobs
    sweeps.back().counts[job_state_from_string(rows.text(3))] = rows.integer(4);
    sweeps.back().expired_leases += rows.integer(5);
  }
  return sweeps;
}

SweepStatus JobStore::status(const std::string& sweep) {
  check_selection_exists(JobSelection::sweep(sweep));
  for (auto& counted : status())
    if (counted.name == sweep) return counted;
  throw InputError(fmt::format("{}: no sweep named '{}'", path().string(), sweep));
}

std::vector<Job> JobStore::jobs_where(const std::string& condition, const JobSelection& which) {
  auto rows =
      connection_.prepare(fmt::format("SELECT {} FROM jobs WHERE {} AND ({}) ORDER BY "
                                      "jobs.number",
                                      kJobColumns, selection_condition(which), condition));
  rows.bind_all(selection_value(which));
  std::vector<Job> jobs;
  while (rows.step()) jobs.push_back(read_job(rows));
  return jobs;
}

std::vector<Job> JobStore::failures(const JobSelection& which) {
  Transaction snapshot(connection_, Transaction::Mode::deferred);
  check_selection_exists(which);
  return jobs_where("jobs.error IS NOT NULL OR jobs.state = 'failed'", which);
}

std::vector<JobResult> JobStore::results(const JobSelection& which) {
  // One read transaction: the jobs and their levels come from the same snapshot.
  Transaction snapshot(connection_, Transaction::Mode::deferred);
  check_selection_exists(which);
  std::vector<JobResult> results;
  std::map<std::string, std::size_t> index_of;
  for (auto& job : jobs_where("1", which)) {
    index_of[job.id] = results.size();
    results.push_back({std::move(job), {}, {}});
  }
  auto levels = rows_of_jobs(connection_, fmt::format("job_id, {}", kLevelColumns), "levels",
                             "job_id, level", which);
  while (levels.step())
    results[index_of.at(levels.text(0))].levels.push_back(read_level(levels, 1));
  auto uses = rows_of_jobs(connection_, "job_id, cache_key, hit, seconds, attempt",
                           "hierarchy_cache_uses", "job_id, attempt, position", which);
  while (uses.step())
    results[index_of.at(uses.text(0))].hierarchy_uses.push_back(
        {uses.text(1), uses.integer(2) != 0, uses.real(3), uses.integer(4)});
  read_frames(which, results);
  return results;
}

std::optional<Job> JobStore::find_job(const std::string& id) {
  auto found = jobs_where("1", JobSelection::job(id));
  if (found.empty()) return std::nullopt;
  return std::move(found.front());
}

std::vector<std::string> JobStore::integrity_problems() {
  std::vector<std::string> problems;
  auto integrity = connection_.prepare("PRAGMA integrity_check");
  while (integrity.step())
    if (integrity.text(0) != "ok") problems.push_back(integrity.text(0));
  auto foreign_keys = connection_.prepare("PRAGMA foreign_key_check");
  while (foreign_keys.step())
    problems.push_back(fmt::format("row {} of {} refers to a missing row of {}",
                                   foreign_keys.integer(1), foreign_keys.text(0),
                                   foreign_keys.text(2)));
  return problems;
}

}  // namespace psq::db
