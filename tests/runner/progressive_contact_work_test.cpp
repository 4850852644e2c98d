// Sweep jobs of a contact scene with depth 2 (issue 13 items 7 and 8): `psq work` runs them
// through the progressive solver's safe refinement; the refinement's statistics reach the level
// checkpoint, the store's level record and the report; a worker SIGKILLed inside the safe
// initialization resumes from the level it was refining and ends where an uninterrupted run
// ends; and the job's XDMF sidecars show the sheet and the moving ball as blocks of every level
// (issue 17 item 5).

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <thread>

#include "db/job_store.hpp"
#include "engine/io/checkpoint.hpp"
#include "engine/io/xdmf.hpp"
#include "engine/scene/scene_reader.hpp"
#include "engine/sim/shell_system.hpp"
#include "io/meshio_reader.hpp"
#include "jobs/psq_child.hpp"
#include "runner/cantilever_workspace.hpp"
#include "support/press_scene.hpp"
#include "support/run_process.hpp"
#include "support/test_paths.hpp"

namespace psq {
namespace {

namespace fs = std::filesystem;

constexpr double kLease = 0.4;  // seconds; short, so a killed worker's job is free again soon

/// Two jobs of depth 2 of the press (its refinement expands 18 clusters in five batches against
/// the sphere) in a fresh store.
struct PressSweep : test::CantileverWorkspace {
  explicit PressSweep(const std::string& name) : CantileverWorkspace(name) {
    test::write_file(dir / "scene.toml", test::kPressScene);
    const test::ProcessResult added =
        add_sweep("p", "\"shell.sheet.material.thickness\" = [1e-3, 1.5e-3]\ndepth = [2]\n");
    EXPECT_EQ(added.exit_code, 0) << added.errors;
  }

  /// `psq work` (or resume) with one worker, to its end or to the kill PSQ_TEST_PAUSE_AT asks
  /// for; returns the exit code and leaves the child's stderr in `errors`.
  int run(const std::string& pause_at, std::string* errors = nullptr) const {
    test::ChildOptions options;
    if (!pause_at.empty()) options.environment["PSQ_TEST_PAUSE_AT"] = pause_at;
    test::PsqChild child(
        PSQ_EXECUTABLE,
        {"work", "--db", db.string(), "--workers", "1", "--lease", fmt::format("{}", kLease)}, dir,
        options);
    const int code = child.wait();
    if (errors) *errors = child.errors();
    return code;
  }

