// Claims restricted to a selection, requeueing interrupted jobs without a failure, and the
// progress-aware retry bound: a worker that died counts against it only if its attempt recorded
// no new checkpoint.

#include <gtest/gtest.h>

#include <functional>
#include <string>

#include "db/job_store.hpp"
#include "db/store_fixtures.hpp"
#include "support/test_paths.hpp"

namespace psq::db {
namespace {

constexpr double kLease = 5;

/// A record of `level` with the checkpoint `file` whose checksum is `checksum`.
LevelRecord checkpointed(int level, LevelStatus status, const std::string& file,
                         const std::string& checksum) {
  LevelRecord record;
  record.level = level;
  record.status = status;
  record.checkpoint_path = file;
  record.checkpoint_checksum = checksum;
  return record;
}

/// A store of one job allowing `max_attempts` failed attempts, on a clock moved by hand.
struct OneJob {
  explicit OneJob(int max_attempts)
      : store(psq::test::fresh_temp_dir("requeue") / "psq.db", clock.options()) {
    store.add_sweep("a", "a.toml", test::thickness_jobs(0, 1, 3, max_attempts));
  }
  /// Claims the job; `during` gets the attempt's lease; then its worker dies (the lease
  /// expires unrenewed).
  void attempt_that_dies(const std::function<void(const Lease&)>& during = {}) {
    const auto claim = store.claim_next(test::worker("mortal"), kLease);
    ASSERT_TRUE(claim);
    if (during) during(claim->lease);
    clock.now += kLease + 1;
  }
  /// The job after the next claim has put expired leases back (the claim itself is dropped).
  Job after_reclaim() {
    const auto claim = store.claim_next(test::worker("next"), kLease);
    if (claim) {
      EXPECT_TRUE(store.release(claim->lease));
    }
    return *store.find_job("job-0000");
  }
  test::ManualClock clock;
  JobStore store;
};

bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

TEST(Requeue, ClaimsOnlyTheSelectedSweep) {
  test::ManualClock clock;
  JobStore store(psq::test::fresh_temp_dir("requeue") / "psq.db", clock.options());
  store.add_sweep("a", "a.toml", test::thickness_jobs(0, 2));
  store.add_sweep("b", "b.toml", test::thickness_jobs(2, 2));
  const auto claim = store.claim_next(test::worker("w"), 10, JobSelection::sweep("b"));
  ASSERT_TRUE(claim);
  EXPECT_EQ(claim->job.id, "job-0002");
  EXPECT_THROW(store.claim_next(test::worker("w"), 10, JobSelection::sweep("zzz")), InputError);
  EXPECT_EQ(store.claim_next(test::worker("w"), 10, JobSelection::job("job-0001"))->job.id,
            "job-0001");
}

TEST(Requeue, InterruptedJobsGoBackWithoutAFailureAndLiveOnesStay) {
  test::ManualClock clock;
  JobStore store(psq::test::fresh_temp_dir("requeue") / "psq.db", clock.options());
  store.add_sweep("a", "a.toml", test::thickness_jobs(0, 2));
  const auto dead = store.claim_next(test::worker("dead"), 5);
  clock.now += 3;
  const auto live = store.claim_next(test::worker("live"), 5);
  clock.now += 3;  // dead's lease expired, live's has not
  EXPECT_EQ(store.requeue_interrupted(JobSelection::sweep("a")), 1);
  const Job requeued = *store.find_job(dead->job.id);
  EXPECT_EQ(requeued.state, JobState::queued);
  EXPECT_EQ(requeued.failures, 0);
  EXPECT_TRUE(requeued.lease_owner.empty());
  EXPECT_EQ(store.find_job(live->job.id)->state, JobState::running);
  // The dead attempt's late writes are refused once the job is claimed again.
  ASSERT_TRUE(store.claim_next(test::worker("next"), 5));
  EXPECT_FALSE(store.heartbeat(dead->lease));
  EXPECT_THROW(store.requeue_interrupted(JobSelection::sweep("nope")), InputError);
}

TEST(Requeue, TheRecordSeamRunsInsideTheTransaction) {
  test::ManualClock clock;
  JobStoreOptions options = clock.options();
  int calls = 0;
  options.inside_record_transaction = [&] { ++calls; };
  JobStore store(psq::test::fresh_temp_dir("requeue") / "psq.db", options);
  store.add_sweep("a", "a.toml", test::thickness_jobs(0, 1));
  const auto claim = store.claim_next(test::worker("w"), 5);
  LevelRecord level;
  level.status = LevelStatus::done;
  store.record_level(claim->lease, level);
  EXPECT_EQ(calls, 1);
}

TEST(Requeue, ADeathAfterANewCheckpointCountsNoFailure) {
  OneJob job(3);
  job.attempt_that_dies([&](const Lease& lease) {
    job.store.record_level(lease, checkpointed(0, LevelStatus::running, "snap_0.h5", "s1"));
  });
  const Job requeued = job.after_reclaim();
  EXPECT_EQ(requeued.state, JobState::queued);
  EXPECT_EQ(requeued.attempt, 2);
  EXPECT_EQ(requeued.failures, 0);
  EXPECT_TRUE(requeued.error.empty()) << requeued.error;
}

TEST(Requeue, ADeathWithoutANewCheckpointCountsAFailure) {
  OneJob job(3);
  job.attempt_that_dies([&](const Lease& lease) {
    job.store.record_level(lease, checkpointed(0, LevelStatus::done, "level_0.h5", "c0"));
  });
  // A resumed attempt records the finished level it resumed from again, then dies: the row is
  // rewritten by this attempt but holds no new checkpoint.
  job.attempt_that_dies([&](const Lease& lease) {
    job.store.record_level(lease, checkpointed(0, LevelStatus::done, "level_0.h5", "c0"));
    LevelRecord without_checkpoint;
    without_checkpoint.level = 1;
    without_checkpoint.status = LevelStatus::failed;
    without_checkpoint.error = "a record without a checkpoint is no progress either";
    job.store.record_level(lease, without_checkpoint);
  });
  const Job counted = job.after_reclaim();
  EXPECT_EQ(counted.state, JobState::queued);
  EXPECT_EQ(counted.failures, 1);
  EXPECT_TRUE(contains(counted.error, "attempt 2 by worker mortal stopped sending heartbeats"))
      << counted.error;
  EXPECT_TRUE(contains(counted.error, "its worker died once without progress (no new checkpoint)"))
      << counted.error;
}

TEST(Requeue, MaxAttemptsDeathsWithoutProgressFailTheJobSayingSo) {
  OneJob job(3);
  for (int k = 0; k < 3; ++k) job.attempt_that_dies();
  const Job failed = job.after_reclaim();
  EXPECT_EQ(failed.state, JobState::failed);
  EXPECT_EQ(failed.failures, 3);
  EXPECT_EQ(failed.attempt, 3);  // not claimed again
  EXPECT_TRUE(contains(failed.error,
                       "its worker died 3 times in a row without progress "
                       "(no new checkpoint), which makes 3 of the 3 failed "
                       "attempts allowed"))
      << failed.error;
  EXPECT_TRUE(contains(failed.error, "psq retry")) << failed.error;

  // A retry starts the count afresh.
  EXPECT_EQ(job.store.retry(JobSelection::all()), 1);
  job.attempt_that_dies();
  const Job retried = job.after_reclaim();
  EXPECT_EQ(retried.state, JobState::queued);
  EXPECT_EQ(retried.failures, 1);
  EXPECT_TRUE(contains(retried.error, "died once without progress")) << retried.error;
}

TEST(Requeue, AJobWithProgressEveryAttemptSurvivesManyMoreDeathsThanItsBoundAndFinishes) {
  OneJob job(2);
  for (int k = 1; k <= 10; ++k)
    job.attempt_that_dies([&](const Lease& lease) {
      const int level = (k - 1) / 4;  // four snapshots a level, then the next level
      job.store.record_level(
          lease, checkpointed(level, LevelStatus::running, "snap.h5", fmt::format("s{}", k)));
    });
  const auto last = job.store.claim_next(test::worker("survivor"), kLease);
  ASSERT_TRUE(last);
  EXPECT_EQ(last->lease.attempt, 11);
  EXPECT_EQ(last->job.failures, 0);
  job.store.record_level(last->lease, checkpointed(2, LevelStatus::done, "level_2.h5", "c2"));
  job.store.finish(last->lease, Outcome::done);
  EXPECT_EQ(job.store.find_job("job-0000")->state, JobState::done);
}

TEST(Requeue, ProgressForgivesEarlierDeathsButNotExplicitFailures) {
  OneJob job(3);
  {
    const auto claim = job.store.claim_next(test::worker("w"), kLease);
    ASSERT_TRUE(claim);
    job.store.finish(claim->lease, Outcome::failed, "internal error: boom");
  }
  job.attempt_that_dies();  // no progress: failures 2 of 3
  EXPECT_EQ(job.after_reclaim().failures, 2);
  job.attempt_that_dies([&](const Lease& lease) {
    job.store.record_level(lease, checkpointed(0, LevelStatus::running, "snap_0.h5", "s1"));
  });
  // The checkpoint showed the death before it was an interruption; the explicit failure stays.
  EXPECT_EQ(job.after_reclaim().failures, 1);
  job.attempt_that_dies();
  const Job survived = job.after_reclaim();
  EXPECT_EQ(survived.state, JobState::queued);
  EXPECT_EQ(survived.failures, 2);
  job.attempt_that_dies();
  const Job failed = job.after_reclaim();
  EXPECT_EQ(failed.state, JobState::failed);
  EXPECT_EQ(failed.failures, 3);
  EXPECT_TRUE(contains(failed.error, "died 2 times in a row without progress")) << failed.error;
}

}  // namespace
}  // namespace psq::db
