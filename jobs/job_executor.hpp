#pragma once
// Runs one claimed job level by level: builds its scene, continues from its last valid
// checkpoint, checkpoints every finished level (and, periodically, the level in progress),
// records every checkpoint in the store, keeps the lease alive, and stops cleanly when asked.
// docs/runner.md describes the files, the resume rules and the outcomes.

#include <atomic>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <string>

#include "db/job_store.hpp"
#include "engine/scene/scene.hpp"
#include "jobs/level_solver.hpp"

namespace psq::jobs {

/// Builds the solver of a job: its scene, its method and its hierarchy depth (hierarchy_depth).
using SolverFactory =
    std::function<std::unique_ptr<LevelSolver>(const Scene&, db::Method, int depth)>;

struct ExecutorSettings {
  /// An in-level snapshot is written after this many Newton iterations since the last one...
  int snapshot_iterations = 50;
  /// ...or once this many seconds have passed since the last checkpoint, whichever comes first.
  double snapshot_seconds = 60.0;
  /// Recorded in every checkpoint.
  std::string code_version;
};

/// Where a running job is, after each Newton iteration.
struct JobProgress {
  std::string job_id;
  int level = 0;
  int level_count = 1;
  int frame = 0;  ///< the frame being solved
  int frame_count = 0;
  int iteration = 0;
  double step_norm = 0.0;             ///< ‖d‖∞ / Δt, the convergence measure
  double gradient_norm = 0.0;         ///< ‖∇E‖, the residual
  std::optional<double> eta_seconds;  ///< of the job, once a frame has been solved
};

/// What the executor tells its caller besides the result.
struct ExecutorEvents {
  std::function<void(const JobProgress&)> progress;  ///< after every Newton iteration
  std::function<void(const std::string&)> log;       ///< one line: levels, resumes, outcomes
};

/// How a run of a job ended.
enum class RunOutcome {
  done,         ///< every level recorded, the job finished
  previewed,    ///< its preview levels recorded; it waits for promotion (a coarse-first sweep)
  failed,       ///< the job is marked failed (retried later if attempts remain and useful)
  interrupted,  ///< a stop was requested: snapshot written, claim released
  lease_lost,   ///< cancelled or reclaimed meanwhile: stopped without writing anything more
};

/// The worker's environment failed (e.g. a checkpoint could not be written: disk full, no
/// permission): not the job's fault, so the job was released, and the worker should stop.
class WorkerEnvironmentError : public InputError {
 public:
  using InputError::InputError;
};

class JobExecutor {
 public:
  /// `store` is the worker's connection; `database` its path (the heartbeat thread opens its
  /// own); each job writes into `runs_dir / <job id>`. `stop` is polled after every Newton
  /// iteration and between frames.
  JobExecutor(db::JobStore& store, std::filesystem::path database, std::filesystem::path runs_dir,
              SolverFactory factory, ExecutorSettings settings, ExecutorEvents events,
              const std::atomic<bool>& stop);

  /// Runs the claimed job to one of the outcomes. Throws WorkerEnvironmentError (after
  /// releasing the job) when its files cannot be written, and the store's errors when the
  /// store itself fails (the lease then expires and the job is reclaimed).
  RunOutcome run(const db::Claim& claim);

 private:
  db::JobStore& store_;
  std::filesystem::path database_;
  std::filesystem::path runs_dir_;
  SolverFactory factory_;
  ExecutorSettings settings_;
  ExecutorEvents events_;
  const std::atomic<bool>& stop_;
};

}  // namespace psq::jobs
