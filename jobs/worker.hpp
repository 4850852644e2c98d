#pragma once
// One worker: claims jobs from the store one after the other and runs them until the queue
// is empty or a stop is requested.

#include <atomic>
#include <filesystem>

#include "db/job_store.hpp"
#include "jobs/job_executor.hpp"

namespace psq::jobs {

struct WorkerOptions {
  db::WorkerInfo identity;
  double lease_seconds = 30.0;
  /// The jobs to claim from (e.g. one sweep's, for psq resume).
  db::JobSelection selection = db::JobSelection::all();
  ExecutorSettings executor;
};

/// How many jobs a worker ran, by outcome.
struct WorkerSummary {
  int done = 0;
  int previewed = 0;
  int failed = 0;
  int interrupted = 0;
  int lease_lost = 0;
};

/// Claims and runs jobs of the store at `database`, writing into `runs_dir`, until no job is
/// queued or `stop` is set (the job in progress is then checkpointed and released). Throws
/// WorkerEnvironmentError when job files cannot be written, and the store's errors.
WorkerSummary run_worker(const std::filesystem::path& database,
                         const std::filesystem::path& runs_dir, const SolverFactory& factory,
                         const WorkerOptions& options, const ExecutorEvents& events,
                         const std::atomic<bool>& stop);

}  // namespace psq::jobs
