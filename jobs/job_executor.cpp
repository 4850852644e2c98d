#include "jobs/job_executor.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>

#include "engine/core/checksum.hpp"
#include "engine/io/checkpoint.hpp"
#include "engine/io/part_meshes.hpp"
#include "engine/io/xdmf.hpp"
#include "jobs/heartbeat.hpp"
#include "jobs/job_identity.hpp"
#include "jobs/run_directory.hpp"
#include "jobs/scene_overrides.hpp"
#include "jobs/test_hooks.hpp"

namespace psq::jobs {
namespace fs = std::filesystem;

namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

// Unwinding signals, thrown from the Newton progress callback through the solver.
struct StopRequested {};
struct LeaseLost {};

/// The store itself failed (disk full, I/O error, locked beyond the timeout): nothing can be
/// recorded, so the worker stops and the job's lease expires.
class StoreFailure : public InputError {
 public:
  using InputError::InputError;
};

/// Runs a store call; its failures other than a lost lease become StoreFailure.
template <class Call>
auto through_store(const Call& call) {
  try {
    return call();
  } catch (const db::LeaseLostError&) {
    throw;
  } catch (const std::exception& error) {
    throw StoreFailure(error.what());
  }
}

/// A frame that did not converge: the job's answer would be wrong, and rerunning it gives the
/// same frame again, so the job fails for good.
class NotConverged : public NumericalError {
 public:
  using NumericalError::NumericalError;
};

/// The job's scene: its file with its overrides. Throws InputError when the scene file changed
/// since the sweep was added (the job's identity no longer describes it) or is now invalid.
Scene job_scene(const db::Job& job) {
  const std::string expected = job.parameters.value("scene", "");
  const std::string actual = file_content_hash(job.scene);
  if (actual != expected)
    throw InputError(
        fmt::format("{}: the scene file changed since the sweep was added ({} then, "
                    "{} now); add the sweep again to run the edited scene",
                    job.scene, expected, actual));
  Overrides overrides;
  const nlohmann::json stored = job.parameters.value("overrides", nlohmann::json::object());
  for (const auto& [path, value] : stored.items()) overrides[path] = value;
  try {
    return SceneDocument::read(job.scene).apply(overrides);
  } catch (const OverrideError& error) {
    throw InputError(fmt::format("{}: {}", job.scene, error.what()));
  }
}

/// The file checksum of a candidate that read_checkpoint has just verified: the recorded one it
/// was verified against (no second read), else the file's own.
std::uint64_t verified_checksum(const ResumeCandidate& candidate) {
  if (candidate.recorded_checksum) return *candidate.recorded_checksum;
  const std::optional<std::uint64_t> checksum = file_fnv1a64(candidate.file);
  if (!checksum) throw CheckpointError(fmt::format("cannot read '{}'", candidate.file.string()));
  return *checksum;
}

IterationRecord iteration_record(int frame, const NewtonIteration& it) {
  return {.frame = frame,
          .iteration = it.iteration,
          .energy = it.energy,
          .gradient_norm = it.gradient_norm,
          .step_norm = it.step_norm,
          .step_length = it.step_length,
          .seconds = it.times.total()};
}

/// (frame, step norm of its last Newton record) of each frame in `iterations` that `solver`
/// settles: those frames' static residuals.
std::vector<std::pair<int, double>> static_residuals(const std::vector<IterationRecord>& iterations,
                                                     const LevelSolver& solver) {
  std::vector<std::pair<int, double>> residuals;
  for (const IterationRecord& it : iterations) {
    if (!solver.settles_frame(it.frame)) continue;
    if (residuals.empty() || residuals.back().first != it.frame)
      residuals.emplace_back(it.frame, it.step_norm);
    else
      residuals.back().second = it.step_norm;
  }
  return residuals;
}

void add_phase_times(std::map<std::string, double>& timings, const PhaseTimes& times) {
  timings["assembly"] += times.assembly;
  timings["factorization"] += times.factorization;
  timings["solve"] += times.solve;
  timings["line_search"] += times.line_search;
}

/// One run of one claimed job: the state between the executor's steps.
class JobRun {
 public:
  JobRun(db::JobStore& store, const fs::path& database, const fs::path& runs_dir,
         const SolverFactory& factory, const ExecutorSettings& settings,
         const ExecutorEvents& events, const std::atomic<bool>& stop, const db::Claim& claim)
      : store_(store),
        factory_(factory),
        settings_(settings),
        events_(events),
        stop_(stop),
        claim_(claim),
        run_(runs_dir / claim.job.id),
        heartbeat_(database, claim.lease) {}

