// `psq work` end to end: a sweep run by worker processes, several `psq work` processes on one
// store (each job run exactly once), the XDMF sidecar of a real job against its HDF5 file, and
// bad input and a hostile environment (clear error, non-zero exit, a consistent store).

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cmath>
#include <nlohmann/json.hpp>

#include "db/job_store.hpp"
#include "engine/io/checkpoint.hpp"
#include "io/xdmf_validator.hpp"
#include "jobs/psq_child.hpp"
#include "runner/cantilever_workspace.hpp"
#include "support/run_process.hpp"
#include "support/test_paths.hpp"

namespace psq {
namespace {

namespace fs = std::filesystem;

class WorkCommand : public ::testing::Test {
 protected:
  /// Adds a sweep over `grid` (TOML lines of the [grid] table); returns the exit code.
  int add_sweep(const std::string& grid, const std::string& name = "w") {
    const auto result = workspace_.add_sweep(name, grid);
    add_errors_ = result.errors;
    return result.exit_code;
  }
  test::ProcessResult psq(std::vector<std::string> arguments) { return workspace_.psq(arguments); }
  std::vector<db::JobResult> results() { return workspace_.results(); }
  /// The store opens, passes SQLite's integrity check, and every job's state agrees with its
  /// lease fields (the schema enforces the rest).
  void expect_store_consistent() {
    db::JobStore store(db_);
    EXPECT_TRUE(store.integrity_problems().empty());
    for (const db::JobResult& r : store.results(db::JobSelection::all()))
      EXPECT_EQ(r.job.lease_owner.empty(), r.job.state != db::JobState::running) << r.job.id;
  }

