// A disk that fills up or turns read-only under a running `psq work`: the runs directory is a
// small tmpfs (support/small_filesystem.hpp; the tests skip where it cannot be mounted). The
// worker is paused after a recorded snapshot, the fault is made, and the worker continues: its
// next checkpoint cannot be written. Afterwards the recorded checkpoint is intact, the store is
// sound and names the file and the reason on the job, no failure is counted, and once the
// fault is gone a plain `psq work` ends every job exactly as an uninterrupted run does. Also a
// store on the full disk itself: it stays sound, and the job finishes once its lease expires.

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <chrono>
#include <map>
#include <thread>

#include "db/job_store.hpp"
#include "engine/core/checksum.hpp"
#include "engine/io/checkpoint.hpp"
#include "jobs/psq_child.hpp"
#include "runner/cantilever_workspace.hpp"
#include "support/small_filesystem.hpp"

namespace psq {
namespace {

namespace fs = std::filesystem;

constexpr double kLease = 1.0;  // seconds; short, so that a job whose release failed is free soon

/// A rubber cantilever (tens of Newton iterations a job) at depths 1 and 2, snapshotted every 3
/// iterations.
struct Sweep : test::CantileverWorkspace {
  explicit Sweep(const std::string& name, const fs::path& store = "psq.db")
      : CantileverWorkspace(name, store) {
    const test::ProcessResult added = add_sweep(
        "d", "\"shell.strip.material.youngs_modulus\" = [5e6]\ndepth = [1, 2]\n");
    EXPECT_EQ(added.exit_code, 0) << added.errors;
  }

  std::vector<std::string> work_arguments() const {
    return {"work", "--db", db.string(), "--workers", "1", "--snapshot-iterations", "3",
            "--lease", fmt::format("{}", kLease)};
  }

  /// `psq work` to its end; its exit code.
  int work() const {
    test::PsqChild child(PSQ_EXECUTABLE, work_arguments(), dir);
    return child.wait();
  }

  fs::path runs() const { return db.parent_path() / "runs"; }

  /// The final checkpoint of every job, by job id.
  std::map<std::string, Checkpoint> final_checkpoints() const {
    std::map<std::string, Checkpoint> by_id;
    for (const db::JobResult& r : results())
      by_id[r.job.id] = read_checkpoint(runs() / r.job.id / fmt::format("level_{}.h5",
                                                                         r.job.depth - 1));
    return by_id;
  }
};

const std::map<std::string, Checkpoint>& reference() {
  static const std::map<std::string, Checkpoint> checkpoints = [] {
    const Sweep sweep("full_disk_reference");
    EXPECT_EQ(sweep.work(), 0);
    return sweep.final_checkpoints();
  }();
  return checkpoints;
}

/// Every job done with no failure counted, and ended exactly as in the uninterrupted run.
void expect_reference_result(const Sweep& sweep) {
  for (const db::JobResult& r : sweep.results()) {
    EXPECT_EQ(r.job.state, db::JobState::done) << r.job.id;
    EXPECT_EQ(r.job.error, "") << r.job.id;
    EXPECT_EQ(r.job.failures, 0) << r.job.id;
  }
  EXPECT_TRUE(db::JobStore(sweep.db).integrity_problems().empty());
  for (const auto& [id, c] : sweep.final_checkpoints()) {
    const Checkpoint& expected = reference().at(id);
    EXPECT_EQ(c.positions, expected.positions) << id;  // bit for bit
    EXPECT_EQ(c.statistics.iterations.size(), expected.statistics.iterations.size()) << id;
  }
}

enum class Fault { full, read_only };

class FullDisk : public ::testing::TestWithParam<Fault> {
 protected:
  void make(Fault fault) const {
    if (fault == Fault::full) disk_.fill();
    if (fault == Fault::read_only) disk_.set_read_only(true);
  }
  void remove(Fault fault) const {
    if (fault == Fault::full) disk_.free_space();
    if (fault == Fault::read_only) disk_.set_read_only(false);
  }
  static std::string reason(Fault fault) {
    return fault == Fault::full ? "No space left on device" : "Read-only file system";
  }