  RunOutcome run() {
    try {
      run_.create();
    } catch (const InputError& error) {
      throw environment_failure(error.what());
    }
    run_.remove_stale_temporaries();
    try {
      scene_ = job_scene(claim_.job);
      solver_ = factory_(scene_, claim_.job.method, hierarchy_depth(claim_.job));
      record_hierarchy_cache_uses();
      resume();
      while (true) {
        if (!solver_->level_done()) solve_level();  // a resumed level may be done already
        if (solver_->finished()) break;
        if (solver_->level() + 1 >= claim_.job.levels_to_run()) return finish_preview();
        refine();
        start_level();
      }
      test_point("before_finish");
      through_store([&] { store_.finish(claim_.lease, db::Outcome::done); });
      log(fmt::format("done in {:.1f} s", seconds_since(run_start_)));
      return RunOutcome::done;
    } catch (const StopRequested&) {
      through_store([&] { return store_.release(claim_.lease); });
      log("stopped on request: checkpoint written, job released");
      return RunOutcome::interrupted;
    } catch (const LeaseLost&) {
      log("lease lost (cancelled, or reclaimed by another worker): stopped");
      return RunOutcome::lease_lost;
    } catch (const db::LeaseLostError&) {
      log("lease lost (cancelled, or reclaimed by another worker): stopped");
      return RunOutcome::lease_lost;
    } catch (const WorkerEnvironmentError&) {
      throw;
    } catch (const StoreFailure&) {
      throw;
    } catch (const CheckpointError& error) {
      throw environment_failure(error.what());
    } catch (const NumericalError& error) {
      return fail(db::Outcome::failed_permanently,
                  fmt::format("numerical failure: {}", error.what()));
    } catch (const InputError& error) {
      return fail(db::Outcome::failed_permanently, error.what());
    } catch (const std::exception& error) {
      return fail(db::Outcome::failed, fmt::format("internal error: {}", error.what()));
    }
  }

 private:
  // ---- resuming ------------------------------------------------------------------------------

  /// Continues from the most advanced checkpoint that verifies, or starts the job afresh.
  void resume() {
    const std::vector<db::JobResult> results =
        through_store([&] { return store_.results(db::JobSelection::job(claim_.job.id)); });
    const std::vector<db::LevelRecord> records =
        results.empty() ? std::vector<db::LevelRecord>{} : results.front().levels;
    for (const ResumeCandidate& candidate : resume_candidates(run_, claim_.job.depth, records)) {
      try {
        Checkpoint checkpoint = read_checkpoint(candidate.file, candidate.recorded_checksum);
        if (checkpoint.parameters != claim_.job.parameters.dump())
          throw CheckpointError(
              fmt::format("{}: written for other parameters", candidate.file.string()));
        const bool in_frame = checkpoint.solver.progress == LevelProgress::inside_frame;
        solver_->restore(checkpoint.level, checkpoint.frame, flat(checkpoint.positions),
                         flat(checkpoint.solver.previous_positions),
                         in_frame ? checkpoint.solver.iterations_in_frame : 0,
                         checkpoint.solver.scalars);
        if (in_frame) resumed_in_frame_ = {checkpoint.frame, checkpoint.solver.iterations_in_frame};
        continue_from(candidate, std::move(checkpoint));
        return;
      } catch (const std::invalid_argument& error) {
        log(fmt::format("{}: does not fit the job ({}); trying an earlier checkpoint",
                        candidate.file.filename().string(), error.what()));
      } catch (const CheckpointError& error) {
        log(fmt::format("{}; trying an earlier checkpoint", error.what()));
      }
    }
    start_level();
  }

