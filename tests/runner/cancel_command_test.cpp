// `psq cancel SWEEP|JOB`.

#include <gtest/gtest.h>

#include "db/job_store.hpp"
#include "runner/cantilever_workspace.hpp"
#include "support/run_process.hpp"

namespace psq {
namespace {

/// A workspace with the sweep "c" of three queued jobs.
test::CantileverWorkspace workspace_with_three_jobs() {
  test::CantileverWorkspace workspace("cancel_command");
  EXPECT_EQ(workspace.add_sweep("c", "\"time.frames\" = [2, 3, 4]\n").exit_code, 0);
  return workspace;
}

TEST(CancelCommand, CancelsOneJobByIdThenTheRestOfTheSweep) {
  const test::CantileverWorkspace workspace = workspace_with_three_jobs();
  const std::string first = workspace.results().front().job.id;
  const auto one = workspace.psq({"cancel", first});
  EXPECT_EQ(one.exit_code, 0) << one.errors;
  EXPECT_NE(one.output.find("cancelled 1 job "), std::string::npos) << one.output;
  EXPECT_EQ(workspace.results()[0].job.state, db::JobState::cancelled);
  EXPECT_EQ(workspace.results()[1].job.state, db::JobState::queued);
  const auto rest = workspace.psq({"cancel", "c"});
  EXPECT_NE(rest.output.find("cancelled 2 jobs"), std::string::npos) << rest.output;
  // Nothing is left for a worker.
  const auto work = workspace.psq({"work", "--workers", "1"});
  EXPECT_EQ(work.exit_code, 0);
  for (const db::JobResult& r : workspace.results()) {
    EXPECT_EQ(r.job.state, db::JobState::cancelled);
    EXPECT_TRUE(r.levels.empty());
  }
}

TEST(CancelCommand, UnknownTargetsAreErrors) {
  const test::CantileverWorkspace workspace = workspace_with_three_jobs();
  const auto unknown = workspace.psq({"cancel", "nothing-like-this"});
  EXPECT_EQ(unknown.exit_code, 1);
  EXPECT_NE(unknown.errors.find("'nothing-like-this' is neither a sweep nor a job id"),
            std::string::npos)
      << unknown.errors;
  EXPECT_EQ(test::run_psq({"cancel", "--help"}).exit_code, 0);
  EXPECT_NE(test::run_psq({"cancel"}).exit_code, 0);  // the target is required
}

}  // namespace
}  // namespace psq
