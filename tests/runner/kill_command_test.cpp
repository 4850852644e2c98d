// Real crashes: `psq work` / `psq resume` as child processes, SIGKILLed at more than 20
// moments (inside levels, around checkpoint writes, inside database transactions, at random
// times), resumed each time; afterwards every job is done exactly once and its result equals an
// uninterrupted run's. Also a clean SIGTERM stop, and a second signal that exits at once.

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <set>
#include <thread>

#include "db/job_store.hpp"
#include "engine/io/checkpoint.hpp"
#include "jobs/psq_child.hpp"
#include "runner/cantilever_workspace.hpp"
#include "support/run_process.hpp"
#include "support/test_paths.hpp"

namespace psq {
namespace {

namespace fs = std::filesystem;

constexpr double kLease = 0.4;  // seconds; short, so a killed worker's job is free again soon

/// A workspace with an 8-job sweep of a rubber cantilever (20 to 100 Newton iterations a job).
struct Sweep : test::CantileverWorkspace {
  explicit Sweep(const std::string& name) : CantileverWorkspace(name) {
    const test::ProcessResult added =
        add_sweep("k",
                  "\"shell.strip.material.thickness\" = [5e-4, 6e-4, 7e-4, 8e-4, 9e-4, 1e-3, "
                  "1.2e-3, 1.5e-3]\n"
                  "\"shell.strip.material.youngs_modulus\" = [5e6]\n");
    EXPECT_EQ(added.exit_code, 0) << added.errors;
  }

  std::vector<std::string> work_arguments(const std::string& command) const {
    std::vector<std::string> args{command};
    if (command == "resume") args.push_back("k");
    args.insert(args.end(), {"--db", db.string(), "--workers", "1", "--lease",
                             fmt::format("{}", kLease), "--snapshot-iterations", "3"});
    return args;
  }

  /// Runs `command` to its end with PSQ_TEST_PAUSE_AT = `pause_at` (may be empty).
  int run(const std::string& command, const std::string& pause_at) const {
    test::ChildOptions options;
    if (!pause_at.empty()) options.environment["PSQ_TEST_PAUSE_AT"] = pause_at;
    test::PsqChild child(PSQ_EXECUTABLE, work_arguments(command), dir, options);
    return child.wait();
  }

