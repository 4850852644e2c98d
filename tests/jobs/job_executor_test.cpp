// The job executor against a scripted LevelSolver: levels recorded with their checkpoints,
// stop and resume (from the latest snapshot, a damaged one, or nothing), failures, lost leases
// and unwritable outputs. The real solver and real kills are tested in tests/runner.

#include "jobs/job_executor.hpp"

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <fstream>
#include <map>
#include <thread>

#include "db/job_store.hpp"
#include "engine/core/checksum.hpp"
#include "engine/io/checkpoint.hpp"
#include "engine/io/part_meshes.hpp"
#include "engine/scene/shell_mesh.hpp"
#include "jobs/run_directory.hpp"
#include "jobs/sweep_file.hpp"
#include "support/test_paths.hpp"

namespace psq {
namespace {

namespace fs = std::filesystem;

/// A solver whose every frame takes a fixed number of "Newton" iterations, each a contraction
/// x ← x/2 + (frame + level + drift)·1; its results depend on every iteration taken exactly
/// once. The drift grows by 1/4 per frame solved and is known only through state(), so a resume
/// that does not hand the stored state back ends elsewhere.
class ScriptedSolver final : public jobs::LevelSolver {
 public:
  ScriptedSolver(int levels, int frames, int iterations)
      : levels_(levels), frames_(frames), iterations_(iterations) {
    rest_.vertices = Positions{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
    rest_.triangles = Triangles{{0, 1, 2}};
    x_ = flat(rest_.vertices);
    previous_ = x_;
    finest_rest = rest_.vertices;
  }

  int level_count() const override { return levels_; }
  int level() const override { return level_; }
  int frame() const override { return frame_; }
  int frame_count() const override { return frames_; }
  bool level_done() const override { return frame_ == frames_; }
  bool finished() const override { return level_done() && level_ == levels_ - 1; }

  jobs::LevelFrame step(const Progress& progress) override {
    const int frame = frame_ + 1;
    const int first = std::exchange(resumed_iterations_, 0);
    if (first == 0) previous_ = x_;
    for (int k = first; k < iterations_; ++k) {
      x_ = 0.5 * x_ + Eigen::VectorXd::Constant(x_.size(), frame + level_ + drift_);
      NewtonIteration it;
      it.iteration = k;
      it.step_length = 1.0;
      it.gradient_norm = x_.norm();
      progress(frame, it);
    }
    NewtonIteration check;
    check.iteration = iterations_;
    check.step_norm = 1e-3 * frame;  // the frame's final residual, known from its number
    progress(frame, check);
    frame_ = frame;
    drift_ += 0.25;
    jobs::LevelFrame record;
    record.level = level_;
    record.frame = frame;
    record.converged = !(level_ == fail_at_level && frame == fail_at_frame);
    if (!record.converged) record.failure = failure;
    record.must_converge = level_ + 1 == levels_;  // coarser levels are previews
    record.iterations = iterations_;
    record.elastic_energy = x_.squaredNorm();  // any function of the result will do
    // A load ramped by a quarter per frame, and vertex 0's position as a probe.
    record.readings = {frame, 0.25 * frame, {{"p", "displacement", {x_[0], x_[1], x_[2]}}}};
    return record;
  }
  void refine(const RefinementPhase&) override {
    ++level_;
    frame_ = 0;
  }
  const Eigen::VectorXd& positions() const override { return x_; }
  const Eigen::VectorXd& previous() const override { return previous_; }
  const TriMesh& level_rest_mesh() const override { return rest_; }
  std::vector<PartRange> level_parts() const override {
    return {{"triangle", PartKind::shell, 0, 3, 0, 1}};
  }
  Positions finest_positions() const override { return as_positions(prolongation * x_); }
  const Positions& finest_rest_positions() const override { return finest_rest; }
  /// The last frame of each level settles, as a progressive solve's refine frame does.
  bool settles_frame(int frame) const override { return frame == frames_; }
  std::map<std::string, double> state() const override { return {{"drift", drift_}}; }
  void restore(int level, int frame, const Eigen::VectorXd& positions,
               const Eigen::VectorXd& previous, int iterations_in_frame,
               const std::map<std::string, double>& state) override {
    const auto drift = state.find("drift");
    drift_ = drift == state.end() ? 0.0 : drift->second;
    level_ = level;
    x_ = positions;
    previous_ = previous;
    frame_ = iterations_in_frame > 0 ? frame - 1 : frame;
    resumed_iterations_ = iterations_in_frame;
  }

  int fail_at_level = -1, fail_at_frame = -1;  ///< the frame that does not converge
  std::string failure;                          ///< the reason it gives, if any
  /// The "finest mesh" of a coarse-prolonged solve: positions scaled, a rest shape of its own.
  double prolongation = 1.0;
  Positions finest_rest;

 private:
  int levels_, frames_, iterations_;
  int level_ = 0, frame_ = 0, resumed_iterations_ = 0;
  double drift_ = 0.0;
  TriMesh rest_;
  Eigen::VectorXd x_, previous_;
};

/// max_i ‖a_i − b_i‖, computed here rather than by the executor's own code.
double largest_displacement(const Positions& a, const Positions& b) {
  double largest = 0.0;
  for (Eigen::Index i = 0; i < a.rows(); ++i) largest = std::max(largest, (a.row(i) - b.row(i)).norm());
  return largest;
}

constexpr int kFrames = 4;
constexpr int kIterations = 5;

/// A store with one job of depth 2 on the cantilever scene, and its runs directory.
class Workspace {
 public:
  Workspace() : dir_(test::fresh_temp_dir("job_executor")) {
    fs::copy_file(test::source_dir() / "jobs/scenes/cantilever.toml", dir_ / "scene.toml");
    test::write_file(dir_ / "sweep.toml", "name = \"s\"\nscene = \"scene.toml\"\ndepth = 2\n");
    const jobs::Sweep sweep = jobs::read_sweep(dir_ / "sweep.toml");
    db::JobStore(dir_ / "psq.db").add_sweep("s", "sweep.toml", jobs::new_jobs(sweep));
    job_id_ = sweep.jobs.front().id;
  }

