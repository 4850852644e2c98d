// `psq retry SWEEP|JOB`: failed and cancelled jobs back in the queue, then run.

#include <gtest/gtest.h>

#include "db/job_store.hpp"
#include "support/run_process.hpp"
#include "support/test_paths.hpp"

namespace psq {
namespace {

namespace fs = std::filesystem;

TEST(RetryCommand, RequeuesFailedAndCancelledJobsWhichThenRun) {
  const fs::path dir = test::fresh_temp_dir("retry_command");
  const fs::path db = dir / "psq.db";
  const auto psq = [&](std::vector<std::string> arguments) {
    arguments.insert(arguments.end(), {"--db", db.string()});
    return test::run_psq(arguments);
  };
  fs::copy_file(test::source_dir() / "jobs/scenes/cantilever.toml", dir / "scene.toml");
  // Two iterations cannot reach a tolerance of 1e-30 m/s: the first job fails for good.
  test::write_file(dir / "sweep.toml",
                   "name = \"t\"\nscene = \"scene.toml\"\n[grid]\n"
                   "\"time.frames\" = [2]\n[[zip]]\n"
                   "\"solver.max_iterations\" = [2, 50]\n"
                   "\"solver.tolerance\" = [1e-30, 1e-5]\n");
  ASSERT_EQ(psq({"sweep", "add", (dir / "sweep.toml").string()}).exit_code, 0);
  std::vector<db::JobResult> jobs = db::JobStore(db).results(db::JobSelection::all());
  ASSERT_EQ(psq({"cancel", jobs[1].job.id}).exit_code, 0);
  const auto work = psq({"work", "--workers", "1"});
  EXPECT_EQ(work.exit_code, 5) << work.errors;  // a job failed
  jobs = db::JobStore(db).results(db::JobSelection::all());
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
