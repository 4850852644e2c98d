#pragma once
// SLURM's client commands as psq uses them: sbatch to submit an array job, squeue and sacct to
// learn what became of its tasks, scancel and scontrol to stop or requeue one. Each command is
// looked up on PATH and talks to whatever cluster its environment names (SLURM_CONF), so psq
// needs no SLURM library. Output formats are pinned with --format/--parsable and parsed by
// field, which holds from SLURM 20.11 to 23.x (Debian 12 ships 22.05). docs/slurm.md.

#include <filesystem>
#include <map>
#include <string>
#include <vector>

namespace psq::runner::slurm {

/// What the scheduler says about one array task.
struct TaskState {
  std::string state;   ///< SLURM's job state name: PENDING, RUNNING, COMPLETED, CANCELLED, ...
  std::string reason;  ///< squeue's reason (Resources, BeginTime, ...) or sacct's exit code
};

/// True for the states in which the task will still run or is running (pending, running,
/// being requeued, suspended...): the job stays the cluster's.
bool is_live(const std::string& state);

/// An array task's SLURM name, "<array id>_<index>".
std::string task_name(const std::string& array_id, int index);

class Scheduler {
 public:
  /// Captures the commands' output in a fresh temporary directory, removed on destruction.
  Scheduler();
  ~Scheduler();
  Scheduler(const Scheduler&) = delete;
  Scheduler& operator=(const Scheduler&) = delete;

  /// Submits `script` with `sbatch --parsable`; returns the array job's id. Throws InputError
  /// with sbatch's own message and what to fix (no sbatch on PATH, controller unreachable,
  /// unknown partition, ...).
  std::string submit(const std::filesystem::path& script);

  /// The state of every task of the given arrays that the scheduler still knows: squeue for
  /// tasks in the controller's memory (live ones and those ended within MinJobAge), sacct for
  /// older ones. Keyed by task_name. A cluster without accounting (sacct refuses) answers from
  /// squeue alone. Throws InputError when squeue cannot reach the controller.
  std::map<std::string, TaskState> states(const std::vector<std::string>& array_ids);

  /// `scancel TASK`; throws InputError with scancel's message if it fails.
  void cancel(const std::string& task);
  /// `scontrol requeue TASK`; throws InputError with scontrol's message if it fails.
  void requeue(const std::string& task);

 private:
  struct Output {
    int status = 0;
    std::string out;
    std::string errors;
  };
  Output run(const std::string& program, const std::vector<std::string>& arguments);

  std::filesystem::path scratch_;
};

}  // namespace psq::runner::slurm