  void continue_from(const ResumeCandidate& candidate, Checkpoint checkpoint) {
    log(fmt::format("resuming level {} frame {} from {}", checkpoint.level, checkpoint.frame,
                    candidate.file.filename().string()));
    for (int level = 0; level < checkpoint.level; ++level) add_stored_sidecar_entry(level);
    statistics_ = std::move(checkpoint.statistics);
    if (const auto energy = checkpoint.solver.scalars.find(kElasticEnergyScalar);
        energy != checkpoint.solver.scalars.end())
      frame_energy_ = energy->second;
    level_start_ = Clock::now();
    since_checkpoint_ = Clock::now();
    if (checkpoint.solver.progress == LevelProgress::level_done)
      record_finished_level(candidate.file, verified_checksum(candidate));
  }

  /// Refines to the next level, logging each phase. Nothing is written until the new level's
  /// first checkpoint, so a worker killed here resumes from the level being refined.
  void refine() {
    const int next = solver_->level() + 1;
    solver_->refine([&](const std::string& phase) {
      log(fmt::format("refining to level {}: {}", next, phase));
      test_point("refinement_phase");
      if (heartbeat_.lost()) throw LeaseLost{};
      // The finished level's checkpoint is the place to resume from: nothing to write.
      if (stop_.load()) throw StopRequested{};
    });
  }

  void start_level() {
    statistics_ = {};
    statistics_.refinement = solver_->refinement_statistics();
    frame_energy_.reset();
    level_start_ = Clock::now();
    since_checkpoint_ = Clock::now();
    iterations_since_checkpoint_ = 0;
    if (solver_->level_count() > 1)
      log(fmt::format("level {}/{}: {} vertices", solver_->level(), solver_->level_count(),
                      solver_->level_rest_mesh().vertex_count()));
  }

  /// What the hierarchy cache did for this attempt's solver, for the reports' hits and saved
  /// time.
  void record_hierarchy_cache_uses() {
    const std::vector<db::HierarchyCacheUse> uses = solver_->hierarchy_cache_uses();
    if (!uses.empty())
      through_store([&] { store_.record_hierarchy_uses(claim_.lease, uses); });
  }

  // ---- solving -------------------------------------------------------------------------------

  void solve_level() {
    while (!solver_->level_done()) {
      // A stop before the first step after an in-frame resume snapshots that frame again.
      if (resumed_in_frame_)
        stop_if_asked(LevelProgress::inside_frame, resumed_in_frame_->first,
                      resumed_in_frame_->second);
      else
        stop_if_asked(LevelProgress::frame_done, solver_->frame(), 0);
      const LevelFrame frame =
          solver_->step([this](int frame, const NewtonIteration& it) { on_iteration(frame, it); });
      resumed_in_frame_.reset();
      frame_energy_ = frame.elastic_energy;
      add_unrecorded(frame.readings);
      if (frame.must_converge && frame.stagnated)
        throw NotConverged(fmt::format(
            "level {} frame {} stagnated at round-off at ‖Δx‖∞/Δt = {:.3e}: solver.tolerance is "
            "finer than double precision resolves for this scene; raise it above that",
            frame.level, frame.frame, frame.step_norm));
      if (frame.must_converge && !frame.converged && !frame.failure.empty())
        throw NotConverged(frame.failure);
      if (frame.must_converge && !frame.converged)
        throw NotConverged(fmt::format(
            "level {} frame {} did not converge within solver.max_iterations = {} (‖Δx‖∞/Δt = "
            "{:.3e} at the end){}",
            frame.level, frame.frame, scene_.solver.max_iterations, frame.step_norm,
            scene_.solver.project_on_demand
                ? ""
                : "; raise it, or try [solver] hessian = \"project_on_demand\" (docs/"
                  "scene-format.md), whose steps converge faster where the projected Hessian "
                  "overstates the curvature"));
      if (!solver_->level_done() && snapshot_due())
        snapshot(LevelProgress::frame_done, solver_->frame(), 0);
    }
    const fs::path file = run_.level_checkpoint(solver_->level());
    const std::uint64_t checksum =
        write(file, make_checkpoint(LevelProgress::level_done, solver_->frame(), 0));
    test_point("level_written");
    record_finished_level(file, checksum);
  }

  /// A frame's readings, to go with the level's next record; a settling step of the frame last
  /// added replaces its readings (the frame's answer is its last step's).
  void add_unrecorded(const db::FrameReadings& readings) {
    if (!unrecorded_frames_.empty() && unrecorded_frames_.back().frame == readings.frame)
      unrecorded_frames_.back() = readings;
    else
      unrecorded_frames_.push_back(readings);
  }

