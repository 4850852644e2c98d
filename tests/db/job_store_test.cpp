#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "db/job_store.hpp"
#include "store_fixtures.hpp"
#include "support/test_paths.hpp"

namespace psq::db {
namespace {

using test::ManualClock;
using test::thickness_jobs;
using test::worker;

std::filesystem::path fresh_store_path() {
  return psq::test::fresh_temp_dir("db-store") / "psq.db";
}

std::vector<std::string> ids(const std::vector<NewJob>& jobs) {
  std::vector<std::string> result;
  for (const auto& job : jobs) result.push_back(job.id);
  return result;
}

/// The columns a refused write must leave alone.
void expect_same_row(const Job& before, const Job& after) {
  EXPECT_EQ(after.state, before.state);
  EXPECT_EQ(after.attempt, before.attempt);
  EXPECT_EQ(after.failures, before.failures);
  EXPECT_EQ(after.lease_owner, before.lease_owner);
  EXPECT_EQ(after.lease_expiry, before.lease_expiry);
  EXPECT_EQ(after.heartbeat_at, before.heartbeat_at);
  EXPECT_EQ(after.error, before.error);
  EXPECT_EQ(after.provenance.ended_at, before.provenance.ended_at);
}

LevelRecord level_record(int level, LevelStatus status, std::int64_t iterations) {
  LevelRecord record;
  record.level = level;
  record.status = status;
  record.iterations = iterations;
  return record;
}

TEST(JobStoreSweeps, AddingASweepTwiceAddsNothingTheSecondTime) {
  JobStore store(fresh_store_path());
  const auto jobs = thickness_jobs(0, 5);
  const auto first = store.add_sweep("thickness", "jobs/sweeps/thickness.toml", jobs);
  EXPECT_EQ(first.added, ids(jobs));
  EXPECT_EQ(first.already_present, 0);
  const auto second = store.add_sweep("thickness", "jobs/sweeps/thickness.toml", jobs);
  EXPECT_TRUE(second.added.empty());
  EXPECT_EQ(second.already_present, 5);
  EXPECT_EQ(store.status("thickness").total(), 5);
  EXPECT_EQ(store.results(JobSelection::all()).size(), 5u);
}

TEST(JobStoreSweeps, ExtendedSweepAddsOnlyTheNewJobs) {
  JobStore store(fresh_store_path());
  store.add_sweep("thickness", "t.toml", thickness_jobs(0, 5));
  const auto extension = store.add_sweep("thickness", "t.toml", thickness_jobs(0, 8));
  EXPECT_EQ(extension.added, ids(thickness_jobs(5, 3)));
  EXPECT_EQ(extension.already_present, 5);
  EXPECT_EQ(store.status("thickness").counts.at(JobState::queued), 8);
}

TEST(JobStoreSweeps, PreviewCountsExactlyWhatAddingWouldAddWithoutWriting) {
  JobStore store(fresh_store_path());
  const auto preview_of_new = store.preview_sweep("thickness", thickness_jobs(0, 4));
  EXPECT_EQ(preview_of_new.added.size(), 4u);
  EXPECT_TRUE(store.status().empty());  // not even the sweep was created

  store.add_sweep("thickness", "t.toml", thickness_jobs(0, 2));
  const auto preview = store.preview_sweep("thickness", thickness_jobs(0, 4));
  EXPECT_EQ(preview.added, ids(thickness_jobs(2, 2)));
  EXPECT_EQ(preview.already_present, 2);
  EXPECT_EQ(store.status("thickness").total(), 2);
  const auto real = store.add_sweep("thickness", "t.toml", thickness_jobs(0, 4));
  EXPECT_EQ(real.added, preview.added);
}

TEST(JobStoreSweeps, JobSharedBySweepsIsStoredOnceAndCountedInBoth) {
  ManualClock clock;
  JobStore store(fresh_store_path(), clock.options());
  store.add_sweep("a", "a.toml", thickness_jobs(0, 4));
  const auto b = store.add_sweep("b", "b.toml", thickness_jobs(2, 4));
  EXPECT_EQ(b.added, ids(thickness_jobs(4, 2)));
  EXPECT_EQ(b.already_present, 2);
  EXPECT_EQ(store.results(JobSelection::all()).size(), 6u);
  EXPECT_EQ(store.results(JobSelection::sweep("b")).size(), 4u);

  // Running the shared job once shows it done in both sweeps.
  for (int i = 0; i < 3; ++i) {
    const auto claim = store.claim_next(worker("w"), 60);
    ASSERT_TRUE(claim);
    store.finish(claim->lease, Outcome::done);
  }
  EXPECT_EQ(store.status("a").counts.at(JobState::done), 3);
  EXPECT_EQ(store.status("b").counts.at(JobState::done), 1);  // job-0002
  EXPECT_EQ(store.status("b").counts.at(JobState::queued), 3);
}

TEST(JobStoreSweeps, SameIdWithOtherParametersIsRefused) {
  JobStore store(fresh_store_path());
  store.add_sweep("s", "s.toml", thickness_jobs(0, 1));
  auto impostor = thickness_jobs(0, 1);
  impostor[0].parameters["thickness"] = 0.5;
  try {
    store.add_sweep("s", "s.toml", impostor);
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("job-0000"), std::string::npos) << e.what();
  }
  EXPECT_DOUBLE_EQ(store.find_job("job-0000")->parameters.at("thickness").get<double>(), 1e-3);
}

TEST(JobStoreSweeps, AJobWhoseMethodDoesNotFitItsLevelsIsRefusedAndMethodsAreKept) {
  JobStore store(fresh_store_path());
  auto jobs = thickness_jobs(0, 3, 1);
  jobs[1].method = Method::coarse_prolonged;
  jobs[2].method = Method::progressive;  // with one level
  try {
    store.add_sweep("bad-method", "s.toml", jobs);
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("job-0002: a progressive job solves 2 levels or more, not 1"),
              std::string::npos)
        << message;
  }
  EXPECT_TRUE(store.status().empty());
  jobs.pop_back();
  store.add_sweep("methods", "s.toml", jobs);
  EXPECT_EQ(store.find_job("job-0000")->method, Method::direct);
  EXPECT_EQ(store.find_job("job-0001")->method, Method::coarse_prolonged);
}

