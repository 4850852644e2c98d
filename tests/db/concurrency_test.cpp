// Several processes on one store, and processes killed with SIGKILL in the middle of their
// work: the store must stay sound and every job must end up done exactly once.

#include <gtest/gtest.h>
#include <sqlite3.h>

#include <chrono>
#include <fstream>
#include <map>
#include <random>
#include <string>
#include <thread>

#include "child_process.hpp"
#include "db/job_store.hpp"
#include "db/schema.hpp"
#include "store_fixtures.hpp"
#include "support/test_paths.hpp"

namespace psq::db {
namespace {

using test::ChildProcess;
using test::exited_cleanly;
using test::ManualClock;
using test::Pipe;
using test::thickness_jobs;
using test::worker;

double wall_clock() {
  return std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch())
      .count();
}

/// A worker's loop: claim, record every level, finish, until no job is queued. Appends the id
/// of every job it finished to `finished_log`. A lost lease (the job was reclaimed meanwhile)
/// abandons that job only, as psq work does.
void work_until_empty(JobStore& store, const std::string& id, double lease_seconds,
                      const std::filesystem::path& finished_log) {
  std::ofstream finished(finished_log, std::ios::app);
  while (const auto claim = store.claim_next(worker(id), lease_seconds)) {
    try {
      for (int level = 0; level < claim->job.depth; ++level) {
        LevelRecord record;
        record.level = level;
        record.status = LevelStatus::done;
        record.iterations = level + 1;
        record.residuals = {1.0, 0.1 / (level + 1)};
        store.record_level(claim->lease, record);
      }
      store.finish(claim->lease, Outcome::done);
      finished << claim->job.id << std::endl;
    } catch (const LeaseLostError&) {
    }
  }
}

/// How many times each job id was logged as finished, over every log in `dir`.
std::map<std::string, int> finished_counts(const std::filesystem::path& dir) {
  std::map<std::string, int> counts;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    if (entry.path().extension() != ".log") continue;
    std::ifstream log(entry.path());
    for (std::string id; std::getline(log, id);) ++counts[id];
  }
  return counts;
}

void expect_every_job_done_by_its_last_attempt(JobStore& store, std::size_t job_count) {
  const auto results = store.results(JobSelection::all());
  ASSERT_EQ(results.size(), job_count);
  for (const auto& result : results) {
    EXPECT_EQ(result.job.state, JobState::done) << result.job.id;
    ASSERT_EQ(result.levels.size(), static_cast<std::size_t>(result.job.depth)) << result.job.id;
    for (const auto& level : result.levels)
      EXPECT_EQ(level.attempt, result.job.attempt) << result.job.id << " level " << level.level;
  }
}

TEST(JobStoreConcurrency, WorkerProcessesRunEveryJobExactlyOnce) {
  const auto dir = psq::test::fresh_temp_dir("db-workers");
  const auto path = dir / "psq.db";
  constexpr int kJobs = 60;
  constexpr int kWorkers = 4;
  { JobStore(path).add_sweep("s", "s.toml", thickness_jobs(0, kJobs)); }

  std::vector<ChildProcess> workers;
  for (int w = 0; w < kWorkers; ++w)
    workers.emplace_back([&, w] {
      JobStore store(path);
      work_until_empty(store, "worker-" + std::to_string(w), 60,
                       dir / ("worker-" + std::to_string(w) + ".log"));
    });
  for (auto& child : workers) EXPECT_TRUE(exited_cleanly(child.wait()));

  const auto counts = finished_counts(dir);
  EXPECT_EQ(counts.size(), static_cast<std::size_t>(kJobs));
  for (const auto& [id, times] : counts) EXPECT_EQ(times, 1) << id;
  JobStore store(path);
  expect_every_job_done_by_its_last_attempt(store, kJobs);
  for (const auto& result : store.results(JobSelection::all()))
    EXPECT_EQ(result.job.attempt, 1) << result.job.id;  // claimed once: no lease ever expired
  EXPECT_TRUE(store.integrity_problems().empty());
}

TEST(JobStoreConcurrency, SimultaneousFirstOpensMigrateOnceAndMergeSweeps) {
  const auto path = psq::test::fresh_temp_dir("db-first-open") / ".psq" / "psq.db";
  std::vector<ChildProcess> openers;
  for (int i = 0; i < 4; ++i)
    openers.emplace_back(
        [&, i] { JobStore(path).add_sweep("s", "s.toml", thickness_jobs(2 * i, 4)); });
  for (auto& child : openers) EXPECT_TRUE(exited_cleanly(child.wait()));

  JobStore store(path);
  EXPECT_EQ(store.status("s").total(), 10);  // jobs 0..9, the overlaps stored once
  SqliteConnection raw(path, 1000);
  auto versions = raw.prepare("SELECT COUNT(*) FROM schema_version");
  ASSERT_TRUE(versions.step());
  EXPECT_EQ(versions.integer(0), latest_schema_version());
}