  /// Claims the job and runs it; `on_iteration` sees every iteration (its number overall).
  jobs::RunOutcome run(const std::function<void(int)>& on_iteration = {},
                       const fs::path& runs = {}) {
    db::JobStore store(dir_ / "psq.db");
    const auto claim = store.claim_next({"w", "host", "test"}, lease_seconds);
    EXPECT_TRUE(claim);
    if (!claim) return jobs::RunOutcome::failed;
    jobs::ExecutorEvents events;
    events.log = [this](const std::string& line) { log += line + "\n"; };
    events.progress = [&](const jobs::JobProgress&) {
      if (on_iteration) on_iteration(++iterations_seen_);
    };
    jobs::JobExecutor executor(
        store, dir_ / "psq.db", runs.empty() ? dir_ / "runs" : runs,
        [this](const Scene&, db::Method, int depth) {
          auto solver = std::make_unique<ScriptedSolver>(depth, kFrames, kIterations);
          solver->fail_at_level = fail_at_level;
          solver->fail_at_frame = fail_at_frame;
          solver->failure = failure;
          if (finest_rest_shift != 0.0) {
            solver->prolongation = 3.0;
            solver->finest_rest.array() += finest_rest_shift;
          }
          return solver;
        },
        {.snapshot_iterations = 2, .snapshot_seconds = 1e9, .code_version = "test"}, events, stop);
    return executor.run(*claim);
  }

  db::JobResult result() const {
    return db::JobStore(dir_ / "psq.db").results(db::JobSelection::job(job_id_)).front();
  }
  jobs::RunDirectory run_dir() const { return jobs::RunDirectory(dir_ / "runs" / job_id_); }
  Checkpoint final_checkpoint() const { return read_checkpoint(run_dir().level_checkpoint(1)); }
  const fs::path& dir() const { return dir_; }
  const std::string& job_id() const { return job_id_; }

  std::atomic<bool> stop{false};
  std::string log;
  int fail_at_level = -1, fail_at_frame = -1;
  std::string failure;
  double lease_seconds = 30.0;
  /// Not 0: the solver's finest positions are 3 x and its finest rest shape is shifted by this.
  double finest_rest_shift = 0.0;