TEST(JobStoreSweeps, InvalidJobIsRefusedNamingSweepAndJobAndNothingIsAdded) {
  JobStore store(fresh_store_path());
  auto jobs = thickness_jobs(0, 3);
  jobs[2].depth = 0;
  try {
    store.add_sweep("bad-depth", "s.toml", jobs);
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("bad-depth"), std::string::npos) << message;
    EXPECT_NE(message.find("job-0002"), std::string::npos) << message;
    EXPECT_NE(message.find("depth 0"), std::string::npos) << message;
  }
  EXPECT_TRUE(store.status().empty());
  EXPECT_FALSE(store.find_job("job-0000"));
}

TEST(JobStoreClaims, ClaimsFollowTheSweepOrderAndRecordProvenance) {
  ManualClock clock;
  JobStore store(fresh_store_path(), clock.options());
  store.add_sweep("s", "s.toml", thickness_jobs(0, 2));
  const auto first = store.claim_next(worker("host:1"), 30);
  ASSERT_TRUE(first);
  EXPECT_EQ(first->job.id, "job-0000");
  EXPECT_EQ(first->job.state, JobState::running);
  EXPECT_EQ(first->lease.attempt, 1);
  EXPECT_EQ(first->job.lease_owner, "host:1");
  EXPECT_EQ(first->job.lease_expiry, clock.now + 30);
  EXPECT_EQ(first->job.provenance.host, "testhost");
  EXPECT_EQ(first->job.provenance.code_version, "0.1.0-test");
  EXPECT_EQ(first->job.provenance.started_at, clock.now);
  EXPECT_DOUBLE_EQ(first->job.parameters.at("thickness").get<double>(), 1e-3);

  const auto second = store.claim_next(worker("host:2"), 30);
  ASSERT_TRUE(second);
  EXPECT_EQ(second->job.id, "job-0001");
  EXPECT_FALSE(store.claim_next(worker("host:3"), 30));
  EXPECT_EQ(store.status("s").counts.at(JobState::running), 2);
}

