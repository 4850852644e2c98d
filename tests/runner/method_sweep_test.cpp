// Methods as a sweep axis (docs/sweep-format.md, "Methods"): one sweep runs the direct fine
// solve, the progressive solve and the coarse direct solve prolonged to the finest mesh; each job
// stores its method, the coarse job's finest answer is the prolongation of a direct solve of the
// coarse level, and a job of each method interrupted by SIGKILL ends bit-identical to an
// uninterrupted run.

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <csignal>
#include <map>
#include <thread>

#include "db/job_store.hpp"
#include "engine/io/checkpoint.hpp"
#include "engine/progressive/progressive_simulation.hpp"
#include "engine/scene/scene_reader.hpp"
#include "engine/sim/quasistatic.hpp"
#include "jobs/psq_child.hpp"
#include "runner/cantilever_workspace.hpp"
#include "support/test_paths.hpp"

namespace psq {
namespace {

constexpr double kLease = 0.4;  // seconds: a killed worker's job is free again soon
constexpr int kDepth = 2;

/// The cantilever workspace with the sweep "m" of `methods` (a TOML list of names) at depth 2,
/// added.
struct MethodWorkspace : test::CantileverWorkspace {
  MethodWorkspace(const std::string& name, const std::string& methods)
      : CantileverWorkspace(name) {
    const auto file = test::write_file(
        dir / "m.toml",
        fmt::format("name = \"m\"\nscene = \"scene.toml\"\ndepth = {}\n[grid]\nmethod = {}\n",
                    kDepth, methods));
    const test::ProcessResult added = psq({"sweep", "add", file.string()});
    EXPECT_EQ(added.exit_code, 0) << added.errors;
  }

  std::vector<std::string> work_arguments(const std::string& command) const {
    std::vector<std::string> args{command};
    if (command == "resume") args.push_back("m");
    args.insert(args.end(), {"--db", db.string(), "--workers", "1", "--lease",
                             fmt::format("{}", kLease), "--snapshot-iterations", "2"});
    return args;
  }