  // The store in the default workspace directory .psq/, with the runs and cache beside it.
  const test::CantileverWorkspace workspace_{"work_command", fs::path(".psq") / "psq.db"};
  const fs::path& dir_ = workspace_.dir;
  const fs::path& db_ = workspace_.db;
  std::string add_errors_;
};

TEST_F(WorkCommand, DeeperJobsRunLevelByLevelAndShareOneCachedHierarchy) {
  ASSERT_EQ(add_sweep("\"shell.strip.material.thickness\" = [1e-3, 2e-3]\ndepth = [2]\n"), 0)
      << add_errors_;
  const auto work = psq({"work", "--workers", "1"});
  ASSERT_EQ(work.exit_code, 0) << work.errors;
  const auto finished = results();
  ASSERT_EQ(finished.size(), 2u);
  for (const db::JobResult& r : finished) {
    EXPECT_EQ(r.job.state, db::JobState::done);
    ASSERT_EQ(r.levels.size(), 2u);
    const Checkpoint coarse = read_checkpoint(r.levels[0].checkpoint_path);
    const Checkpoint fine = read_checkpoint(r.levels[1].checkpoint_path);
    EXPECT_LT(coarse.positions.rows(), fine.positions.rows());
    // The coarse level's state is prolonged to the finest mesh; the finest level's is itself.
    EXPECT_EQ(coarse.finest_positions.rows(), fine.positions.rows());
    EXPECT_EQ(fine.finest_positions, fine.positions);
    EXPECT_LT(fine.positions.col(2).minCoeff(), -1e-5);
  }
  // Thickness does not change the mesh or the pins: one hierarchy serves both jobs.
  int cached = 0;
  for (const auto& entry : fs::directory_iterator(db_.parent_path() / "cache"))
    cached += entry.path().extension() == ".bin";
  EXPECT_EQ(cached, 1);
  expect_store_consistent();
}

TEST_F(WorkCommand, AResolutionSweepRunsEachMeshAndCachesAHierarchyForEach) {
  // A small jobs/sweeps/resolution.toml: two edge lengths, two frames, two levels.
  ASSERT_EQ(add_sweep("\"shell.strip.mesh.edge_length\" = [0.005, 0.0025]\n"
                      "\"time.frames\" = [2]\ndepth = [2]\n"),
            0)
      << add_errors_;
  const auto work = psq({"work", "--workers", "1"});
  ASSERT_EQ(work.exit_code, 0) << work.errors;
  const auto finished = results();
  ASSERT_EQ(finished.size(), 2u);
  for (const db::JobResult& r : finished) {
    EXPECT_EQ(r.job.state, db::JobState::done);
    ASSERT_EQ(r.levels.size(), 2u);
    // The finest level is the 0.2 m × 0.02 m structured sheet at the job's edge length.
    const double h = r.job.parameters.at("overrides").at("shell.strip.mesh.edge_length");
    const Checkpoint fine = read_checkpoint(r.levels[1].checkpoint_path);
    EXPECT_EQ(fine.positions.rows(), (std::lround(0.2 / h) + 1) * (std::lround(0.02 / h) + 1));
    EXPECT_EQ(fine.frame, 2);
  }
  // The hierarchy is keyed on the mesh: each edge length has its own.
  int cached = 0;
  for (const auto& entry : fs::directory_iterator(db_.parent_path() / "cache"))
    cached += entry.path().extension() == ".bin";
  EXPECT_EQ(cached, 2);
  expect_store_consistent();
}

TEST_F(WorkCommand, WorkerProcessesRunASweepAndRecordEveryJob) {
  ASSERT_EQ(add_sweep("\"shell.strip.material.thickness\" = [8e-4, 1e-3, 2e-3]\n"), 0);
  const auto work = psq({"work", "--workers", "2"});
  EXPECT_EQ(work.exit_code, 0) << work.errors;
  EXPECT_NE(work.errors.find("2 worker processes"), std::string::npos) << work.errors;
  EXPECT_NE(work.errors.find("level 0 done"), std::string::npos) << work.errors;
  for (const db::JobResult& r : results()) {
    EXPECT_EQ(r.job.state, db::JobState::done);
    ASSERT_EQ(r.levels.size(), 1u);
    EXPECT_EQ(r.levels[0].status, db::LevelStatus::done);
    EXPECT_GT(r.levels[0].iterations, 0);
    // The cantilever bends down under its tip load, thinner strips more.
    const Checkpoint c = read_checkpoint(r.levels[0].checkpoint_path);
    EXPECT_LT(c.positions.col(2).minCoeff(), -1e-5);
    EXPECT_EQ(c.frame, 10);
    // Clapeyron: a linear elastic body in equilibrium stores half the work of its load, here
    // ½·F·δ for the 1 mN tip line load and the tip's mean deflection δ.
    double tip_deflection = 0.0;
    int tip_vertices = 0;
    for (Eigen::Index v = 0; v < c.rest_positions.rows(); ++v) {
      if (c.rest_positions(v, 0) < 0.099) continue;
      tip_deflection -= c.positions(v, 2) - c.rest_positions(v, 2);
      ++tip_vertices;
    }
    ASSERT_GT(tip_vertices, 0);
    const double work = 0.5 * 1e-3 * tip_deflection / tip_vertices;
    EXPECT_NEAR(c.solver.scalars.at(kElasticEnergyScalar), work, 0.03 * work);
  }
  expect_store_consistent();
  // Nothing left: a second run has nothing to do.
  const auto again = psq({"work", "--workers", "1"});
  EXPECT_EQ(again.exit_code, 0);
  EXPECT_NE(again.errors.find("0 done, 0 failed"), std::string::npos) << again.errors;
}

TEST_F(WorkCommand, TheSidecarOfARealJobMatchesItsHdf5File) {
  ASSERT_EQ(add_sweep("\"time.frames\" = [3]\n"), 0);
  ASSERT_EQ(psq({"work", "--workers", "1"}).exit_code, 0);
  const db::JobResult r = results().front();
  const fs::path sidecar = dir_ / ".psq" / "runs" / r.job.id / "job.xdmf";
  const test::SidecarSummary summary = test::validate_sidecar(sidecar);
  EXPECT_TRUE(summary.problems.empty()) << summary.problems.front();
  EXPECT_EQ(summary.uniform_grids, 1);
  EXPECT_GE(summary.hdf_items, 3);  // topology, geometry, rest positions
}

TEST_F(WorkCommand, SeveralWorkCommandsOnOneStoreRunEachJobExactlyOnce) {
  ASSERT_EQ(add_sweep("\"shell.strip.material.thickness\" = [6e-4, 7e-4, 8e-4, 9e-4, 1e-3, "
                      "1.2e-3]\n\"time.frames\" = [4]\n"),
            0);
  std::vector<std::unique_ptr<test::PsqChild>> workers;
  for (int k = 0; k < 3; ++k) {
    const fs::path log = dir_ / fmt::format("worker{}", k);
    fs::create_directories(log);
    workers.push_back(std::make_unique<test::PsqChild>(
        PSQ_EXECUTABLE,
        std::vector<std::string>{"work", "--db", db_.string(), "--workers", k == 2 ? "2" : "1"},
        log));
  }
  for (auto& worker : workers) EXPECT_EQ(worker->wait(), 0) << worker->errors();
  const std::vector<db::JobResult> all = results();
  ASSERT_EQ(all.size(), 6u);
  for (const db::JobResult& r : all) {
    EXPECT_EQ(r.job.state, db::JobState::done);
    EXPECT_EQ(r.job.attempt, 1) << "job " << r.job.id << " was claimed more than once";
    ASSERT_EQ(r.levels.size(), 1u);
    EXPECT_EQ(r.levels[0].attempt, 1);
  }
  expect_store_consistent();
}

TEST_F(WorkCommand, BadSweepsAreRefusedAndAddNothing) {
  ASSERT_EQ(add_sweep("\"time.frames\" = [3]\n", "good"), 0);
  const std::vector<std::pair<std::string, std::string>> bad{
      {"\"shell.strip.material.thickness\" = [-1e-3]\n", "must be positive"},
      {"\"shell.strip.material.poisson_ratio\" = [0.5]\n", "poisson_ratio"},
      {"\"depth\" = [0]\n", "depth"},
      {"\"shell.strip.material.thicknes\" = [1e-3]\n", "thickness"},  // suggested
      {"\"time.frames\" = [3\n", "bad.toml"},                         // TOML syntax
  };
  for (const auto& [grid, expected] : bad) {
    SCOPED_TRACE(grid);
    EXPECT_EQ(add_sweep(grid, "bad"), 1);
    EXPECT_NE(add_errors_.find(expected), std::string::npos) << add_errors_;
  }
  test::write_file(dir_ / "broken_scene.toml", "name = \"x\"\n[time]\nstep = -1\n");
  test::write_file(dir_ / "bad.toml", "name = \"bad\"\nscene = \"broken_scene.toml\"\n");
  const auto broken = psq({"sweep", "add", (dir_ / "bad.toml").string()});
  EXPECT_EQ(broken.exit_code, 1);
  EXPECT_NE(broken.errors.find("broken_scene.toml:3"), std::string::npos) << broken.errors;
  EXPECT_EQ(results().size(), 1u);
  expect_store_consistent();
}

TEST_F(WorkCommand, AJobWhoseSceneChangedFailsForGoodWithAClearMessage) {
  ASSERT_EQ(add_sweep("\"time.frames\" = [3]\n"), 0);
  test::write_file(dir_ / "scene.toml", "# edited\n" + test::read_file(dir_ / "scene.toml"));
  const auto work = psq({"work", "--workers", "1"});
  EXPECT_EQ(work.exit_code, 5);
  const db::JobResult r = results().front();
  EXPECT_EQ(r.job.state, db::JobState::failed);
  EXPECT_NE(r.job.error.find("changed since the sweep was added"), std::string::npos)
      << r.job.error;
  expect_store_consistent();
}

TEST_F(WorkCommand, AnUnwritableOutputDirectoryStopsTheWorkerAndKeepsTheJobQueued) {
  ASSERT_EQ(add_sweep("\"time.frames\" = [3]\n"), 0);
  test::write_file(dir_ / ".psq" / "runs", "a file where the runs directory should be");
  const auto work = psq({"work", "--workers", "1"});
  EXPECT_EQ(work.exit_code, 1);
  EXPECT_NE(work.errors.find("cannot create the job's output directory"), std::string::npos)
      << work.errors;
  EXPECT_EQ(results().front().job.state, db::JobState::queued);
  EXPECT_EQ(results().front().job.failures, 0);
  expect_store_consistent();
}

TEST_F(WorkCommand, AFullDiskStopsTheWorkerCleanlyAndTheWorkResumesLater) {
  // A finer strip (729 vertices): its checkpoints (~100 kB) exceed the limit, while the store's
  // files (the -shm index takes 32 kB) stay below it.
  std::string scene = test::read_file(dir_ / "scene.toml");
  scene.replace(scene.find("edge_length = 0.005"), 19, "edge_length = 0.0025");
  test::write_file(dir_ / "scene.toml", scene);
  ASSERT_EQ(add_sweep("\"shell.strip.material.thickness\" = [8e-4, 1e-3]\n"), 0);
  test::ChildOptions small_disk;
  small_disk.file_size_limit = 64 * 1024;
  test::PsqChild child(PSQ_EXECUTABLE, {"work", "--db", db_.string(), "--workers", "1"}, dir_,
                       small_disk);
  EXPECT_EQ(child.wait(), 1) << child.errors();
  EXPECT_NE(child.errors().find("File too large"), std::string::npos) << child.errors();
  EXPECT_NE(child.errors().find("released"), std::string::npos) << child.errors();
  expect_store_consistent();
  const db::Job stopped = results().front().job;
  EXPECT_EQ(stopped.state, db::JobState::queued);
  EXPECT_EQ(stopped.failures, 0);
  // The attempt says which file it could not write, and why.
  const std::string run_dir = fs::absolute(dir_ / ".psq" / "runs" / stopped.id).string();
  EXPECT_NE(stopped.error.find(run_dir + "/level_0."), std::string::npos) << stopped.error;
  EXPECT_NE(stopped.error.find("File too large"), std::string::npos) << stopped.error;
  const auto resumed = psq({"resume", "w", "--workers", "1"});
  EXPECT_EQ(resumed.exit_code, 0) << resumed.errors;
  for (const db::JobResult& r : results()) EXPECT_EQ(r.job.state, db::JobState::done);
  expect_store_consistent();
}

TEST_F(WorkCommand, WithoutAStoreItSaysHowToMakeOne) {
  const auto work = psq({"work"});
  EXPECT_EQ(work.exit_code, 1);
  EXPECT_NE(work.errors.find("psq sweep add"), std::string::npos) << work.errors;
}

}  // namespace
}  // namespace psq