TEST(JobStoreClaims, HeartbeatPushesTheLeaseExpiry) {
  ManualClock clock;
  JobStore store(fresh_store_path(), clock.options());
  store.add_sweep("s", "s.toml", thickness_jobs(0, 1));
  const auto claim = store.claim_next(worker("w"), 30);
  ASSERT_TRUE(claim);
  clock.now += 20;
  EXPECT_TRUE(store.heartbeat(claim->lease));
  EXPECT_EQ(store.find_job("job-0000")->lease_expiry, clock.now + 30);
  EXPECT_EQ(store.find_job("job-0000")->heartbeat_at, clock.now);
  clock.now += 20;  // 40 s after the claim, but only 20 after the heartbeat
  EXPECT_FALSE(store.claim_next(worker("other"), 30));
}

TEST(JobStoreClaims, ExpiredLeaseIsReclaimedWithAHigherAttemptAndCountsAFailure) {
  ManualClock clock;
  JobStore store(fresh_store_path(), clock.options());
  store.add_sweep("s", "s.toml", thickness_jobs(0, 1));
  const auto dead = store.claim_next(worker("dead"), 30);
  ASSERT_TRUE(dead);
  clock.now += 29;
  EXPECT_FALSE(store.claim_next(worker("live"), 30));  // lease still valid
  clock.now += 2;
  EXPECT_EQ(store.status("s").expired_leases, 1);
  const auto reclaimed = store.claim_next(worker("live"), 30);
  ASSERT_TRUE(reclaimed);
  EXPECT_EQ(reclaimed->job.id, "job-0000");
  EXPECT_EQ(reclaimed->lease.attempt, 2);
  EXPECT_EQ(reclaimed->job.failures, 1);
  EXPECT_EQ(reclaimed->job.lease_owner, "live");
  EXPECT_NE(reclaimed->job.error.find("worker dead stopped sending heartbeats"),
            std::string::npos)
      << reclaimed->job.error;
  EXPECT_EQ(store.status("s").expired_leases, 0);
}

TEST(JobStoreClaims, LateHeartbeatKeepsTheJobWhileNobodyReclaimedIt) {
  // Expiry alone does not fence: only a new claim does (docs/job-store.md).
  ManualClock clock;
  JobStore store(fresh_store_path(), clock.options());
  store.add_sweep("s", "s.toml", thickness_jobs(0, 1));
  const auto slow = store.claim_next(worker("slow"), 30);
  ASSERT_TRUE(slow);
  clock.now += 45;
  EXPECT_TRUE(store.heartbeat(slow->lease));
  EXPECT_FALSE(store.claim_next(worker("other"), 30));
  store.finish(slow->lease, Outcome::done);
  EXPECT_EQ(store.find_job("job-0000")->state, JobState::done);
}

TEST(JobStoreFencing, StaleAttemptCannotChangeAnything) {
  ManualClock clock;
  JobStore store(fresh_store_path(), clock.options());
  store.add_sweep("s", "s.toml", thickness_jobs(0, 1));
  const auto stale = store.claim_next(worker("stale"), 30);
  ASSERT_TRUE(stale);
  store.record_level(stale->lease, level_record(0, LevelStatus::done, 7));
  clock.now += 31;
  const auto current = store.claim_next(worker("current"), 30);
  ASSERT_TRUE(current);
  ASSERT_EQ(current->lease.attempt, stale->lease.attempt + 1);
  store.record_level(current->lease, level_record(0, LevelStatus::done, 9));

  const Job before = *store.find_job("job-0000");
  clock.now += 1;
  EXPECT_FALSE(store.heartbeat(stale->lease));
  EXPECT_THROW(store.record_level(stale->lease, level_record(0, LevelStatus::failed, 1)),
               LeaseLostError);
  EXPECT_THROW(store.record_level(stale->lease, level_record(1, LevelStatus::done, 1)),
               LeaseLostError);
  EXPECT_THROW(store.finish(stale->lease, Outcome::done), LeaseLostError);
  EXPECT_THROW(store.finish(stale->lease, Outcome::failed, "late"), LeaseLostError);
  EXPECT_FALSE(store.release(stale->lease));
  expect_same_row(before, *store.find_job("job-0000"));
  const auto levels = store.results(JobSelection::job("job-0000")).front().levels;
  ASSERT_EQ(levels.size(), 1u);
  EXPECT_EQ(levels[0].iterations, 9);
  EXPECT_EQ(levels[0].attempt, current->lease.attempt);

  // The current attempt is unaffected by the refused writes.
  EXPECT_TRUE(store.heartbeat(current->lease));
  store.finish(current->lease, Outcome::done);
  EXPECT_EQ(store.find_job("job-0000")->state, JobState::done);
}