  void on_iteration(int frame, const NewtonIteration& it) {
    statistics_.iterations.push_back(iteration_record(frame, it));
    add_phase_times(statistics_.timings, it.times);
    report_progress(frame, it);
    test_point("iteration");
    if (heartbeat_.lost()) throw LeaseLost{};
    if (it.step_length <= 0.0) return;  // no step taken: the frame ends with this record
    ++iterations_since_checkpoint_;
    stop_if_asked(LevelProgress::inside_frame, frame, it.iteration + 1);
    if (snapshot_due()) snapshot(LevelProgress::inside_frame, frame, it.iteration + 1);
  }

  void stop_if_asked(LevelProgress progress, int frame, int iterations_in_frame) {
    if (heartbeat_.lost()) throw LeaseLost{};
    if (!stop_.load()) return;
    snapshot(progress, frame, iterations_in_frame);
    throw StopRequested{};
  }

  bool snapshot_due() const {
    return iterations_since_checkpoint_ >= settings_.snapshot_iterations ||
           seconds_since(since_checkpoint_) >= settings_.snapshot_seconds;
  }

  void report_progress(int frame, const NewtonIteration& it) {
    if (!events_.progress) return;
    JobProgress progress;
    progress.job_id = claim_.job.id;
    progress.level = solver_->level();
    progress.level_count = solver_->level_count();
    progress.frame = frame;
    progress.frame_count = solver_->frame_count();
    progress.iteration = it.iteration;
    progress.step_norm = it.step_norm;
    progress.gradient_norm = it.gradient_norm;
    const int solved = solver_->frame();
    if (solved > 0) {
      const double per_frame = level_seconds() / solved;
      progress.eta_seconds = per_frame * (solver_->frame_count() - solved);
    }
    events_.progress(progress);
  }

  /// Wall time of the current level over all attempts so far.
  double level_seconds() const {
    const auto recorded = statistics_.timings.find("wall");
    return (recorded == statistics_.timings.end() ? 0.0 : recorded->second) +
           seconds_since(level_start_);
  }

  // ---- checkpoints and records ---------------------------------------------------------------

  /// Writes level l's in-level snapshot, keeping the one before it, and records it.
  void snapshot(LevelProgress progress, int frame, int iterations_in_frame) {
    const int level = solver_->level();
    const fs::path file = run_.snapshot(level);
    const fs::path previous = run_.previous_snapshot(level);
    std::error_code error;
    bool kept = false;
    if (fs::exists(file)) {
      fs::rename(file, previous, error);
      kept = !error;
    }
    std::uint64_t checksum = 0;
    try {
      checksum = write(file, make_checkpoint(progress, frame, iterations_in_frame));
    } catch (...) {
      // The latest snapshot goes back under the name the store's record of the level gives it,
      // so that a resume verifies it against the recorded checksum.
      if (kept) fs::rename(previous, file, error);
      throw;
    }
    test_point("snapshot_written");
    record(db::LevelStatus::running, file, checksum);
    test_point("snapshot_recorded");
  }

  void record_finished_level(const fs::path& file, std::uint64_t checksum) {
    const int level = solver_->level();
    record(db::LevelStatus::done, file, checksum);
    test_point("level_recorded");
    run_.remove_snapshots(level);
    try {
      const fs::path parts_file = run_.part_meshes(level);
      const PartMeshes parts = level_parts();
      write_part_meshes(parts_file, parts);
      add_sidecar_entry(xdmf_entry(parts_file.filename().string(), parts));
      write_xdmf(run_.sidecar(), sidecar_entries_);
    } catch (const InputError& error) {
      throw environment_failure(error.what());
    }
    log(fmt::format("level {} done: {} iterations, {:.1f} s", level, steps_taken(),
                    statistics_.timings["wall"]));
  }

