#pragma once
// Where psq keeps its state: the workspace directory `.psq/` in the current directory, with
// the job store `.psq/psq.db` and the job outputs `.psq/runs/<job id>/`. `--db PATH` or the
// PSQ_DB environment variable choose another store; the outputs are always in `runs/` beside
// it. Also the settings of the commands that run jobs (`psq work`, `psq resume`).

#include <CLI/CLI.hpp>
#include <filesystem>
#include <functional>
#include <initializer_list>
#include <string>
#include <vector>

#include "db/job_store.hpp"
#include "runner/commands.hpp"

namespace psq::runner {

/// The job store's path: `option` if given, else $PSQ_DB if set and not empty, else
/// .psq/psq.db in the current directory.
std::filesystem::path database_path(const std::string& option);

/// Adds `--db PATH` to a subcommand, filling `path`.
void add_database_option(CLI::App& command, std::string& path);

/// The directory of the job outputs that belong to the store at `database`: `runs/` beside it.
std::filesystem::path runs_directory(const std::filesystem::path& database);
/// Where built hierarchies are cached: `cache/` beside the database (jobs that vary only
/// material or thickness share one hierarchy).
std::filesystem::path hierarchy_cache_directory(const std::filesystem::path& database);

/// Throws InputError naming `database` and how to create it when no store is there.
void require_database(const std::filesystem::path& database);

/// The sweep named `target`, else the job with that id. Throws InputError naming the store when
/// neither exists.
db::JobSelection sweep_or_job(db::JobStore& store, const std::string& target);

/// What `psq <command> SWEEP|JOB` does to the selected jobs; returns the line to print.
using SweepOrJobAction = std::function<std::string(
    db::JobStore& store, const db::JobSelection& jobs, const std::string& target)>;

/// Adds `psq <name> TARGET [--db PATH]`, which runs `action` on the sweep or job named TARGET
/// (sweep_or_job) of an existing store (require_database) and prints its line.
void register_sweep_or_job_command(CLI::App& app, std::vector<Command>& commands,
                                   const std::string& name, const std::string& description,
                                   SweepOrJobAction action);

/// How `psq work` and `psq resume` run jobs.
struct WorkSettings {
  std::string database;
  int workers = 0;  ///< worker processes; 0 = one per core
  double lease_seconds = 30.0;
  int snapshot_iterations = 50;
  double snapshot_seconds = 60.0;
  std::string sweep;      ///< claim only this sweep's jobs (empty: every sweep)
  int worker_number = 0;  ///< > 0 in a worker process started by a supervisor
};

/// Adds the options shared by `psq work` and `psq resume` to `command`.
void add_work_options(CLI::App& command, WorkSettings& settings);

/// Runs queued jobs until none is left (see docs/runner.md); returns the exit code: 0 when
/// every job run finished, 5 when one failed, 128 + signal when stopped by a signal.
int run_work(const WorkSettings& settings);

/// Where a worker reads and writes: its store, the job directories and the hierarchy cache.
/// `psq work` keeps the last two beside the store; a SLURM array task has a store of its own
/// inside the job's directory (docs/slurm.md).
struct WorkerPlacement {
  std::filesystem::path database;
  std::filesystem::path runs;
  std::filesystem::path cache;
};

/// The worker loop of run_work in this process, against `placement`; the same exit codes.
/// install_stop_handlers must have been called.
int work_in_this_process(const WorkSettings& settings, const WorkerPlacement& placement);

/// The first of these signals makes the worker checkpoint the job in progress, release it and
/// return; a second one exits at once.
void install_stop_handlers(std::initializer_list<int> signals);
/// The signal that stopped the worker; 0 if none came.
int stop_signal();

}  // namespace psq::runner