TEST(JobStoreFencing, LeaseLostErrorExplainsWhatHappened) {
  ManualClock clock;
  JobStore store(fresh_store_path(), clock.options());
  store.add_sweep("s", "s.toml", thickness_jobs(0, 1));
  const auto claim = store.claim_next(worker("w"), 30);
  ASSERT_TRUE(claim);
  store.cancel(JobSelection::job("job-0000"));
  try {
    store.finish(claim->lease, Outcome::done);
    FAIL() << "expected LeaseLostError";
  } catch (const LeaseLostError& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("job-0000"), std::string::npos) << message;
    EXPECT_NE(message.find("cancelled"), std::string::npos) << message;
  }
}

TEST(JobStoreRetries, FailedAttemptsAreRetriedUpToTheBound) {
  ManualClock clock;
  JobStore store(fresh_store_path(), clock.options());
  store.add_sweep("s", "s.toml", thickness_jobs(0, 1, 3, /*max_attempts=*/2));
  const auto first = store.claim_next(worker("w"), 30);
  ASSERT_TRUE(first);
  store.finish(first->lease, Outcome::failed, "boom 1");
  Job job = *store.find_job("job-0000");
  EXPECT_EQ(job.state, JobState::queued);
  EXPECT_EQ(job.failures, 1);
  EXPECT_EQ(job.error, "boom 1");

  const auto second = store.claim_next(worker("w"), 30);
  ASSERT_TRUE(second);
  EXPECT_EQ(second->lease.attempt, 2);
  store.finish(second->lease, Outcome::failed, "boom 2");
  job = *store.find_job("job-0000");
  EXPECT_EQ(job.state, JobState::failed);
  EXPECT_EQ(job.failures, 2);
  EXPECT_FALSE(store.claim_next(worker("w"), 30));

  const auto failed = store.failures(JobSelection::sweep("s"));
  ASSERT_EQ(failed.size(), 1u);
  EXPECT_EQ(failed[0].error, "boom 2");
}

TEST(JobStoreRetries, ExpiredLeasesCountTowardsTheBound) {
  ManualClock clock;
  JobStore store(fresh_store_path(), clock.options());
  store.add_sweep("s", "s.toml", thickness_jobs(0, 1, 3, /*max_attempts=*/2));
  for (int attempt = 1; attempt <= 2; ++attempt) {
    const auto claim = store.claim_next(worker("crashing"), 30);
    ASSERT_TRUE(claim) << attempt;
    EXPECT_EQ(claim->lease.attempt, attempt);
    clock.now += 31;
  }
  EXPECT_FALSE(store.claim_next(worker("w"), 30));
  const Job job = *store.find_job("job-0000");
  EXPECT_EQ(job.state, JobState::failed);
  EXPECT_EQ(job.failures, 2);
  EXPECT_NE(job.error.find("stopped sending heartbeats"), std::string::npos) << job.error;
}

TEST(JobStoreRetries, PermanentFailureIsNotRetried) {
  ManualClock clock;
  JobStore store(fresh_store_path(), clock.options());
  store.add_sweep("s", "s.toml", thickness_jobs(0, 1, 3, /*max_attempts=*/5));
  const auto claim = store.claim_next(worker("w"), 30);
  ASSERT_TRUE(claim);
  store.finish(claim->lease, Outcome::failed_permanently, "scene.toml:3: negative thickness");
  EXPECT_EQ(store.find_job("job-0000")->state, JobState::failed);
  EXPECT_FALSE(store.claim_next(worker("w"), 30));
}

TEST(JobStoreRetries, ReleaseRequeuesWithoutAFailureAndNeverReusesTheToken) {
  ManualClock clock;
  JobStore store(fresh_store_path(), clock.options());
  store.add_sweep("s", "s.toml", thickness_jobs(0, 1, 3, /*max_attempts=*/1));
  const auto first = store.claim_next(worker("w"), 30);
  ASSERT_TRUE(first);
  EXPECT_TRUE(store.release(first->lease));
  Job job = *store.find_job("job-0000");
  EXPECT_EQ(job.state, JobState::queued);
  EXPECT_EQ(job.failures, 0);
  EXPECT_EQ(job.lease_owner, "");
  EXPECT_FALSE(store.release(first->lease));

  // Even with max_attempts = 1 the released job can run again, with a fresh token.
  const auto second = store.claim_next(worker("w"), 30);
  ASSERT_TRUE(second);
  EXPECT_EQ(second->lease.attempt, 2);
  EXPECT_THROW(store.finish(first->lease, Outcome::done), LeaseLostError);
}

