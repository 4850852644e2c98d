// `psq slurm` against a real time limit on the localhost cluster: a task submitted with
// --time 1 --signal-before 25 gets slurmctld's own warning (SIGUSR1 from its periodic
// time-limit check, not one sent by hand as in slurm_test.cpp) mid-level, checkpoints,
// requeues itself and, run after run, continues from its last checkpoint until its job is
// done, without SLURM ever killing it at the limit.

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <future>
#include <regex>

#include "db/job_store.hpp"
#include "runner/slurm_cluster.hpp"

namespace psq {
namespace {

using test::all_task_logs;
using test::array_ended;
using test::count;
using test::expect_equal_to_local_run;
using test::require_cluster;
using test::run;
using test::SlurmSweep;
using test::submitted_array;
using test::task_states;
using test::wait_until;

/// slurmctld checks time limits every 30 s and sends a --signal warning at the first check
/// that is at most 30 s before it is due, so with --time 1 and --signal-before 25 it comes 5 to
/// 35 s into a run: after the job's first frames (with 30 or more it could come before them),
/// long before SLURM kills at the first check past the minute. A run started a few seconds
/// after the check that warned the run before it is warned at the next check, some 26 s in.
/// This job (about 60 s of one core) outlasts the latest first warning and ends in the second
/// or third run on an idle machine; a busy one only adds runs.
constexpr const char* kLongCantilever =
    "\"shell.strip.material.thickness\" = [6e-4]\n"
    "\"shell.strip.material.youngs_modulus\" = [5e6]\n"
    "\"shell.strip.mesh.edge_length\" = [0.00125]\n"
    "\"time.frames\" = [1000]\n";

/// The frame each run after the first resumed from, in the order of the runs.
std::vector<int> resumed_frames(const std::string& log, const std::string& job) {
  const std::regex resuming("job " + job + R"(: resuming level 0 frame ([0-9]+) from)");
  std::vector<int> frames;
  for (auto it = std::sregex_iterator(log.begin(), log.end(), resuming);
       it != std::sregex_iterator(); ++it)
    frames.push_back(std::stoi((*it)[1].str()));
  return frames;
}

/// How many times SLURM has started the task again (scontrol's Restarts=), or -1.
int restarts(const std::string& task) {
  const std::string shown = run("/usr/bin/scontrol", {"show", "job", task}).output;
  std::smatch match;
  if (!std::regex_search(shown, match, std::regex("Restarts=([0-9]+)"))) return -1;
  return std::stoi(match[1].str());
}

TEST(Slurm, ATaskAtItsTimeLimitCheckpointsRequeuesItselfAndResumesUntilDone) {
  ASSERT_NO_FATAL_FAILURE(require_cluster());
  SlurmSweep local("slurm_time_limit_local", kLongCantilever);
  // The local run goes on while the cluster runs the same job: the test lasts one job, not two.
  std::future<test::ProcessResult> local_work = std::async(std::launch::async, [&] {
    return local.psq({"work", "--workers", "1"});
  });

  SlurmSweep sweep("slurm_time_limit", kLongCantilever);
  const test::ProcessResult submit =
      sweep.psq({"slurm", "submit", "k", "--time", "1", "--signal-before", "25", "--mem", "200M"});
  ASSERT_EQ(submit.exit_code, 0) << submit.errors;
  const std::string array = submitted_array(submit);
  const std::string task = array + "_0";
  const std::vector<db::JobResult> submitted = sweep.results();
  ASSERT_EQ(submitted.size(), 1u);
  const std::string job = submitted[0].job.id;
  // Generous: a busy machine (ctest -j, a build beside it) only adds runs.
  wait_until([&] { return array_ended(array); }, 400, "the task to end", array);
  EXPECT_EQ(task_states(array)[task].state, "COMPLETED");

  const std::string log = all_task_logs(sweep);
  const std::size_t warnings = count(log, "psq slurm task: time limit near; requeueing job");
  EXPECT_GE(warnings, 1u) << "the job ended before its first time-limit warning; make it longer\n"
                          << log;
  EXPECT_EQ(count(log, "DUE TO TIME LIMIT"), 0u) << log;
  EXPECT_EQ(count(log, fmt::format("job {}: stopped on request: checkpoint written", job)),
            warnings)
      << log;
  EXPECT_EQ(restarts(task), static_cast<int>(warnings));
  // Each run continues where the one before it stopped, never from the start.
  const std::vector<int> frames = resumed_frames(log, job);
  EXPECT_EQ(frames.size(), warnings) << log;
  for (std::size_t i = 0; i < frames.size(); ++i)
    EXPECT_GT(frames[i], i == 0 ? 0 : frames[i - 1]) << "run " << i + 2 << "\n" << log;
  EXPECT_EQ(count(log, fmt::format("job {}: done in", job)), 1u) << log;

  const test::ProcessResult sync = sweep.psq({"slurm", "sync", "k"});
  ASSERT_EQ(sync.exit_code, 0) << sync.errors;
  EXPECT_NE(sync.output.find("1 done, 0 failed, 0 queued again, 0 requeued on the cluster"),
            std::string::npos)
      << sync.output;
  const std::optional<db::Job> done = db::JobStore(sweep.db).find_job(job);
  ASSERT_TRUE(done);
  EXPECT_EQ(done->state, db::JobState::done);
  EXPECT_EQ(done->attempt, 1) << "the one submission's claim carried the job through its runs";
  EXPECT_EQ(done->failures, 0);

  const test::ProcessResult work = local_work.get();
  ASSERT_EQ(work.exit_code, 0) << work.errors;
  expect_equal_to_local_run(sweep, local);
}

}  // namespace
}  // namespace psq