 private:
  fs::path dir_;
  std::string job_id_;
  int iterations_seen_ = 0;
};

/// The final state and iteration history of an uninterrupted run of the job.
const Checkpoint& reference() {
  static const Checkpoint checkpoint = [] {
    Workspace fresh;
    EXPECT_EQ(fresh.run(), jobs::RunOutcome::done);
    return fresh.final_checkpoint();
  }();
  return checkpoint;
}

/// The frames an uninterrupted run of the job records.
const std::vector<db::LevelRecord>& reference_levels() {
  static const std::vector<db::LevelRecord> levels = [] {
    Workspace fresh;
    EXPECT_EQ(fresh.run(), jobs::RunOutcome::done);
    return fresh.result().levels;
  }();
  return levels;
}

/// Every level of `r` has every frame once, each as the uninterrupted run recorded it.
void expect_frames_as_reference(const db::JobResult& r) {
  ASSERT_EQ(r.levels.size(), reference_levels().size());
  for (std::size_t l = 0; l < r.levels.size(); ++l) {
    ASSERT_EQ(r.levels[l].frames.size(), static_cast<std::size_t>(kFrames)) << "level " << l;
    EXPECT_EQ(r.levels[l].frames, reference_levels()[l].frames) << "level " << l;
  }
}

void expect_same_as_reference(const Checkpoint& c) {
  EXPECT_EQ(c.positions, reference().positions);
  EXPECT_EQ(c.solver.scalars, reference().solver.scalars);
  ASSERT_EQ(c.statistics.iterations.size(), reference().statistics.iterations.size());
  for (std::size_t k = 0; k < c.statistics.iterations.size(); ++k) {
    EXPECT_EQ(c.statistics.iterations[k].frame, reference().statistics.iterations[k].frame);
    EXPECT_EQ(c.statistics.iterations[k].iteration, reference().statistics.iterations[k].iteration);
    EXPECT_EQ(c.statistics.iterations[k].gradient_norm,
              reference().statistics.iterations[k].gradient_norm);
  }
}

class Executor : public ::testing::Test, public Workspace {};

TEST_F(Executor, RunsEveryLevelAndRecordsItsCheckpoint) {
  ASSERT_EQ(run(), jobs::RunOutcome::done);
  const db::JobResult r = result();
  EXPECT_EQ(r.job.state, db::JobState::done);
  ASSERT_EQ(r.levels.size(), 2u);
  for (const db::LevelRecord& level : r.levels) {
    EXPECT_EQ(level.status, db::LevelStatus::done);
    EXPECT_EQ(level.iterations, kFrames * kIterations);
    EXPECT_EQ(level.residuals.size(), std::size_t(kFrames * (kIterations + 1)));
    // Only the settled last frame has a static residual: its final record's step norm.
    ASSERT_EQ(level.static_residuals.size(), 1u);
    EXPECT_EQ(level.static_residuals[0].first, kFrames);
    EXPECT_EQ(level.static_residuals[0].second, 1e-3 * kFrames);
    const fs::path file = run_dir().level_checkpoint(level.level);
    EXPECT_EQ(fs::path(level.checkpoint_path), fs::absolute(file));
    // The recorded checksum is the file's: read_checkpoint verifies it.
    const auto checksum = parse_checksum(level.checkpoint_checksum);
    ASSERT_TRUE(checksum);
    EXPECT_EQ(read_checkpoint(file, *checksum).level, level.level);
    EXPECT_GT(level.timings.at("checkpoint"), 0.0);
    EXPECT_GT(level.timings.at("database"), 0.0);
    EXPECT_FALSE(fs::exists(run_dir().snapshot(level.level)));
    EXPECT_FALSE(fs::exists(run_dir().previous_snapshot(level.level)));
  }
  // Every iteration of every frame of both levels applied once, in order: x ← x/2 + frame +
  // level + drift, from the rest position 0 of vertex 0.
  double expected = 0.0;
  double drift = 0.0;
  for (int level = 0; level < 2; ++level)
    for (int frame = 1; frame <= kFrames; ++frame, drift += 0.25)
      for (int k = 0; k < kIterations; ++k) expected = 0.5 * expected + frame + level + drift;
  const Checkpoint c = final_checkpoint();
  EXPECT_EQ(c.positions(0, 0), expected);
  // The level's checkpoint holds its last frame's energy for the reports.
  EXPECT_EQ(c.solver.scalars.at(kElasticEnergyScalar), flat(c.positions).squaredNorm());
  std::ifstream sidecar(run_dir().sidecar());
  const std::string xml{std::istreambuf_iterator<char>(sidecar), {}};
  EXPECT_NE(xml.find("level_0.parts.h5:/parts/0/positions"), std::string::npos);
  EXPECT_NE(xml.find("level_1.parts.h5:/parts/0/positions"), std::string::npos);
  EXPECT_NE(xml.find(R"(<Grid Name="triangle" GridType="Uniform">)"), std::string::npos);
  // The level's part is where the level ended.
  const PartMeshes parts = read_part_meshes(run_dir().part_meshes(1));
  ASSERT_EQ(parts.parts.size(), 1u);
  EXPECT_EQ(parts.parts[0].positions, c.positions);
  // Each frame's readings, in order, across the level's snapshots and its final record; the last
  // frame's probe is where the level ended.
  for (const db::LevelRecord& level : r.levels) {
    ASSERT_EQ(level.frames.size(), static_cast<std::size_t>(kFrames));
    for (int k = 0; k < kFrames; ++k) {
      EXPECT_EQ(level.frames[k].frame, k + 1);
      EXPECT_EQ(level.frames[k].load_scale, 0.25 * (k + 1));
    }
  }
  EXPECT_EQ(r.levels[1].frames.back().probes.at(0).value[0], c.positions(0, 0));
}

TEST_F(Executor, TheAnswersDisplacementIsMeasuredOnTheFinestMeshAndAPreviewsOnItsOwn) {
  // As for a coarse-prolonged job: the last level's state lives on a mesh of its own, its
  // answer is its prolongation.
  finest_rest_shift = 0.5;
  ASSERT_EQ(run(), jobs::RunOutcome::done);
  const db::JobResult r = result();
  ASSERT_EQ(r.levels.size(), 2u);
  const Checkpoint preview = read_checkpoint(run_dir().level_checkpoint(0));
  const Checkpoint answer = final_checkpoint();
  const Positions finest_rest = answer.rest_positions.array() + 0.5;
  const double on_finest = largest_displacement(answer.finest_positions, finest_rest);
  const double on_own = largest_displacement(answer.positions, answer.rest_positions);
  EXPECT_GT(std::abs(on_finest - on_own), 1e-3 * on_finest);  // the two measures differ here
  EXPECT_DOUBLE_EQ(r.levels[1].outputs.at("max_displacement"), on_finest);
  EXPECT_DOUBLE_EQ(r.levels[0].outputs.at("max_displacement"),
                   largest_displacement(preview.positions, preview.rest_positions));
}

TEST_F(Executor, StopWritesASnapshotReleasesAndResumesToTheSameResult) {
  // 27 progress events in (6 per frame: 5 steps and the converged check): level 1, frame 1,
  // after its third step.
  const auto stop_after = [this](int n) {
    if (n == 27) stop = true;
  };
  ASSERT_EQ(run(stop_after), jobs::RunOutcome::interrupted);
  db::JobResult r = result();
  EXPECT_EQ(r.job.state, db::JobState::queued);
  EXPECT_EQ(r.job.failures, 0);
  ASSERT_EQ(r.levels.size(), 2u);
  EXPECT_EQ(r.levels[1].status, db::LevelStatus::running);
  const Checkpoint snapshot = read_checkpoint(run_dir().snapshot(1));
  EXPECT_EQ(snapshot.solver.progress, LevelProgress::inside_frame);
  EXPECT_EQ(snapshot.frame, 1);
  EXPECT_EQ(snapshot.solver.iterations_in_frame, 3);

  stop = false;
  ASSERT_EQ(run(), jobs::RunOutcome::done);
  EXPECT_NE(log.find("resuming level 1 frame 1 from level_1.snapshot.h5"), std::string::npos)
      << log;
  EXPECT_EQ(result().job.state, db::JobState::done);
  expect_same_as_reference(final_checkpoint());
  // The frames the first attempt recorded and those the resumed one solved, each once.
  expect_frames_as_reference(result());
}

TEST_F(Executor, ADamagedSnapshotFallsBackToThePreviousOne) {
  ASSERT_EQ(run([this](int n) { stop = n == 9; }), jobs::RunOutcome::interrupted);
  ASSERT_TRUE(fs::exists(run_dir().previous_snapshot(0)));
  // A torn file: half of the latest snapshot, plus a temporary a killed write left behind.
  fs::resize_file(run_dir().snapshot(0), fs::file_size(run_dir().snapshot(0)) / 2);
  test::write_file(run_dir().dir() / ".level_0.snapshot.h5.tmp999", "partial");
  stop = false;
  ASSERT_EQ(run(), jobs::RunOutcome::done);
  EXPECT_NE(log.find("resuming level 0 frame 2 from level_0.snapshot.prev.h5"), std::string::npos)
      << log;
  EXPECT_FALSE(fs::exists(run_dir().dir() / ".level_0.snapshot.h5.tmp999"));
  expect_same_as_reference(final_checkpoint());
}

TEST_F(Executor, ASnapshotThatDiffersFromTheStoreRecordIsNotTrusted) {
  ASSERT_EQ(run([this](int n) { stop = n == 9; }), jobs::RunOutcome::interrupted);
  // A valid checkpoint, but not the file the store recorded (e.g. written by a dead attempt
  // after the last record): the previous snapshot is used instead.
  Checkpoint other = read_checkpoint(run_dir().snapshot(0));
  other.positions(0, 0) += 1.0;
  write_checkpoint(run_dir().snapshot(0), other);
  stop = false;
  ASSERT_EQ(run(), jobs::RunOutcome::done);
  EXPECT_NE(log.find("level_0.snapshot.prev.h5"), std::string::npos) << log;
  expect_same_as_reference(final_checkpoint());
}

TEST_F(Executor, WithNoValidCheckpointTheJobStartsOver) {
  ASSERT_EQ(run([this](int n) { stop = n == 9; }), jobs::RunOutcome::interrupted);
  for (const fs::path& file : {run_dir().snapshot(0), run_dir().previous_snapshot(0)})
    test::write_file(file, "not a checkpoint");
  stop = false;
  ASSERT_EQ(run(), jobs::RunOutcome::done);
  EXPECT_EQ(log.find("resuming"), std::string::npos) << log;
  expect_same_as_reference(final_checkpoint());
}

TEST_F(Executor, AFinestFrameThatDoesNotConvergeFailsTheJobForGood) {
  fail_at_level = 1;
  fail_at_frame = 3;
  ASSERT_EQ(run(), jobs::RunOutcome::failed);
  const db::JobResult r = result();
  EXPECT_EQ(r.job.state, db::JobState::failed);
  EXPECT_NE(r.job.error.find("level 1 frame 3 did not converge"), std::string::npos) << r.job.error;
  ASSERT_EQ(r.levels.size(), 2u);
  EXPECT_EQ(r.levels[0].status, db::LevelStatus::done);
  EXPECT_EQ(r.levels[1].status, db::LevelStatus::failed);
}

TEST_F(Executor, AFrameThatFailsForAReasonItKnowsFailsTheJobWithThatReason) {
  fail_at_level = 1;
  fail_at_frame = 2;
  failure = "level 1 frame 2: the settling to a static equilibrium stalled";
  ASSERT_EQ(run(), jobs::RunOutcome::failed);
  const db::JobResult r = result();
  EXPECT_EQ(r.job.state, db::JobState::failed);
  EXPECT_NE(r.job.error.find(failure), std::string::npos) << r.job.error;
  EXPECT_EQ(r.job.error.find("max_iterations"), std::string::npos) << r.job.error;
}

TEST_F(Executor, APreviewFrameMayStopAtItsIterationBudget) {
  // Coarse levels are previews with a fixed Newton budget per frame (progressive_simulation.hpp):
  // only the finest level has to converge.
  fail_at_level = 0;
  fail_at_frame = 3;
  ASSERT_EQ(run(), jobs::RunOutcome::done);
  const db::JobResult r = result();
  EXPECT_EQ(r.job.state, db::JobState::done);
  ASSERT_EQ(r.levels.size(), 2u);
  EXPECT_EQ(r.levels[0].status, db::LevelStatus::done);
}

TEST_F(Executor, AnUnwritableRunsDirectoryReleasesTheJobAndStopsTheWorker) {
  test::write_file(dir() / "runs_file", "a file where the runs directory should be");
  EXPECT_THROW(run({}, dir() / "runs_file"), jobs::WorkerEnvironmentError);
  const db::JobResult r = result();
  EXPECT_EQ(r.job.state, db::JobState::queued);
  EXPECT_EQ(r.job.failures, 0);
}

TEST_F(Executor, ASnapshotThatCannotBeWrittenKeepsTheRecordedOneAndTheJobResumesExactly) {
  // A directory in the way of the snapshot's temporary (replace_file_atomically's
  // ".<name>.tmp<pid>") fails the write with EISDIR, like a full or read-only disk would: at
  // progress event 7 (frame 2, step 1: a snapshot is due), after the snapshot of frame 1 step 4.
  const fs::path obstacle =
      run_dir().dir() / fmt::format(".{}.tmp{}", run_dir().snapshot(0).filename().string(),
                                    ::getpid());
  const auto block_at_seven = [&](int n) {
    if (n != 7) return;
    fs::create_directories(obstacle);
    test::write_file(obstacle / "in_the_way", "so that the failed write cannot remove it");
  };
  const std::string snapshot = run_dir().snapshot(0).string();
  try {
    run(block_at_seven);
    FAIL() << "expected WorkerEnvironmentError";
  } catch (const jobs::WorkerEnvironmentError& error) {
    EXPECT_NE(std::string(error.what()).find(snapshot), std::string::npos) << error.what();
  }
  const db::JobResult stopped = result();
  EXPECT_EQ(stopped.job.state, db::JobState::queued);
  EXPECT_EQ(stopped.job.failures, 0);
  EXPECT_NE(stopped.job.error.find("attempt 1 stopped: "), std::string::npos) << stopped.job.error;
  EXPECT_NE(stopped.job.error.find(snapshot), std::string::npos) << stopped.job.error;
  EXPECT_NE(stopped.job.error.find("Is a directory"), std::string::npos) << stopped.job.error;
  // The store's record still names the previous snapshot, which verifies against its checksum.
  ASSERT_EQ(stopped.levels.size(), 1u);
  const db::LevelRecord& record = stopped.levels[0];
  EXPECT_EQ(record.status, db::LevelStatus::running);
  EXPECT_EQ(fs::path(record.checkpoint_path), fs::absolute(snapshot));
  const auto checksum = parse_checksum(record.checkpoint_checksum);
  ASSERT_TRUE(checksum);
  const Checkpoint kept = read_checkpoint(snapshot, *checksum);
  EXPECT_EQ(kept.frame, 1);
  EXPECT_EQ(kept.solver.iterations_in_frame, 4);
  EXPECT_TRUE(db::JobStore(dir() / "psq.db").integrity_problems().empty());

  fs::remove_all(obstacle);
  ASSERT_EQ(run(), jobs::RunOutcome::done);
  EXPECT_NE(log.find("resuming level 0 frame 1 from level_0.snapshot.h5"), std::string::npos)
      << log;
  const db::JobResult finished = result();
  EXPECT_EQ(finished.job.state, db::JobState::done);
  EXPECT_EQ(finished.job.error, "");
  expect_same_as_reference(final_checkpoint());
}

TEST_F(Executor, ACancelledJobStopsAtItsNextHeartbeat) {
  lease_seconds = 0.3;
  const auto cancel_then_wait = [this](int n) {
    if (n != 3) return;
    db::JobStore(dir() / "psq.db").cancel(db::JobSelection::job(job_id()));
    std::this_thread::sleep_for(std::chrono::milliseconds(400));  // > 3 heartbeat periods
  };
  EXPECT_EQ(run(cancel_then_wait), jobs::RunOutcome::lease_lost);
  EXPECT_EQ(result().job.state, db::JobState::cancelled);
}

TEST(ExecutorScenes, TheResolutionSweepsJobsRunOnMeshesOfTheirEdgeLengths) {
  const jobs::Sweep sweep = jobs::read_sweep(test::source_dir() / "jobs/sweeps/resolution.toml");
  ASSERT_EQ(sweep.jobs.size(), 3u);
  const fs::path dir = test::fresh_temp_dir("resolution_sweep");
  db::JobStore store(dir / "psq.db");
  store.add_sweep(sweep.name, sweep.file.string(), jobs::new_jobs(sweep));
  int vertices = 0;  // of the scene the executor built for the job being run
  const std::atomic<bool> stop{false};
  jobs::JobExecutor executor(
      store, dir / "psq.db", dir / "runs",
      [&](const Scene& scene, db::Method, int depth) {
        vertices = build_shell_mesh(scene.shells.at(0).mesh).vertex_count();
        return std::make_unique<ScriptedSolver>(depth, 1, 1);
      },
      {.snapshot_iterations = 1000, .snapshot_seconds = 1e9, .code_version = "test"}, {}, stop);
  std::map<std::string, int> vertices_of_job;
  while (const auto claim = store.claim_next({"w", "host", "test"}, 30.0)) {
    ASSERT_EQ(executor.run(*claim), jobs::RunOutcome::done);
    vertices_of_job[claim->job.id] = vertices;
  }
  ASSERT_EQ(vertices_of_job.size(), 3u);
  // The 0.2 m × 0.02 m structured sheet has (0.2/h + 1)·(0.02/h + 1) vertices.
  for (const jobs::SweepJob& job : sweep.jobs) {
    const double h = job.overrides.at("shell.strip.mesh.edge_length").get<double>();
    EXPECT_EQ(vertices_of_job.at(job.id), (std::lround(0.2 / h) + 1) * (std::lround(0.02 / h) + 1))
        << "edge length " << h;
  }
}

}  // namespace
}  // namespace psq