TEST(JobStoreRetries, ReleaseWithAReasonKeepsItUntilTheJobIsDone) {
  ManualClock clock;
  JobStore store(fresh_store_path(), clock.options());
  store.add_sweep("s", "s.toml", thickness_jobs(0, 1, 3, /*max_attempts=*/1));
  const auto first = store.claim_next(worker("w"), 30);
  ASSERT_TRUE(first);
  const std::string reason = "cannot write '/runs/j/level_0.h5': No space left on device";
  EXPECT_TRUE(store.release(first->lease, reason));
  Job job = *store.find_job("job-0000");
  EXPECT_EQ(job.state, JobState::queued);
  EXPECT_EQ(job.failures, 0);
  EXPECT_EQ(job.error, reason);
  ASSERT_EQ(store.failures(JobSelection::all()).size(), 1u);  // psq status shows it

  // A clean release (a stop on request) leaves the reason; finishing clears it.
  const auto second = store.claim_next(worker("w"), 30);
  ASSERT_TRUE(second);
  EXPECT_TRUE(store.release(second->lease));
  EXPECT_EQ(store.find_job("job-0000")->error, reason);
  const auto third = store.claim_next(worker("w"), 30);
  ASSERT_TRUE(third);
  store.finish(third->lease, Outcome::done);
  job = *store.find_job("job-0000");
  EXPECT_EQ(job.state, JobState::done);
  EXPECT_EQ(job.error, "");
  EXPECT_TRUE(store.integrity_problems().empty());
}

TEST(JobStoreRetries, RetryRequeuesFailedJobsWithFailuresReset) {
  ManualClock clock;
  JobStore store(fresh_store_path(), clock.options());
  store.add_sweep("s", "s.toml", thickness_jobs(0, 2, 3, /*max_attempts=*/1));
  const auto claim = store.claim_next(worker("w"), 30);
  ASSERT_TRUE(claim);
  store.finish(claim->lease, Outcome::failed, "diverged");
  store.cancel(JobSelection::job("job-0001"));
  EXPECT_FALSE(store.claim_next(worker("w"), 30));

  EXPECT_EQ(store.retry(JobSelection::sweep("s")), 1);  // the failed one only
  Job job = *store.find_job("job-0000");
  EXPECT_EQ(job.state, JobState::queued);
  EXPECT_EQ(job.failures, 0);
  EXPECT_EQ(job.error, "");
  EXPECT_EQ(store.find_job("job-0001")->state, JobState::cancelled);

  const auto again = store.claim_next(worker("w"), 30);
  ASSERT_TRUE(again);
  EXPECT_EQ(again->lease.attempt, 2);  // the token keeps counting across retries
  EXPECT_EQ(store.retry(JobSelection::all(), /*include_cancelled=*/true), 1);
  EXPECT_EQ(store.find_job("job-0001")->state, JobState::queued);
}

TEST(JobStoreCancel, CancelStopsQueuedAndRunningJobsButNotFinishedOnes) {
  ManualClock clock;
  JobStore store(fresh_store_path(), clock.options());
  store.add_sweep("s", "s.toml", thickness_jobs(0, 4));
  const auto done = store.claim_next(worker("w"), 30);
  ASSERT_TRUE(done);
  store.finish(done->lease, Outcome::done);
  const auto running = store.claim_next(worker("w"), 30);
  ASSERT_TRUE(running);

  EXPECT_EQ(store.cancel(JobSelection::sweep("s")), 3);
  EXPECT_FALSE(store.heartbeat(running->lease));  // how the worker learns it
  EXPECT_THROW(store.record_level(running->lease, level_record(0, LevelStatus::done, 1)),
               LeaseLostError);
  EXPECT_FALSE(store.claim_next(worker("w"), 30));
  const auto counts = store.status("s").counts;
  EXPECT_EQ(counts.at(JobState::done), 1);
  EXPECT_EQ(counts.at(JobState::cancelled), 3);
  EXPECT_EQ(counts.at(JobState::running), 0);
}