  const Sweep sweep_{"full_disk"};
  // Ample for the sweep's checkpoints (tens of kB each) until it is filled.
  const test::SmallFilesystem disk_{sweep_.runs(), 8 << 20};
};

TEST_P(FullDisk, TheRecordedCheckpointSurvivesTheAttemptSaysWhyAndTheJobEndsAsIfUninterrupted) {
  ASSERT_EQ(reference().size(), 2u);
  test::ChildOptions options;
  options.environment["PSQ_TEST_PAUSE_AT"] = "snapshot_recorded:2:stop";
  test::PsqChild child(PSQ_EXECUTABLE, sweep_.work_arguments(), sweep_.dir, options);
  ASSERT_TRUE(child.wait_until_stopped()) << child.errors();
  make(GetParam());
  child.signal(SIGCONT);
  EXPECT_EQ(child.wait(), 1) << child.errors();

  const db::JobResult stopped = sweep_.results().front();
  const std::string run_dir = (sweep_.runs() / stopped.job.id).string();
  EXPECT_NE(child.errors().find(run_dir + "/level_0."), std::string::npos) << child.errors();
  EXPECT_NE(child.errors().find(reason(GetParam())), std::string::npos) << child.errors();
  EXPECT_TRUE(db::JobStore(sweep_.db).integrity_problems().empty());
  EXPECT_EQ(stopped.job.state, db::JobState::queued);
  EXPECT_EQ(stopped.job.failures, 0);
  EXPECT_NE(stopped.job.error.find("attempt 1 stopped: "), std::string::npos) << stopped.job.error;
  EXPECT_NE(stopped.job.error.find(run_dir + "/level_0."), std::string::npos) << stopped.job.error;
  EXPECT_NE(stopped.job.error.find(reason(GetParam())), std::string::npos) << stopped.job.error;
  // The last recorded checkpoint (the second snapshot) is in place and verifies against the
  // checksum the store recorded; the failed write left no temporary behind.
  ASSERT_EQ(stopped.levels.size(), 1u);
  const db::LevelRecord& record = stopped.levels[0];
  EXPECT_EQ(record.status, db::LevelStatus::running);
  const auto checksum = parse_checksum(record.checkpoint_checksum);
  ASSERT_TRUE(checksum);
  EXPECT_EQ(read_checkpoint(record.checkpoint_path, *checksum).solver.progress,
            LevelProgress::inside_frame);
  for (const auto& entry : fs::directory_iterator(run_dir))
    EXPECT_FALSE(entry.path().filename().string().starts_with('.')) << entry.path();

  remove(GetParam());
  EXPECT_EQ(sweep_.work(), 0);
  expect_reference_result(sweep_);
}

INSTANTIATE_TEST_SUITE_P(Faults, FullDisk, ::testing::Values(Fault::full, Fault::read_only),
                         [](const auto& info) {
                           return info.param == Fault::full ? "NoSpace" : "ReadOnly";
                         });

TEST(FullDisk, WithTheStoreOnTheFullDiskTooTheStoreStaysSoundAndTheJobFinishesLater) {
  ASSERT_EQ(reference().size(), 2u);
  const fs::path disk_dir = test::fresh_temp_dir("full_disk_store") / "disk";
  const test::SmallFilesystem disk(disk_dir, 8 << 20);
  const Sweep sweep("full_disk_store", disk_dir / "psq.db");
  test::ChildOptions options;
  options.environment["PSQ_TEST_PAUSE_AT"] = "snapshot_recorded:2:stop";
  test::PsqChild child(PSQ_EXECUTABLE, sweep.work_arguments(), sweep.dir, options);
  ASSERT_TRUE(child.wait_until_stopped()) << child.errors();
  disk.fill();
  child.signal(SIGCONT);
  // Whichever write meets the full disk first (a checkpoint, the store's commit of its record,
  // or the release) stops the worker with the reason.
  EXPECT_EQ(child.wait(), 1) << child.errors();
  EXPECT_TRUE(child.errors().find("No space left on device") != std::string::npos ||
              child.errors().find("disk full") != std::string::npos)
      << child.errors();
  disk.free_space();

  EXPECT_TRUE(db::JobStore(sweep.db).integrity_problems().empty());
  // The checkpoint of the store's record survives: under its name, or as the previous snapshot
  // if a newer one was written and its record could not be.
  const db::JobResult stopped = sweep.results().front();
  ASSERT_EQ(stopped.levels.size(), 1u);
  const auto checksum = parse_checksum(stopped.levels[0].checkpoint_checksum);
  ASSERT_TRUE(checksum);
  bool survived = false;
  for (const auto& entry : fs::directory_iterator(sweep.runs() / stopped.job.id))
    survived = survived || file_fnv1a64(entry.path()) == checksum;
  EXPECT_TRUE(survived);

  std::this_thread::sleep_for(std::chrono::duration<double>(kLease * 1.3));
  EXPECT_EQ(sweep.work(), 0);
  expect_reference_result(sweep);
}

}  // namespace
}  // namespace psq