  Checkpoint make_checkpoint(LevelProgress progress, int frame, int iterations_in_frame) {
    statistics_.timings["wall"] = level_seconds();
    level_start_ = Clock::now();
    const TriMesh& rest = solver_->level_rest_mesh();
    Checkpoint c;
    c.code_version = settings_.code_version;
    c.parameters = claim_.job.parameters.dump();
    c.level = solver_->level();
    c.frame = frame;
    c.time = frame * scene_.time.step;
    c.positions = as_positions(solver_->positions());
    c.rest_positions = rest.vertices;
    c.triangles = rest.triangles;
    c.finest_positions = solver_->finest_positions();
    c.solver.progress = progress;
    c.solver.previous_positions = as_positions(solver_->previous());
    c.solver.iterations_in_frame = iterations_in_frame;
    c.solver.scalars = solver_->state();
    if (frame_energy_) c.solver.scalars[kElasticEnergyScalar] = *frame_energy_;
    c.statistics = statistics_;
    return c;
  }

  /// Writes a checkpoint, timed; a failure to write is the environment's, not the job's, while
  /// a checkpoint refused as inconsistent (a non-finite state, say) is the job's failure.
  std::uint64_t write(const fs::path& file, const Checkpoint& c) {
    const Clock::time_point start = Clock::now();
    try {
      test_point("checkpoint_write");
      const std::uint64_t checksum = write_checkpoint(file, c);
      statistics_.timings["checkpoint"] += seconds_since(start);
      since_checkpoint_ = Clock::now();
      iterations_since_checkpoint_ = 0;
      return checksum;
    } catch (const CheckpointWriteError& error) {
      throw environment_failure(error.what());
    }
  }

  void record(db::LevelStatus status, const fs::path& file, std::uint64_t checksum,
              const std::string& error = {}) {
    const Clock::time_point start = Clock::now();
    db::LevelRecord level;
    level.level = solver_ ? solver_->level() : 0;
    level.status = status;
    level.iterations = steps_taken();
    for (const IterationRecord& it : statistics_.iterations)
      level.residuals.push_back(it.gradient_norm);
    level.timings = statistics_.timings;
    level.refinement = statistics_.refinement;
    if (status == db::LevelStatus::done) level.outputs = level_outputs();
    if (solver_) level.static_residuals = static_residuals(statistics_.iterations, *solver_);
    if (!file.empty()) {
      level.checkpoint_path = fs::absolute(file).lexically_normal().string();
      level.checkpoint_checksum = checksum_text(checksum);
    }
    level.error = error;
    level.frames = unrecorded_frames_;
    test_point("record_level");
    through_store([&] { store_.record_level(claim_.lease, level); });
    unrecorded_frames_.clear();
    statistics_.timings["database"] += seconds_since(start);
  }

  /// What the finished level computed (db::kLevelOutputs), by which coarse-first rules select.
  /// The job's last level is its answer, measured on the finest mesh like every method's (a
  /// coarse-prolonged job's one level after prolongation); a preview level on its own mesh.
  std::map<std::string, double> level_outputs() const {
    const bool answer = solver_->level() + 1 == solver_->level_count();
    const Positions& rest =
        answer ? solver_->finest_rest_positions() : solver_->level_rest_mesh().vertices;
    const Positions positions =
        answer ? solver_->finest_positions() : as_positions(solver_->positions());
    std::map<std::string, double> outputs{
        {"max_displacement", (positions - rest).rowwise().norm().maxCoeff()},
        {"iterations", static_cast<double>(steps_taken())},
        {"seconds", statistics_.timings.count("wall") ? statistics_.timings.at("wall") : 0.0}};
    if (frame_energy_) outputs["elastic_energy"] = *frame_energy_;
    if (!statistics_.iterations.empty())
      outputs["residual"] = statistics_.iterations.back().gradient_norm;
    return outputs;
  }

  std::int64_t steps_taken() const {
    return std::count_if(statistics_.iterations.begin(), statistics_.iterations.end(),
                         [](const IterationRecord& it) { return it.step_length > 0.0; });
  }

  /// The finished level's state, cut into its shells and colliders, for the sidecars.
  PartMeshes level_parts() const {
    const int frame = solver_->frame();
    return {.level = solver_->level(),
            .frame = frame,
            .time = frame * scene_.time.step,
            .parts = split_into_parts(as_positions(solver_->positions()),
                                      solver_->level_rest_mesh(), solver_->level_parts())};
  }