TEST(JobStoreCrash, KillInsideTheClaimTransactionLosesNothing) {
  const auto path = psq::test::fresh_temp_dir("db-kill") / "psq.db";
  JobStoreOptions impatient;
  impatient.busy_timeout_ms = 200;
  JobStore store(path, impatient);
  store.add_sweep("s", "s.toml", thickness_jobs(0, 1));

  Pipe inside;
  ChildProcess doomed([&] {
    JobStoreOptions options;
    options.inside_claim_transaction = [&] {
      inside.signal();
      ::pause();
    };
    JobStore(path, options).claim_next(worker("doomed"), 30);
  });
  ASSERT_TRUE(inside.await());
  // The child holds the write lock: our own claim must time out rather than interleave.
  try {
    (void)store.claim_next(worker("parent"), 30);
    ADD_FAILURE() << "the child's claim transaction did not hold the write lock";
  } catch (const DatabaseError& e) {
    EXPECT_EQ(e.sqlite_code() & 0xff, SQLITE_BUSY) << e.what();
  }
  const int status = doomed.kill_and_wait();
  ASSERT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == SIGKILL);

  JobStore reopened(path);
  EXPECT_TRUE(reopened.integrity_problems().empty());
  const Job job = *reopened.find_job("job-0000");
  EXPECT_EQ(job.state, JobState::queued);  // the claim was rolled back
  EXPECT_EQ(job.attempt, 0);
  const auto claim = reopened.claim_next(worker("survivor"), 30);
  ASSERT_TRUE(claim);
  EXPECT_EQ(claim->lease.attempt, 1);
}

TEST(JobStoreCrash, JobOfAKilledWorkerIsReclaimedAfterItsLeaseExpires) {
  const auto path = psq::test::fresh_temp_dir("db-kill") / "psq.db";
  { JobStore(path).add_sweep("s", "s.toml", thickness_jobs(0, 1, /*depth=*/2)); }
  Pipe claimed;
  ChildProcess doomed([&] {
    JobStore store(path);
    const auto claim = store.claim_next(worker("doomed"), 30);
    LevelRecord coarse;
    coarse.status = LevelStatus::done;
    coarse.checkpoint_path = "runs/job-0000/level-0.h5";
    store.record_level(claim->lease, coarse);
    claimed.signal();
    ::pause();
  });
  ASSERT_TRUE(claimed.await());
  doomed.kill_and_wait();

  ManualClock clock{wall_clock()};
  JobStore store(path, clock.options());
  EXPECT_TRUE(store.integrity_problems().empty());
  EXPECT_FALSE(store.claim_next(worker("survivor"), 30));  // the lease is still valid
  clock.now += 31;
  const auto claim = store.claim_next(worker("survivor"), 30);
  ASSERT_TRUE(claim);
  EXPECT_EQ(claim->lease.attempt, 2);
  // The dead attempt recorded a new checkpoint: an interruption, not a failure.
  EXPECT_EQ(claim->job.failures, 0);
  EXPECT_TRUE(claim->job.error.empty()) << claim->job.error;
  // What the dead attempt completed is still there to resume from.
  const auto levels = store.results(JobSelection::job("job-0000"))[0].levels;
  ASSERT_EQ(levels.size(), 1u);
  EXPECT_EQ(levels[0].checkpoint_path, "runs/job-0000/level-0.h5");
}

TEST(JobStoreCrash, WorkersKilledAtRandomMomentsLeaveASoundStore) {
  const auto dir = psq::test::fresh_temp_dir("db-random-kill");
  const auto path = dir / "psq.db";
  // Rounds go on until enough workers died mid-work; on a fast machine 150 jobs were all done
  // after 8 kills, so there are enough jobs for the kills not to run out of work.
  constexpr int kJobs = 400;
  constexpr int kWantedKills = 12;
  { JobStore(path).add_sweep("s", "s.toml", thickness_jobs(0, kJobs, 3, /*max_attempts=*/1000)); }

  std::mt19937 random(20240607);
  std::uniform_int_distribution<int> delay_us(0, 30000);
  int killed = 0;
  for (int round = 0; round < 200 && killed < kWantedKills; ++round) {
    std::vector<ChildProcess> workers;
    for (int w = 0; w < 2; ++w) {
      const std::string id = fmt::format("r{}w{}", round, w);
      // A short lease, so that later rounds reclaim what killed workers held.
      workers.emplace_back([&, id] {
        JobStore store(path);
        work_until_empty(store, id, 0.02, dir / (id + ".log"));
      });
    }
    std::this_thread::sleep_for(std::chrono::microseconds(delay_us(random)));
    for (auto& child : workers) {
      const int status = child.kill_and_wait();
      if (WIFSIGNALED(status)) ++killed;
      else EXPECT_TRUE(exited_cleanly(status));
    }
  }
  EXPECT_GE(killed, kWantedKills) << "too few workers were killed for the test to mean anything";

  ManualClock later{wall_clock() + 3600};  // every lease of a killed worker has expired
  JobStore store(path, later.options());
  EXPECT_TRUE(store.integrity_problems().empty());
  work_until_empty(store, "final", 60, dir / "final.log");
  expect_every_job_done_by_its_last_attempt(store, kJobs);
  const auto counts = finished_counts(dir);
  // A worker killed between finishing a job and logging it leaves no line; none has two.
  EXPECT_LE(counts.size(), static_cast<std::size_t>(kJobs));
  for (const auto& [id, times] : counts) EXPECT_EQ(times, 1) << id;
}

}  // namespace
}  // namespace psq::db
