#pragma once
// The store's table of SLURM array tasks (db/schema.cpp, migration 2): which task holds which
// claim of a job, and what the scheduler last said about it. The claim itself is an ordinary
// lease in `jobs` whose owner is "slurm:<array>_<index>" (slurm_owner), so the job store's
// rules (fencing, cancel, retry) apply unchanged; this table only adds the cluster's view.

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "db/sqlite_handle.hpp"

namespace psq::runner::slurm {

/// The lease owner of a job claimed for an array task.
std::string slurm_owner(const std::string& array_id, int index);
/// The array id and index of a lease owner made by slurm_owner; nothing for any other owner.
std::optional<std::pair<std::string, int>> parse_slurm_owner(const std::string& owner);

struct SlurmTask {
  std::string job_id;
  std::int64_t attempt = 0;  ///< the job's claim (fencing token) this task holds
  std::string array_id;
  int index = 0;
  std::string manifest;
  std::string state;   ///< SLURM's state name, last seen
  std::string reason;  ///< squeue's reason or sacct's exit code; or psq's note
  double submitted_at = 0;  ///< when its current run was submitted, or requeued by sync
  std::optional<double> synced_at;
};

/// One connection to the table in the store at `database` (opened, and so migrated, by a
/// JobStore first).
class SlurmTaskTable {
 public:
  explicit SlurmTaskTable(const std::filesystem::path& database);

  /// Adds the tasks, or updates the state, reason, submission and sync time of the ones
  /// already there.
  /// One transaction.
  void record(const std::vector<SlurmTask>& tasks);
  /// The tasks of the sweep (every sweep when empty) that hold their job now: the job is
  /// running with the task's attempt. By array, then index.
  std::vector<SlurmTask> holding(const std::string& sweep);
  /// The tasks of the sweep (every sweep when empty) whose job was cancelled in the store
  /// (psq cancel) while they held it.
  std::vector<SlurmTask> cancelled(const std::string& sweep);

 private:
  std::vector<SlurmTask> select(const std::string& job_state, const std::string& sweep);

  db::SqliteConnection connection_;
};

}  // namespace psq::runner::slurm