TEST(JobStoreCancel, UnknownSweepOrJobIsAnInputErrorListingTheSweeps) {
  JobStore store(fresh_store_path());
  store.add_sweep("materials", "m.toml", thickness_jobs(0, 1));
  store.add_sweep("thickness", "t.toml", thickness_jobs(1, 1));
  try {
    store.cancel(JobSelection::sweep("thicknes"));
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("'thicknes'"), std::string::npos) << message;
    EXPECT_NE(message.find("materials, thickness"), std::string::npos) << message;
  }
  EXPECT_THROW(store.retry(JobSelection::job("job-9999")), InputError);
  EXPECT_THROW(store.status("nope"), InputError);
  EXPECT_EQ(store.status("materials").counts.at(JobState::queued), 1);
}

TEST(JobStoreResults, LevelRecordsRoundTripAndLaterAttemptsReplaceThem) {
  ManualClock clock;
  JobStore store(fresh_store_path(), clock.options());
  store.add_sweep("s", "s.toml", thickness_jobs(0, 2, /*depth=*/2));
  const auto first = store.claim_next(worker("w"), 30);
  ASSERT_TRUE(first);
  LevelRecord coarse = level_record(0, LevelStatus::done, 3);
  coarse.residuals = {1.0, 1e-3, 1e-9};
  coarse.timings = {{"solve", 0.25}, {"checkpoint", 0.01}};
  coarse.static_residuals = {{2, 1e-6}, {3, 2.5e-7}};
  coarse.refinement = {{"expansions", 12.0}, {"final_gap", 1.0 / 3.0}};
  coarse.checkpoint_path = ".psq/runs/job-0000/level-0.h5";
  coarse.checkpoint_checksum = "sha256:abc";
  store.record_level(first->lease, coarse);
  LevelRecord fine = level_record(1, LevelStatus::failed, 2);
  fine.residuals = {1.0, std::nan("")};
  fine.error = "NaN in the gradient";
  store.record_level(first->lease, fine);
  EXPECT_THROW(store.record_level(first->lease, level_record(2, LevelStatus::done, 1)),
               std::invalid_argument);
  store.finish(first->lease, Outcome::failed, "level 1 diverged");

  const auto resumed = store.claim_next(worker("w"), 30);
  ASSERT_TRUE(resumed);
  ASSERT_EQ(resumed->job.id, "job-0000");
  store.record_level(resumed->lease, level_record(1, LevelStatus::done, 4));
  store.finish(resumed->lease, Outcome::done);

  const auto results = store.results(JobSelection::sweep("s"));
  ASSERT_EQ(results.size(), 2u);
  EXPECT_EQ(results[0].job.state, JobState::done);
  EXPECT_EQ(results[0].job.error, "");
  EXPECT_TRUE(results[1].levels.empty());
  const auto& levels = results[0].levels;
  ASSERT_EQ(levels.size(), 2u);
  EXPECT_EQ(levels[0].level, 0);
  EXPECT_EQ(levels[0].status, LevelStatus::done);
  EXPECT_EQ(levels[0].residuals, coarse.residuals);
  EXPECT_EQ(levels[0].timings, coarse.timings);
  EXPECT_EQ(levels[0].static_residuals, coarse.static_residuals);
  EXPECT_EQ(levels[0].refinement, coarse.refinement);
  EXPECT_TRUE(levels[1].refinement.empty());
  EXPECT_EQ(levels[0].checkpoint_path, coarse.checkpoint_path);
  EXPECT_EQ(levels[0].checkpoint_checksum, coarse.checkpoint_checksum);
  EXPECT_EQ(levels[0].attempt, 1);  // written by the first attempt, kept
  EXPECT_EQ(levels[1].status, LevelStatus::done);
  EXPECT_EQ(levels[1].iterations, 4);
  EXPECT_EQ(levels[1].error, "");
  EXPECT_EQ(levels[1].attempt, 2);
}

