// `psq resume [SWEEP]`: interrupted jobs (expired leases) back in the queue without a failure
// counted, then run from their checkpoints.

#include <gtest/gtest.h>

#include <thread>

#include "db/job_store.hpp"
#include "runner/cantilever_workspace.hpp"
#include "support/run_process.hpp"

namespace psq {
namespace {

namespace fs = std::filesystem;

TEST(ResumeCommand, RequeuesExpiredJobsOfTheSweepWithoutCountingAFailure) {
  const test::CantileverWorkspace workspace("resume_command");
  const auto psq = [&](std::vector<std::string> arguments) { return workspace.psq(arguments); };
  const fs::path& db = workspace.db;
  ASSERT_EQ(workspace.add_sweep("a", "\"time.frames\" = [2]\n").exit_code, 0);
  ASSERT_EQ(workspace.add_sweep("b", "\"time.frames\" = [3]\n").exit_code, 0);
  {
    // A worker that claimed sweep a's job and vanished.
    db::JobStore store(db);
    ASSERT_TRUE(store.claim_next({"gone:1", "host", "test"}, 0.05, db::JobSelection::sweep("a")));
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(100));
  const auto resume = psq({"resume", "a", "--workers", "1"});
  EXPECT_EQ(resume.exit_code, 0) << resume.errors;
  EXPECT_NE(resume.errors.find("1 interrupted job back in the queue"), std::string::npos)
      << resume.errors;
  db::JobStore store(db);
  const db::JobResult a = store.results(db::JobSelection::sweep("a")).front();
  EXPECT_EQ(a.job.state, db::JobState::done);
  EXPECT_EQ(a.job.failures, 0);
  EXPECT_EQ(a.job.attempt, 2);
  // Only sweep a was run.
  EXPECT_EQ(store.results(db::JobSelection::sweep("b")).front().job.state, db::JobState::queued);

  const auto unknown = psq({"resume", "zzz"});
  EXPECT_EQ(unknown.exit_code, 1);
  EXPECT_NE(unknown.errors.find("no sweep named 'zzz'"), std::string::npos) << unknown.errors;
  EXPECT_EQ(test::run_psq({"resume", "--help"}).exit_code, 0);
}

}  // namespace
}  // namespace psq