  void add_sidecar_entry(XdmfEntry entry) {
    if (std::none_of(sidecar_entries_.begin(), sidecar_entries_.end(),
                     [&](const XdmfEntry& e) { return e.level == entry.level; }))
      sidecar_entries_.push_back(std::move(entry));
  }

  /// A level finished by an earlier attempt, listed from its part-meshes file.
  void add_stored_sidecar_entry(int level) {
    const fs::path file = run_.part_meshes(level);
    try {
      add_sidecar_entry(xdmf_entry(file.filename().string(), read_part_meshes(file)));
    } catch (const InputError& error) {
      log(fmt::format("the sidecar leaves out level {}: {}", level, error.what()));
    }
  }

  // ---- endings -------------------------------------------------------------------------------

  /// A coarse-first job has run its preview levels: it stops there until promoted, and then
  /// resumes from the last preview level's checkpoint and refines as if it had not stopped.
  RunOutcome finish_preview() {
    test_point("before_finish");
    through_store([&] { store_.finish(claim_.lease, db::Outcome::previewed); });
    log(fmt::format("previewed (levels 0–{}) in {:.1f} s; the finer levels wait for promotion",
                    solver_->level(), seconds_since(run_start_)));
    return RunOutcome::previewed;
  }

  RunOutcome fail(db::Outcome outcome, const std::string& message) {
    try {
      record(db::LevelStatus::failed, {}, 0, message);
      through_store([&] { store_.finish(claim_.lease, outcome, message); });
    } catch (const db::LeaseLostError&) {
      return RunOutcome::lease_lost;
    }
    log(fmt::format("failed: {}", message));
    return RunOutcome::failed;
  }

  /// The job's files cannot be written (disk full, read-only, no permission): not the job's
  /// fault, and every other job would fail alike. The attempt is released with the reason (no
  /// failure counted), and the worker is told to stop.
  WorkerEnvironmentError environment_failure(const std::string& what) {
    const std::string reason = fmt::format(
        "attempt {} stopped: {}; the job was released without counting a failure: free disk "
        "space or make the directory writable, then run psq work, and the job continues from "
        "its last checkpoint",
        claim_.lease.attempt, what);
    try {
      store_.release(claim_.lease, reason);
    } catch (const std::exception&) {
      // The store may share the failing disk; the lease then expires instead.
    }
    return WorkerEnvironmentError(fmt::format("job {}: {}", claim_.job.id, reason));
  }

  void log(const std::string& line) const {
    if (events_.log) events_.log(fmt::format("job {}: {}", claim_.job.id, line));
  }

  db::JobStore& store_;
  const SolverFactory& factory_;
  const ExecutorSettings& settings_;
  const ExecutorEvents& events_;
  const std::atomic<bool>& stop_;
  const db::Claim& claim_;
  RunDirectory run_;
  Heartbeat heartbeat_;
  Scene scene_;
  std::unique_ptr<LevelSolver> solver_;
  LevelStatistics statistics_;  ///< of the current level, over all attempts so far
  std::vector<XdmfEntry> sidecar_entries_;
  Clock::time_point run_start_ = Clock::now();
  Clock::time_point level_start_ = Clock::now();  ///< start of the wall time not yet counted
  Clock::time_point since_checkpoint_ = Clock::now();
  int iterations_since_checkpoint_ = 0;
  /// (frame, iterations done) of a frame restored in progress, until its next step.
  std::optional<std::pair<int, int>> resumed_in_frame_;
  /// The readings of the current level's frames solved since its last record.
  std::vector<db::FrameReadings> unrecorded_frames_;
  /// Elastic energy of the last solved frame of this level (the reports' energy output).
  std::optional<double> frame_energy_;
};

}  // namespace

JobExecutor::JobExecutor(db::JobStore& store, fs::path database, fs::path runs_dir,
                         SolverFactory factory, ExecutorSettings settings, ExecutorEvents events,
                         const std::atomic<bool>& stop)
    : store_(store),
      database_(std::move(database)),
      runs_dir_(std::move(runs_dir)),
      factory_(std::move(factory)),
      settings_(std::move(settings)),
      events_(std::move(events)),
      stop_(stop) {}

RunOutcome JobExecutor::run(const db::Claim& claim) {
  return JobRun(store_, database_, runs_dir_, factory_, settings_, events_, stop_, claim).run();
}

}  // namespace psq::jobs