TEST(JobStoreResults, HierarchyCacheUsesAreKeptPerAttemptInOrderAndFenced) {
  JobStore store(fresh_store_path());
  store.add_sweep("s", "s.toml", thickness_jobs(0, 1));
  const auto first = store.claim_next(worker("a"), 30);
  ASSERT_TRUE(first);
  store.record_hierarchy_uses(first->lease, {{"000000000000000a", false, 4.0},
                                             {"000000000000000b", false, 1.0}});
  ASSERT_TRUE(store.release(first->lease));
  const auto second = store.claim_next(worker("b"), 30);
  ASSERT_TRUE(second);
  store.record_hierarchy_uses(second->lease, {{"000000000000000a", true, 0.5}});
  // The first attempt no longer holds the lease: its late write changes nothing.
  EXPECT_THROW(store.record_hierarchy_uses(first->lease, {{"000000000000000c", true, 0.1}}),
               LeaseLostError);

  const std::vector<HierarchyCacheUse> uses =
      store.results(JobSelection::all()).front().hierarchy_uses;
  ASSERT_EQ(uses.size(), 3u);
  EXPECT_EQ(uses[0].key, "000000000000000a");
  EXPECT_FALSE(uses[0].hit);
  EXPECT_EQ(uses[0].seconds, 4.0);
  EXPECT_EQ(uses[0].attempt, first->lease.attempt);
  EXPECT_EQ(uses[1].key, "000000000000000b");
  EXPECT_TRUE(uses[2].hit);
  EXPECT_EQ(uses[2].seconds, 0.5);
  EXPECT_EQ(uses[2].attempt, second->lease.attempt);
}

TEST(JobStoreResults, NonFiniteResidualsSurviveAsNaN) {
  ManualClock clock;
  JobStore store(fresh_store_path(), clock.options());
  store.add_sweep("s", "s.toml", thickness_jobs(0, 1));
  const auto claim = store.claim_next(worker("w"), 30);
  ASSERT_TRUE(claim);
  LevelRecord record = level_record(0, LevelStatus::failed, 2);
  record.residuals = {0.5, std::nan(""), HUGE_VAL};
  record.static_residuals = {{1, std::nan("")}, {2, 0.5}};
  store.record_level(claim->lease, record);
  const LevelRecord stored = store.results(JobSelection::job("job-0000"))[0].levels[0];
  const auto& residuals = stored.residuals;
  ASSERT_EQ(residuals.size(), 3u);
  EXPECT_EQ(residuals[0], 0.5);
  EXPECT_TRUE(std::isnan(residuals[1]));
  EXPECT_TRUE(std::isnan(residuals[2]));  // JSON has no infinity either
  ASSERT_EQ(stored.static_residuals.size(), 2u);
  EXPECT_EQ(stored.static_residuals[0].first, 1);
  EXPECT_TRUE(std::isnan(stored.static_residuals[0].second));
  EXPECT_EQ(stored.static_residuals[1], std::make_pair(2, 0.5));
}

TEST(JobStoreStatus, CountsEveryStatePerSweep) {
  ManualClock clock;
  JobStore store(fresh_store_path(), clock.options());
  store.add_sweep("a", "a.toml", thickness_jobs(0, 5, 3, /*max_attempts=*/1));
  store.add_sweep("empty", "e.toml", {});
  store.add_sweep("b", "b.toml", thickness_jobs(10, 2));
  // a: job 0 done, job 1 failed, job 2 running, job 3 cancelled, job 4 queued.
  const auto done = store.claim_next(worker("w"), 30);
  ASSERT_TRUE(done);
  store.finish(done->lease, Outcome::done);
  const auto failed = store.claim_next(worker("w"), 30);
  ASSERT_TRUE(failed);
  store.finish(failed->lease, Outcome::failed, "x");
  ASSERT_TRUE(store.claim_next(worker("w"), 30));
  store.cancel(JobSelection::job("job-0003"));

  const auto sweeps = store.status();
  ASSERT_EQ(sweeps.size(), 3u);
  EXPECT_EQ(sweeps[0].name, "a");
  EXPECT_EQ(sweeps[0].source, "a.toml");
  const std::map<JobState, std::int64_t> expected_a{
      {JobState::queued, 1}, {JobState::running, 1}, {JobState::done, 1},
      {JobState::failed, 1}, {JobState::cancelled, 1}, {JobState::previewed, 0}};
  EXPECT_EQ(sweeps[0].counts, expected_a);
  EXPECT_EQ(sweeps[1].name, "empty");
  EXPECT_EQ(sweeps[1].total(), 0);
  EXPECT_EQ(sweeps[1].counts.size(), kAllJobStates.size());
  EXPECT_EQ(sweeps[2].counts.at(JobState::queued), 2);
  EXPECT_EQ(sweeps[2].total(), 2);
  EXPECT_EQ(store.failures(JobSelection::sweep("a")).size(), 1u);
}

}  // namespace
}  // namespace psq::db
