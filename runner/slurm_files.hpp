#pragma once
// The files that connect the submitting host and the array tasks (docs/slurm.md), all on the
// shared file system and all written atomically:
//   <store dir>/slurm/<submission>/manifest.json   the frozen list of jobs, one per array task
//   <store dir>/slurm/<submission>/array.sbatch    the array job script
//   runs/<job id>/slurm/task.db                    the task's own job store (one job)
//   runs/<job id>/slurm/result.json                how the task's last run ended
// A task reads the manifest and writes only below its job's directory; the submitting host's
// store is never opened by a task.

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "db/job_records.hpp"

namespace psq::runner::slurm {

/// What every array task of one submission needs: the sweep's pending jobs, frozen at
/// submission (task index i runs jobs[i]), and how to run them.
struct Manifest {
  std::string sweep;
  std::filesystem::path runs;  ///< job directories: runs / <job id>
  int snapshot_iterations = 50;
  double snapshot_seconds = 60.0;
  std::vector<db::NewJob> jobs;
};

void write_manifest(const std::filesystem::path& file, const Manifest& manifest);
/// Throws InputError naming the file if it is missing or not a manifest.
Manifest read_manifest(const std::filesystem::path& file);

/// How one run of an array task ended, for `psq slurm sync` to bring into the store.
struct TaskResult {
  std::string array_id;  ///< the array job the task belonged to
  int index = 0;         ///< its index in the array
  /// done; failed (for good, or after the job's attempts inside the task); queued: stopped by a
  /// signal after writing a checkpoint, to continue when SLURM runs the task again.
  db::JobState state = db::JobState::queued;
  std::string error;
  std::vector<db::LevelRecord> levels;  ///< the task store's records, coarsest first
};

/// runs / <job id> / slurm: the task's files, inside the job's own directory.
std::filesystem::path task_directory(const std::filesystem::path& runs, const std::string& job_id);
std::filesystem::path task_store(const std::filesystem::path& runs, const std::string& job_id);
std::filesystem::path task_result(const std::filesystem::path& runs, const std::string& job_id);

void write_task_result(const std::filesystem::path& file, const TaskResult& result);
/// Nothing when the file does not exist (the task has not ended a run, or was killed).
/// Throws InputError naming the file if it cannot be parsed.
std::optional<TaskResult> read_task_result(const std::filesystem::path& file);

}  // namespace psq::runner::slurm
