#pragma once
// The SQLite job store: sweeps, jobs with leases, per-level records. Several worker processes
// share one store on local disk. Every write is one short transaction; claims run inside
// BEGIN IMMEDIATE; every write about a claimed job carries its Lease, whose attempt number is a
// fencing token: once the job has been claimed again (or cancelled, finished, released), a
// late write from the old attempt is refused and changes nothing. docs/job-store.md has the
// whole protocol.

#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "db/job_records.hpp"
#include "db/sqlite_handle.hpp"

namespace psq::db {

/// A write about a job whose lease this attempt no longer holds: the job was claimed again
/// after the lease expired, cancelled, finished or released. The worker must stop the job.
class LeaseLostError : public Error {
 public:
  using Error::Error;
};

struct JobStoreOptions {
  /// How long a statement waits for another process's write lock before failing.
  int busy_timeout_ms = 10'000;
  /// Seconds since the Unix epoch; the system clock when empty. Tests move time by hand.
  std::function<double()> clock;
  /// Test seam: called inside claim_next's transaction, after the job is chosen and before the
  /// claim is committed (to kill a process while it holds the write lock).
  std::function<void()> inside_claim_transaction;
  /// Test seam: called inside record_level's transaction, after the row is written and before
  /// the commit (to kill a process in the middle of a database write).
  std::function<void()> inside_record_transaction;
  /// Test seam: called inside finish's transaction, after the job's end and any promotion it
  /// triggers are written and before the commit.
  std::function<void()> inside_finish_transaction;
};

/// One connection to a job store. Not thread-safe: use one JobStore per thread (e.g. a second
/// one for a heartbeat thread), and open a new one after fork().
class JobStore {
 public:
  /// Opens the store at `path`, creating it and its parent directories if needed, in WAL mode
  /// with synchronous=NORMAL, foreign keys on, and migrations applied. Throws InputError naming
  /// the file if it is not a SQLite database, belongs to another program, or has a newer
  /// schema than this build.
  explicit JobStore(const std::filesystem::path& path, JobStoreOptions options = {});

  const std::filesystem::path& path() const { return connection_.path(); }

  /// Adds the sweep `name` (or extends it) with the jobs whose ids are not yet stored; jobs
  /// already stored (by this or another sweep) are only linked to it and keep their state,
  /// except that a job keeps the most levels any of its sweeps asks of it (a previewed job
  /// linked to a sweep that wants more goes back to the queue). `refine` (the sweep's, stored
  /// with it and replacing an earlier one) is applied once the previews are in. Throws
  /// InputError if a job is invalid or an id is stored with other parameters.
  SweepAddition add_sweep(const std::string& name, const std::string& source,
                          const std::vector<NewJob>& jobs, const RefineRule& refine = {});
  /// What add_sweep would do, without changing anything.
  SweepAddition preview_sweep(const std::string& name, const std::vector<NewJob>& jobs);

  /// Promotes the previewed jobs of `sweep` that `rule` selects: they go back to the queue and
  /// then run their finer levels, resuming from their preview checkpoints. The rule judges
  /// every job of the sweep that has a preview (promoted ones too, so that a ranking means the
  /// same whenever it is applied). One write transaction: two processes never promote a job
  /// twice. Throws InputError for an unknown sweep or a condition naming nothing the jobs have.
  Promotion promote(const std::string& sweep, const RefineRule& rule);

