// `psq retry SWEEP|JOB`: failed and cancelled jobs back in the queue, then run.

#include <gtest/gtest.h>

#include "db/job_store.hpp"
#include "runner/cantilever_workspace.hpp"
#include "support/run_process.hpp"

namespace psq {
namespace {

namespace fs = std::filesystem;

TEST(RetryCommand, RequeuesFailedAndCancelledJobsWhichThenRun) {
  const test::CantileverWorkspace workspace("retry_command");
  const auto psq = [&](std::vector<std::string> arguments) { return workspace.psq(arguments); };
  const fs::path& db = workspace.db;
  // Two iterations cannot reach a tolerance of 1e-30 m/s: the first job fails for good.
  ASSERT_EQ(workspace
                .add_sweep("t",
                           "\"time.frames\" = [2]\n[[zip]]\n"
                           "\"solver.max_iterations\" = [2, 50]\n"
                           "\"solver.tolerance\" = [1e-30, 1e-5]\n")
                .exit_code,
            0);
  std::vector<db::JobResult> jobs = workspace.results();
  ASSERT_EQ(psq({"cancel", jobs[1].job.id}).exit_code, 0);
  const auto work = psq({"work", "--workers", "1"});
  EXPECT_EQ(work.exit_code, 5) << work.errors;  // a job failed
  jobs = workspace.results();
  EXPECT_EQ(jobs[0].job.state, db::JobState::failed);
  EXPECT_NE(jobs[0].job.error.find("did not converge"), std::string::npos) << jobs[0].job.error;
  EXPECT_EQ(jobs[1].job.state, db::JobState::cancelled);

  const auto retry = psq({"retry", jobs[1].job.id});
  EXPECT_EQ(retry.exit_code, 0) << retry.errors;
  EXPECT_NE(retry.output.find("requeued 1 failed or cancelled job "), std::string::npos)
      << retry.output;
  EXPECT_EQ(psq({"work", "--workers", "1"}).exit_code, 0);
  EXPECT_EQ(db::JobStore(db).find_job(jobs[1].job.id)->state, db::JobState::done);

  const auto sweep = psq({"retry", "t"});
  EXPECT_NE(sweep.output.find("requeued 1 "), std::string::npos) << sweep.output;
  EXPECT_EQ(db::JobStore(db).find_job(jobs[0].job.id)->state, db::JobState::queued);
  EXPECT_EQ(db::JobStore(db).find_job(jobs[0].job.id)->failures, 0);

  const auto unknown = psq({"retry", "nope"});
  EXPECT_EQ(unknown.exit_code, 1);
  EXPECT_NE(unknown.errors.find("neither a sweep nor a job id"), std::string::npos);
  EXPECT_EQ(test::run_psq({"retry", "--help"}).exit_code, 0);
}

}  // namespace
}  // namespace psq