  /// Runs `command` to its end, killed at `kill_at` (PSQ_TEST_PAUSE_AT) when that is given.
  int run(const std::string& command, const std::string& kill_at = {}) const {
    test::ChildOptions options;
    if (!kill_at.empty()) options.environment["PSQ_TEST_PAUSE_AT"] = kill_at + ":kill";
    test::PsqChild child(PSQ_EXECUTABLE, work_arguments(command), dir, options);
    return child.wait();
  }
};

/// The checkpoint of a job's last recorded level.
Checkpoint last_checkpoint(const db::JobResult& result) {
  EXPECT_FALSE(result.levels.empty());
  return read_checkpoint(result.levels.back().checkpoint_path);
}

double largest_difference(const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
  EXPECT_EQ(a.size(), b.size());
  if (a.size() != b.size()) return std::numeric_limits<double>::infinity();
  return (a - b).cwiseAbs().maxCoeff();
}

/// Newton iterations a job's levels took in all, from their checkpoints.
std::size_t iterations_of(const db::JobResult& result) {
  std::size_t iterations = 0;
  for (const db::LevelRecord& level : result.levels)
    iterations += read_checkpoint(level.checkpoint_path).statistics.iterations.size();
  return iterations;
}

TEST(MethodSweep, EachMethodRunsIsStoredAndTheCoarseAnswerIsProlongedToTheFinestMesh) {
  const MethodWorkspace workspace(
      "method_sweep", "[\"direct\", \"direct_final\", \"progressive\", \"coarse_prolonged\"]");
  ASSERT_EQ(workspace.run("work"), 0);
  std::map<db::Method, db::JobResult> by_method;
  for (const db::JobResult& r : workspace.results()) {
    EXPECT_EQ(r.job.state, db::JobState::done) << r.job.error;
    by_method.emplace(r.job.method, r);
  }
  ASSERT_EQ(by_method.size(), 4u);
  EXPECT_EQ(by_method.at(db::Method::direct).levels.size(), 1u);
  ASSERT_EQ(by_method.at(db::Method::direct_final).levels.size(), 1u);
  EXPECT_EQ(by_method.at(db::Method::progressive).levels.size(), std::size_t{kDepth});
  ASSERT_EQ(by_method.at(db::Method::coarse_prolonged).levels.size(), 1u);

  const Checkpoint fine = last_checkpoint(by_method.at(db::Method::direct));
  const Checkpoint coarse = last_checkpoint(by_method.at(db::Method::coarse_prolonged));
  // The coarse job solved the coarse mesh and stored its answer on the finest mesh.
  EXPECT_LT(coarse.positions.rows(), fine.positions.rows());
  ASSERT_EQ(coarse.finest_positions.rows(), fine.positions.rows());

  // direct_final settles the last frame only (the refine frame, the scene's last), direct every
  // frame; both reach the same equilibrium.
  const Checkpoint fine_final = last_checkpoint(by_method.at(db::Method::direct_final));
  const auto& settled_final = by_method.at(db::Method::direct_final).levels[0].static_residuals;
  ASSERT_EQ(settled_final.size(), 1u);
  EXPECT_EQ(settled_final[0].first, fine.frame);
  EXPECT_EQ(by_method.at(db::Method::direct).levels[0].static_residuals.size(),
            std::size_t(fine.frame));
  const double deflection = largest_difference(flat(fine.positions), flat(fine.rest_positions));
  EXPECT_GT(deflection, 1e-4 * bounding_box_diagonal(fine.rest_positions));
  EXPECT_LE(largest_difference(flat(fine_final.positions), flat(fine.positions)),
            1e-2 * deflection);

  // The coarse level of the same hierarchy, solved directly here, and prolonged here.
  const Scene scene = read_scene(workspace.dir / "scene.toml");
  ProgressiveSettings settings = ProgressiveSettings::from_scene(scene);
  settings.schedule.levels = kDepth;
  const CoarseProblem problem = ProgressiveSimulation(scene, settings).coarse_problem(0);
  QuasistaticSimulation direct_coarse(scene, problem.shells, problem.colliders, problem.loads);
  while (direct_coarse.frame() < direct_coarse.frame_count()) {
    const FrameRecord frame = direct_coarse.step();
    ASSERT_TRUE(frame.newton.converged) << frame.frame;
  }
  EXPECT_LE(largest_difference(flat(coarse.positions), direct_coarse.positions()), 1e-12);
  EXPECT_EQ(largest_difference(flat(coarse.finest_positions),
                               problem.to_finest.apply(flat(coarse.positions))),
            0.0);
  // The coarse load is the fine one carried over: the same total force bends the strip.
  const Eigen::Vector3d fine_total = as_positions(ShellSystem(scene).loads()).colwise().sum().transpose();
  const Eigen::Vector3d coarse_total = as_positions(problem.loads).colwise().sum().transpose();
  EXPECT_LE((fine_total - coarse_total).norm(), 1e-12 * fine_total.norm());
  EXPECT_LT(coarse.finest_positions.col(2).minCoeff(), 0.0);
}

class MethodResume : public ::testing::TestWithParam<const char*> {};

TEST_P(MethodResume, AJobKilledInsideItsSolveResumesToTheUninterruptedAnswerBitForBit) {
  const std::string method = fmt::format("[\"{}\"]", GetParam());
  const MethodWorkspace reference(fmt::format("method_resume_ref_{}", GetParam()), method);
  ASSERT_EQ(reference.run("work"), 0);
  const db::JobResult expected = reference.results().front();
  ASSERT_EQ(expected.job.state, db::JobState::done) << expected.job.error;

  const MethodWorkspace killed(fmt::format("method_resume_{}", GetParam()), method);
  // Two thirds of the way: in the finest level of a progressive job.
  const std::size_t kill_at = 2 * iterations_of(expected) / 3;
  ASSERT_GE(kill_at, 3u);
  EXPECT_EQ(killed.run("work", fmt::format("iteration:{}", kill_at)), 128 + SIGKILL);
  const db::JobResult interrupted = killed.results().front();
  EXPECT_EQ(interrupted.job.state, db::JobState::running);
  ASSERT_FALSE(interrupted.levels.empty());  // a snapshot (or a level) to resume from
  std::this_thread::sleep_for(std::chrono::duration<double>(kLease * 1.3));
  ASSERT_EQ(killed.run("resume"), 0);

  const db::JobResult resumed = killed.results().front();
  ASSERT_EQ(resumed.job.state, db::JobState::done) << resumed.job.error;
  EXPECT_EQ(resumed.job.method, expected.job.method);
  ASSERT_EQ(resumed.levels.size(), expected.levels.size());
  const Checkpoint a = last_checkpoint(resumed);
  const Checkpoint b = last_checkpoint(expected);
  EXPECT_EQ(largest_difference(flat(a.positions), flat(b.positions)), 0.0);
  EXPECT_EQ(largest_difference(flat(a.finest_positions), flat(b.finest_positions)), 0.0);
}

INSTANTIATE_TEST_SUITE_P(Methods, MethodResume,
                         ::testing::Values("direct", "direct_final", "progressive",
                                           "coarse_prolonged"));

}  // namespace
}  // namespace psq