  /// Claims the first queued job (in the order jobs were added) for `worker`, with a lease of
  /// `lease_seconds`. Running jobs whose lease expired are first put back in the queue: with
  /// no failure counted if the expired attempt recorded a new checkpoint, else with one more
  /// failure (or failed, if that was their last attempt). Returns nothing when no job is
  /// queued.
  std::optional<Claim> claim_next(const WorkerInfo& worker, double lease_seconds);
  /// claim_next among the selected jobs only (e.g. one sweep's). Throws InputError for an
  /// unknown sweep or job.
  std::optional<Claim> claim_next(const WorkerInfo& worker, double lease_seconds,
                                  const JobSelection& which);
  /// Pushes the lease expiry to now + lease.seconds. False if the lease is lost (the worker
  /// must stop the job; its writes would be refused).
  [[nodiscard]] bool heartbeat(const Lease& lease);
  /// Stores (or replaces) the record of one level; one with a checkpoint the row did not hold
  /// is the attempt's progress. Throws LeaseLostError if the lease is lost,
  /// std::invalid_argument if the level is outside [0, depth).
  void record_level(const Lease& lease, const LevelRecord& level);
  /// Stores how this attempt obtained its hierarchies (one row each, in order; an attempt
  /// records them once). Throws LeaseLostError if the lease is lost.
  void record_hierarchy_uses(const Lease& lease, const std::vector<HierarchyCacheUse>& uses);
  /// Ends the attempt: done, or failed with `error` (queued again while failures stay below
  /// max_attempts, unless permanent). Throws LeaseLostError if the lease is lost.
  void finish(const Lease& lease, Outcome outcome, const std::string& error = {});
  /// Gives the job back to the queue without counting a failure: a clean shutdown, or an
  /// attempt stopped by its environment (a file it could not write), whose `reason` is then
  /// kept as the job's error until the job finishes. False if the lease was already lost.
  bool release(const Lease& lease, const std::string& reason = {});

  /// Cancels the selected queued or running jobs; returns how many. A running job's worker
  /// learns it from its next heartbeat.
  std::int64_t cancel(const JobSelection& which);
  /// Puts the selected running jobs whose lease has expired back in the queue without counting
  /// a failure (a user resuming interrupted work: the worker was stopped, the job did not
  /// fail); returns how many. Throws InputError for an unknown sweep or job.
  std::int64_t requeue_interrupted(const JobSelection& which);
  /// Puts the selected failed jobs (and cancelled ones, if `include_cancelled`) back in the
  /// queue with their failure count reset; returns how many.
  std::int64_t retry(const JobSelection& which, bool include_cancelled = false);

  /// Counts per state of every sweep, in the order sweeps were created.
  std::vector<SweepStatus> status();
  /// Counts per state of one sweep. Throws InputError for an unknown sweep.
  SweepStatus status(const std::string& sweep);
  /// The selected jobs that have a failure message (failed ones, and ones waiting for a retry).
  std::vector<Job> failures(const JobSelection& which);
  /// The selected jobs with their level records and hierarchy cache uses, in the order jobs
  /// were added.
  std::vector<JobResult> results(const JobSelection& which);
  /// The job with this id, if stored.
  std::optional<Job> find_job(const std::string& id);
  /// Result of SQLite's integrity check: empty if the database is sound, else the problems.
  std::vector<std::string> integrity_problems();

 private:
  SweepAddition add_jobs(const std::string& name, const std::string& source,
                         const std::vector<NewJob>& jobs, const RefineRule& refine, bool commit);
  void expire_leases(double time);
  /// Applies the rule of every sweep whose previews have come in since its rule was last
  /// applied, once none of its jobs is still queued or running towards its preview. Inside the
  /// caller's write transaction.
  void apply_settled_rules();
  /// In the caller's write transaction: the selection of `rule` among the previews of the
  /// sweep `sweep_id`, and those promoted.
  Promotion promote_in_transaction(std::int64_t sweep_id, const RefineRule& rule);
  std::vector<PreviewPoint> preview_points(std::int64_t sweep_id);
  /// Throws LeaseLostError unless the job is running with the lease's attempt; returns its
  /// depth.
  int check_lease(const Lease& lease);
  /// Writes level.frames of the job, each replacing its frame's rows (inside record_level's
  /// transaction).
  void write_frames(const std::string& job_id, const LevelRecord& level);
  /// Adds to each level of `results` (the jobs of `which`) its stored frames, in frame order.
  void read_frames(const JobSelection& which, std::vector<JobResult>& results);
  /// Throws InputError if the selection names a sweep or job that is not stored.
  void check_selection_exists(const JobSelection& which);
  /// In one immediate transaction, after check_selection_exists: runs `update` (an UPDATE of
  /// `jobs` ending in a WHERE condition) on the selected jobs only. ?1 is the selection's value;
  /// ?2, if `update` uses it, the current time, read inside the transaction. Returns the number
  /// of jobs changed.
  std::int64_t update_selected(const JobSelection& which, const std::string& update);
  std::vector<Job> jobs_where(const std::string& condition, const JobSelection& which);
  double now() const;

  JobStoreOptions options_;
  SqliteConnection connection_;
};

}  // namespace psq::db