  Checkpoint final_checkpoint(const std::string& job) const {
    return read_checkpoint(dir / "runs" / job / "level_0.h5");
  }
};

/// The final checkpoints of an uninterrupted run, by job id.
const std::map<std::string, Checkpoint>& reference() {
  static const std::map<std::string, Checkpoint> checkpoints = [] {
    Sweep sweep("kill_reference");
    EXPECT_EQ(sweep.run("work", ""), 0);
    std::map<std::string, Checkpoint> by_id;
    for (const db::JobResult& r : sweep.results())
      by_id[r.job.id] = sweep.final_checkpoint(r.job.id);
    return by_id;
  }();
  return checkpoints;
}

/// Every job done once, with one level record, clean run directories, and the reference
/// result to round-off (positions and the whole iteration history).
void expect_complete_and_equal_to_reference(const Sweep& sweep) {
  db::JobStore store(sweep.db);
  EXPECT_TRUE(store.integrity_problems().empty());
  const std::vector<db::JobResult> results = sweep.results();
  ASSERT_EQ(results.size(), reference().size());
  for (const db::JobResult& r : results) {
    SCOPED_TRACE(r.job.id);
    EXPECT_EQ(r.job.state, db::JobState::done) << r.job.error;
    ASSERT_EQ(r.levels.size(), 1u);
    EXPECT_EQ(r.levels[0].status, db::LevelStatus::done);
    std::set<std::string> files;
    for (const auto& entry : fs::directory_iterator(sweep.dir / "runs" / r.job.id))
      files.insert(entry.path().filename().string());
    EXPECT_EQ(files, (std::set<std::string>{"job.xdmf", "job.strip.xdmf", "level_0.h5",
                                            "level_0.parts.h5"}));
    const Checkpoint c = sweep.final_checkpoint(r.job.id);
    const Checkpoint& expected = reference().at(r.job.id);
    ASSERT_EQ(c.positions.rows(), expected.positions.rows());
    EXPECT_LE((c.positions - expected.positions).cwiseAbs().maxCoeff(), 1e-12);
    ASSERT_EQ(c.statistics.iterations.size(), expected.statistics.iterations.size());
    for (std::size_t k = 0; k < expected.statistics.iterations.size(); ++k) {
      const IterationRecord& a = c.statistics.iterations[k];
      const IterationRecord& b = expected.statistics.iterations[k];
      EXPECT_EQ(a.frame, b.frame);
      EXPECT_EQ(a.iteration, b.iteration);
      EXPECT_NEAR(a.gradient_norm, b.gradient_norm, 1e-9 * (1.0 + std::abs(b.gradient_norm)));
    }
    EXPECT_EQ(
        r.levels[0].iterations,
        std::count_if(expected.statistics.iterations.begin(), expected.statistics.iterations.end(),
                      [](const IterationRecord& it) { return it.step_length > 0; }));
  }
}

void wait_for_lease_expiry() {
  std::this_thread::sleep_for(std::chrono::duration<double>(kLease * 1.3));
}

TEST(Kill, TwentyFiveKillsAndResumesGiveTheUninterruptedResult) {
  ASSERT_EQ(reference().size(), 8u);
  const Sweep sweep("kill_many");
  // Named moments: inside levels (iterations), around snapshot and level checkpoints, inside
  // the claim and level-record transactions, in the heartbeat thread, before finishing.
  const std::vector<std::string> moments{
      "claim_transaction:1", "claimed:1",          "iteration:2",
      "checkpoint_write:1",  "snapshot_written:1", "record_transaction:1",
      "snapshot_recorded:1", "iteration:17",       "record_level:3",
      "snapshot_written:4",  "level_written:1",    "record_transaction:5",
      "level_recorded:1",    "before_finish:1",    "heartbeat:2",
      "claim_transaction:2", "iteration:33",       "checkpoint_write:6",
      "snapshot_recorded:5", "level_written:2",    "before_finish:2"};
  int killed = 0;
  for (const std::string& moment : moments) {
    SCOPED_TRACE(moment);
    const int code = sweep.run("resume", moment + ":kill");
    EXPECT_TRUE(code == 128 + SIGKILL || code == 0) << code;
    killed += code == 128 + SIGKILL;
    wait_for_lease_expiry();
  }
  // Random moments, wherever they fall (solving, writing, committing).
  std::mt19937 random(20240611);
  std::uniform_int_distribution<int> delay_ms(40, 400);
  for (int k = 0; k < 6; ++k) {
    test::PsqChild child(PSQ_EXECUTABLE, sweep.work_arguments("resume"), sweep.dir);
    std::this_thread::sleep_for(std::chrono::milliseconds(delay_ms(random)));
    child.signal(SIGKILL);
    killed += child.wait() == 128 + SIGKILL;
    wait_for_lease_expiry();
  }
  EXPECT_GE(killed, 20) << "the work ran out before the kills did; make the sweep bigger";
  EXPECT_EQ(sweep.run("resume", ""), 0);
  expect_complete_and_equal_to_reference(sweep);
}

TEST(Kill, SigtermCheckpointsReleasesAndTheNextRunFinishesTheSame) {
  const Sweep sweep("kill_sigterm");
  test::ChildOptions options;
  options.environment["PSQ_TEST_PAUSE_AT"] = "iteration:7:stop";
  test::PsqChild child(PSQ_EXECUTABLE, sweep.work_arguments("work"), sweep.dir, options);
  ASSERT_TRUE(child.wait_until_stopped());
  child.signal(SIGTERM);
  child.signal(SIGCONT);
  EXPECT_EQ(child.wait(), 128 + SIGTERM) << child.errors();
  EXPECT_NE(child.errors().find("stopped on request"), std::string::npos) << child.errors();
  const std::vector<db::JobResult> stopped = sweep.results();
  EXPECT_EQ(stopped.front().job.state, db::JobState::queued);  // released, not failed
  EXPECT_EQ(stopped.front().job.failures, 0);
  ASSERT_EQ(stopped.front().levels.size(), 1u);
  EXPECT_EQ(stopped.front().levels[0].status, db::LevelStatus::running);  // the snapshot
  EXPECT_EQ(sweep.run("work", ""), 0);
  expect_complete_and_equal_to_reference(sweep);
}

TEST(Kill, ASecondSignalExitsAtOnceAndTheHeldJobIsResumedLater) {
  const Sweep sweep("kill_second_signal");
  test::ChildOptions options;
  options.environment["PSQ_TEST_PAUSE_AT"] = "iteration:7:stop";
  test::PsqChild child(PSQ_EXECUTABLE, sweep.work_arguments("work"), sweep.dir, options);
  ASSERT_TRUE(child.wait_until_stopped());
  // Two different signals, so that both are pending when the worker continues: the first asks
  // for a clean stop, the second must end the process before that stop runs.
  child.signal(SIGINT);
  child.signal(SIGTERM);
  child.signal(SIGCONT);
  const int code = child.wait();
  EXPECT_TRUE(code == 128 + SIGINT || code == 128 + SIGTERM) << code << child.errors();
  EXPECT_EQ(child.errors().find("stopped on request"), std::string::npos) << child.errors();
  const std::vector<db::JobResult> held = sweep.results();
  EXPECT_EQ(held.front().job.state, db::JobState::running);  // not released: it left at once
  EXPECT_EQ(held.front().job.failures, 0);
  wait_for_lease_expiry();
  EXPECT_EQ(sweep.run("work", ""), 0);
  expect_complete_and_equal_to_reference(sweep);
}

}  // namespace
}  // namespace psq
