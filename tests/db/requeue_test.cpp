// Claims restricted to a selection, and requeueing interrupted jobs without a failure.

#include <gtest/gtest.h>

#include "db/job_store.hpp"
#include "db/store_fixtures.hpp"
#include "support/test_paths.hpp"

namespace psq::db {
namespace {

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

}  // namespace
}  // namespace psq::db
