// `psq slurm` against the single-node cluster of scripts/slurm-localhost.sh (started here if
// it is not running; this test fails, never skips, when it cannot be). A 4-job sweep runs as
// an array: one task is requeued mid-level (scontrol requeue), one killed mid-level (scancel
// --batch --signal=KILL: no chance to checkpoint; sync requeues it in SLURM), one gets SLURM's
// time-limit warning (SIGUSR1, as --signal=B:USR1@S sends it, here by hand; a real --time in
// slurm_time_limit_test.cpp) mid-level and requeues itself; each continues from its last
// checkpoint, and after sync every job is done once with the result of a local run.
// Bad input: no sbatch, a cluster that does not answer, an unknown partition.

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <regex>

#include "db/job_store.hpp"
#include "runner/slurm_cluster.hpp"
#include "support/test_paths.hpp"

namespace psq {
namespace {

namespace fs = std::filesystem;
using test::all_task_logs;
using test::array_ended;
using test::count;
using test::expect_equal_to_local_run;
using test::is_live;
using test::require_cluster;
using test::run;
using test::SlurmSweep;
using test::submitted_array;
using test::task_states;
using test::wait_until;

/// Every level_0 snapshot or checkpoint of the job: it is mid-level once one exists.
bool has_snapshot(const SlurmSweep& sweep, const std::string& job) {
  return fs::exists(sweep.dir / "runs" / job / "level_0.snapshot.h5");
}

TEST(Slurm, RequeuedKilledAndTimedOutTasksResumeAndSyncToTheLocalResult) {
  ASSERT_NO_FATAL_FAILURE(require_cluster());
  SlurmSweep local("slurm_local");
  const test::ProcessResult work = local.psq({"work", "--workers", "1"});
  ASSERT_EQ(work.exit_code, 0) << work.errors;

  SlurmSweep sweep("slurm_cluster");
  const test::ProcessResult submit =
      sweep.psq({"slurm", "submit", "k", "--partition", "debug", "--max-parallel", "2", "--time",
                 "10", "--mem", "200M", "--snapshot-iterations", "3"});
  ASSERT_EQ(submit.exit_code, 0) << submit.errors;
  const std::string array = submitted_array(submit);
  std::vector<std::string> jobs;
  for (const db::JobResult& r : sweep.results()) {
    EXPECT_EQ(r.job.state, db::JobState::running);
    EXPECT_EQ(r.job.lease_owner, fmt::format("slurm:{}_{}", array, jobs.size()));
    jobs.push_back(r.job.id);
  }
  ASSERT_EQ(jobs.size(), 4u);
  const test::ProcessResult status = sweep.psq({"status", "k"});
  EXPECT_NE(status.output.find("SLURM array " + array + ": 4 PENDING"), std::string::npos)
      << status.output;

  const auto task = [&](int i) { return fmt::format("{}_{}", array, i); };
  // Task 0: requeued by the scheduler mid-level (SIGTERM: it checkpoints, SLURM runs it again).
  wait_until([&] { return has_snapshot(sweep, jobs[0]); }, 60, "task 0 mid-level", array);
  EXPECT_EQ(run("/usr/bin/scontrol", {"requeue", task(0)}).exit_code, 0);
  // Task 1: killed outright mid-level; it resumes from its last periodic snapshot.
  wait_until([&] { return has_snapshot(sweep, jobs[1]); }, 60, "task 1 mid-level", array);
  EXPECT_EQ(run("/usr/bin/scancel", {"--batch", "--signal=KILL", task(1)}).exit_code, 0);
  // Task 2: the warning before its time limit; it checkpoints and requeues itself.
  wait_until([&] { return has_snapshot(sweep, jobs[2]); }, 60, "task 2 mid-level", array);
  EXPECT_EQ(run("/usr/bin/scancel", {"--batch", "--signal=USR1", task(2)}).exit_code, 0);
  wait_until([&] { return array_ended(array); }, 150, "the array to end", array);

  // Sync brings in the three that ended with a result and requeues the killed task in SLURM:
  // the same task, still holding its claim, continues from its checkpoint.
  const test::ProcessResult first_sync = sweep.psq({"slurm", "sync", "k"});
  ASSERT_EQ(first_sync.exit_code, 0) << first_sync.errors;
  EXPECT_NE(first_sync.output.find("3 done, 0 failed, 0 queued again, 1 requeued on the cluster"),
            std::string::npos)
      << first_sync.output;
  EXPECT_NE(first_sync.output.find("SLURM array task " + task(1) + " ended (FAILED"),
            std::string::npos)
      << first_sync.output;
  EXPECT_NE(first_sync.output.find("without a result"), std::string::npos) << first_sync.output;
  const std::optional<db::Job> killed = db::JobStore(sweep.db).find_job(jobs[1]);
  ASSERT_TRUE(killed);
  EXPECT_EQ(killed->state, db::JobState::running);
  EXPECT_EQ(killed->lease_owner, "slurm:" + task(1)) << "the requeued task keeps the claim";
  EXPECT_EQ(killed->failures, 0) << "it made progress before the kill";
  EXPECT_TRUE(is_live(task_states(array)[task(1)].state));

  wait_until([&] { return !is_live(task_states(array)[task(1)].state); }, 90,
             "the requeued task to end", array);
  const test::ProcessResult second_sync = sweep.psq({"slurm", "sync"});
  EXPECT_NE(second_sync.output.find("1 done, 0 failed, 0 queued again, 0 requeued on the cluster"),
            std::string::npos)
      << second_sync.output;

  expect_equal_to_local_run(sweep, local);
  const std::string logs = all_task_logs(sweep);
  for (int i = 0; i < 3; ++i) {
    SCOPED_TRACE(i);
    EXPECT_EQ(count(logs, fmt::format("job {}: resuming level 0", jobs[i])), 1u) << logs;
  }
  for (const std::string& job : jobs)
    EXPECT_EQ(count(logs, fmt::format("job {}: done in", job)), 1u);
  // Each job claimed once, by the one submission: no job needed a second.
  for (const db::JobResult& r : sweep.results()) EXPECT_EQ(r.job.attempt, 1) << r.job.id;
  EXPECT_EQ(std::distance(fs::directory_iterator(sweep.dir / "slurm"), fs::directory_iterator()),
            1);

  // Idempotent: another sync changes nothing.
  const test::ProcessResult third_sync = sweep.psq({"slurm", "sync", "k"});
  EXPECT_NE(third_sync.output.find("0 done, 0 failed, 0 queued again, 0 requeued on the cluster"),
            std::string::npos)
      << third_sync.output;
  expect_equal_to_local_run(sweep, local);
}

TEST(Slurm, SyncCancelsTheTasksOfJobsCancelledInTheStore) {
  ASSERT_NO_FATAL_FAILURE(require_cluster());
  const SlurmSweep sweep("slurm_cancel");
  const test::ProcessResult submit = sweep.psq({"slurm", "submit", "k", "--max-parallel", "1"});
  ASSERT_EQ(submit.exit_code, 0) << submit.errors;
  const std::string array = submitted_array(submit);
  ASSERT_EQ(sweep.psq({"cancel", "k"}).exit_code, 0);
  const test::ProcessResult sync = sweep.psq({"slurm", "sync", "k"});
  ASSERT_EQ(sync.exit_code, 0) << sync.errors;
  EXPECT_EQ(count(sync.output, "cancelled in the store; task cancelled"), 4u) << sync.output;
  wait_until(
      [&] {
        for (const auto& [name, seen] : task_states(array))
          if (seen.state != "CANCELLED") return false;
        return true;
      },
      30, "the tasks to be cancelled", array);
  for (const db::JobResult& r : sweep.results()) EXPECT_EQ(r.job.state, db::JobState::cancelled);
  // Once cancelled, a task is not cancelled again.
  EXPECT_EQ(count(sweep.psq({"slurm", "sync", "k"}).output, "task cancelled"), 0u);
}

/// The store's jobs as text, and whether a submission left files behind.
std::string store_snapshot(const SlurmSweep& sweep) {
  std::string text;
  for (const db::JobResult& r : sweep.results())
    text += fmt::format("{} {} {} {} {}\n", r.job.id, db::to_string(r.job.state), r.job.attempt,
                        r.job.failures, r.levels.size());
  const test::ProcessResult status = sweep.psq({"status", "--json"});
  return text + status.output;
}

void expect_refused(const SlurmSweep& sweep, const test::ProcessResult& result,
                    const std::vector<std::string>& message_parts, const std::string& before) {
  EXPECT_EQ(result.exit_code, 1) << result.output << result.errors;
  for (const std::string& part : message_parts)
    EXPECT_NE(result.errors.find(part), std::string::npos) << result.errors;
  EXPECT_EQ(store_snapshot(sweep), before);
  EXPECT_TRUE(!fs::exists(sweep.dir / "slurm") || fs::is_empty(sweep.dir / "slurm"));
}

TEST(Slurm, FailedSubmissionsSayWhatToFixAndLeaveTheStoreUnchanged) {
  ASSERT_NO_FATAL_FAILURE(require_cluster());
  const SlurmSweep sweep("slurm_bad");
  const std::string before = store_snapshot(sweep);
  const std::vector<std::string> submit{PSQ_EXECUTABLE, "slurm",          "submit", "k",
                                        "--db",         sweep.db.string()};
  const auto with_environment = [&](const std::string& variable) {
    std::vector<std::string> arguments{variable};
    arguments.insert(arguments.end(), submit.begin(), submit.end());
    return run("/usr/bin/env", arguments);
  };

  expect_refused(sweep, with_environment("PATH=/nonexistent"),
                 {"sbatch is not on PATH", "slurm-client"}, before);

  // A configuration whose controller port nobody listens on: the cluster is down.
  std::string conf = test::read_file("/etc/slurm/slurm.conf");
  conf = std::regex_replace(conf, std::regex("SlurmctldHost=localhost"),
                            "SlurmctldHost=localhost\nSlurmctldPort=6999");
  const fs::path down = test::write_file(sweep.dir / "down.conf", conf);
  expect_refused(sweep, with_environment("SLURM_CONF=" + down.string()),
                 {"Unable to contact slurm controller", "scontrol ping"}, before);

  expect_refused(sweep, sweep.psq({"slurm", "submit", "k", "--partition", "nosuchpartition"}),
                 {"nvalid partition", "sinfo --summarize"}, before);

  expect_refused(sweep, sweep.psq({"slurm", "submit", "nosuchsweep"}), {"nosuchsweep"}, before);
}

}  // namespace
}  // namespace psq