  Checkpoint level_checkpoint(const std::string& job, int level) const {
    return read_checkpoint(dir / "runs" / job / fmt::format("level_{}.h5", level));
  }
};

/// The finest checkpoints of an uninterrupted run, by job id.
const std::map<std::string, Checkpoint>& reference() {
  static const std::map<std::string, Checkpoint> checkpoints = [] {
    const PressSweep sweep("progressive_contact_reference");
    EXPECT_EQ(sweep.run(""), 0);
    std::map<std::string, Checkpoint> by_id;
    for (const db::JobResult& r : sweep.results())
      by_id[r.job.id] = sweep.level_checkpoint(r.job.id, 1);
    return by_id;
  }();
  return checkpoints;
}

TEST(ProgressiveContactWork, RefinementStatisticsReachTheCheckpointTheStoreAndTheReport) {
  const PressSweep sweep("progressive_contact_stats");
  std::string errors;
  ASSERT_EQ(sweep.run("", &errors), 0) << errors;
  // The worker shows the refinement's phases as they start.
  EXPECT_NE(errors.find("refining to level 1: batch 1 of"), std::string::npos) << errors;
  EXPECT_NE(errors.find("refining to level 1: exact check"), std::string::npos) << errors;

  const std::vector<db::JobResult> results = sweep.results();
  ASSERT_EQ(results.size(), 2u);
  for (const db::JobResult& r : results) {
    SCOPED_TRACE(r.job.id);
    EXPECT_EQ(r.job.state, db::JobState::done) << r.job.error;
    ASSERT_EQ(r.levels.size(), 2u);
    EXPECT_TRUE(r.levels[0].refinement.empty());  // level 0 is not refined into
    const std::map<std::string, double>& stats = r.levels[1].refinement;
    EXPECT_GT(stats.at("expansions"), 0.0);
    EXPECT_GE(stats.at("batches"), 1.0);
    EXPECT_GT(stats.at("ccd_rounds"), 0.0);
    EXPECT_GE(stats.at("perturbation_retries"), 0.0);
    // The initializer keeps a positive gap, measured up to d̂ (its cap).
    EXPECT_GT(stats.at("final_gap"), 0.0);
    EXPECT_LE(stats.at("final_gap"), 2e-4 + 1e-12);
    EXPECT_GT(stats.at("smallest_gap"), 0.0);
    EXPECT_LE(stats.at("mean_target_distance"), stats.at("max_target_distance"));
    const double phases = stats.at("gap_seconds") + stats.at("perturb_seconds") +
                          stats.at("ccd_seconds") + stats.at("relax_seconds") +
                          stats.at("check_seconds");
    EXPECT_LE(phases, stats.at("safe_initialization_seconds") + 1e-9);
    EXPECT_LE(stats.at("safe_initialization_seconds"), stats.at("seconds") + 1e-9);
    // The same figures in the level's checkpoint, to the bit.
    EXPECT_EQ(sweep.level_checkpoint(r.job.id, 1).statistics.refinement, stats);
    EXPECT_TRUE(sweep.level_checkpoint(r.job.id, 0).statistics.refinement.empty());
  }

  const fs::path out = sweep.dir / "report";
  const test::ProcessResult report = sweep.psq({"report", "p", "--out", out.string()});
  ASSERT_EQ(report.exit_code, 0) << report.errors;
  const std::string html = test::read_file(out / "report.html");
  EXPECT_NE(html.find("<h2>Refinements</h2>"), std::string::npos);
  EXPECT_NE(html.find("final gap (m)"), std::string::npos);
  const std::string markdown = test::read_file(out / "summary.md");
  EXPECT_NE(markdown.find("## Refinements"), std::string::npos);
}

TEST(ProgressiveContactWork, AWorkerKilledInsideTheSafeInitializationResumesToTheSameResult) {
  ASSERT_EQ(reference().size(), 2u);
  const PressSweep sweep("progressive_contact_kill");
  // A refinement tells a phase per expansion batch, then the advance, the relaxation and the
  // exact check (safe_refinement.hpp). Two kills inside the first job's refinement (a third
  // without progress would fail the job: docs/job-store.md), then one inside the second job's,
  // after the first job's refinement has passed all its phases in that run.
  const std::vector<db::JobResult> jobs = sweep.results();
  ASSERT_EQ(jobs.size(), 2u);
  const int first_phases =
      static_cast<int>(reference().at(jobs[0].job.id).statistics.refinement.at("batches")) + 3;
  int killed = 0;
  for (const int phase : {3, first_phases, first_phases + 2}) {
    const std::string moment = fmt::format("refinement_phase:{}", phase);
    SCOPED_TRACE(moment);
    const int code = sweep.run(moment + ":kill");
    EXPECT_EQ(code, 128 + SIGKILL);
    killed += code == 128 + SIGKILL;
    std::this_thread::sleep_for(std::chrono::duration<double>(kLease * 1.3));
  }
  EXPECT_EQ(killed, 3) << "the refinements ended before the kills did";
  std::string errors;
  ASSERT_EQ(sweep.run("", &errors), 0) << errors;

  db::JobStore store(sweep.db);
  EXPECT_TRUE(store.integrity_problems().empty());
  for (const db::JobResult& r : sweep.results()) {
    SCOPED_TRACE(r.job.id);
    EXPECT_EQ(r.job.state, db::JobState::done) << r.job.error;
    ASSERT_EQ(r.levels.size(), 2u);
    EXPECT_EQ(r.levels[1].status, db::LevelStatus::done);
    const Checkpoint finest = sweep.level_checkpoint(r.job.id, 1);
    const Checkpoint& expected = reference().at(r.job.id);
    ASSERT_EQ(finest.positions.rows(), expected.positions.rows());
    EXPECT_EQ((finest.positions - expected.positions).cwiseAbs().maxCoeff(), 0.0);
    ASSERT_EQ(finest.statistics.iterations.size(), expected.statistics.iterations.size());
    for (std::size_t k = 0; k < expected.statistics.iterations.size(); ++k)
      EXPECT_EQ(finest.statistics.iterations[k].gradient_norm,
                expected.statistics.iterations[k].gradient_norm);
    EXPECT_EQ(finest.statistics.refinement.at("expansions"),
              expected.statistics.refinement.at("expansions"));
    EXPECT_EQ(finest.statistics.refinement.at("final_gap"),
              expected.statistics.refinement.at("final_gap"));
  }
}

/// The triangles of a JSON list of triples.
Triangles triangles_of(const nlohmann::json& rows) {
  Triangles triangles(static_cast<Eigen::Index>(rows.size()), 3);
  for (std::size_t r = 0; r < rows.size(); ++r)
    for (int c = 0; c < 3; ++c) triangles(static_cast<Eigen::Index>(r), c) = rows[r][c];
  return triangles;
}

TEST(ProgressiveContactWork, TheSidecarsShowTheSheetAndTheBallAtEveryLevelAsMeshioReadsThem) {
  const PressSweep sweep("progressive_contact_xdmf");
  ASSERT_EQ(sweep.run(""), 0);
  const std::string job = sweep.results().front().job.id;
  const fs::path sidecar = sweep.dir / "runs" / job / "job.xdmf";
  const std::vector<fs::path> parts = part_sidecar_paths(sidecar, {"sheet", "ball"});
  const nlohmann::json read = test::read_with_meshio(sidecar, parts);

  EXPECT_TRUE(read["mismatches"].empty()) << read["mismatches"].dump();
  ASSERT_EQ(read["blocks"].size(), 2u);  // one step per level
  for (const nlohmann::json& step : read["blocks"])
    EXPECT_EQ(step["grids"], (nlohmann::json{"sheet", "ball"}));
  const nlohmann::json& sheet = read["parts"][0];
  const nlohmann::json& ball = read["parts"][1];
  ASSERT_EQ(sheet["steps"], 2);
  ASSERT_EQ(ball["steps"], 2);

  const ShellSystem finest(read_scene(sweep.dir / "scene.toml"));
  for (int level = 0; level < 2; ++level) {
    SCOPED_TRACE(::testing::Message() << "level " << level);
    const Checkpoint c = sweep.level_checkpoint(job, level);
    const nlohmann::json& s = sheet["frames"][level];
    const nlohmann::json& b = ball["frames"][level];
    const auto n = static_cast<Eigen::Index>(s["points"].size());
    const auto m = static_cast<Eigen::Index>(s["triangles"].size());
    // The blocks are the checkpoint's one mesh, cut where the sheet ends.
    ASSERT_EQ(n + static_cast<Eigen::Index>(b["points"].size()), c.positions.rows());
    ASSERT_EQ(m + static_cast<Eigen::Index>(b["triangles"].size()), c.triangles.rows());
    test::expect_rows_near(s["points"], c.positions.topRows(n), 0.0);
    test::expect_rows_near(b["points"], c.positions.bottomRows(c.positions.rows() - n), 0.0);
    test::expect_rows_near(s["point_data"]["rest_position"], c.rest_positions.topRows(n), 0.0);
    EXPECT_EQ(triangles_of(s["triangles"]), c.triangles.topRows(m));
    EXPECT_EQ(Triangles(triangles_of(b["triangles"]).array() + static_cast<int>(n)),
              c.triangles.bottomRows(c.triangles.rows() - m));
    const Positions sheet_moved = c.positions.topRows(n) - c.rest_positions.topRows(n);
    test::expect_rows_near(s["point_data"]["displacement"], sheet_moved, 0.0);
    // Both levels end at the last frame (t = 0.4 s), where the ball's one motion has taken it
    // 6 cm down.
    EXPECT_EQ(c.frame, 10);
    const Positions down = Eigen::RowVector3d(0, 0, -0.06).replicate(c.positions.rows() - n, 1);
    test::expect_rows_near(b["point_data"]["displacement"], down, 1e-12);
  }
  // The finest level holds the scene's own meshes; the coarse one a coarser sheet.
  EXPECT_EQ(sheet["frames"][1]["points"].size(),
            static_cast<std::size_t>(finest.shells()[0].vertex_count));
  EXPECT_EQ(ball["frames"][1]["points"].size(),
            static_cast<std::size_t>(finest.colliders()[0].vertex_count));
  EXPECT_LT(sheet["frames"][0]["points"].size(), sheet["frames"][1]["points"].size());
}

}  // namespace
}  // namespace psq
