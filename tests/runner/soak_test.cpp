// Crash soak: one sweep worked on by two `psq work` processes on one store at once, whose
// workers are killed at random moments (wherever they fall: Newton iterations, checkpoint and
// snapshot writes, store commits) with SIGKILL, once with SIGTERM and once with SIGINT, each
// stopped process replaced at once, as a machine that kills processes would leave it. No
// `psq resume` and no `psq retry`: the sweep must finish by itself, which only the
// progress-aware retry bound allows (docs/job-store.md). Afterwards every job is done exactly
// once, with one record per level, every checkpoint verifies, and every level's positions
// equal an uninterrupted run's bit for bit.
//
// The reduced soak runs in CI; PSQ_SOAK_KILLS and PSQ_SOAK_SEED make it a full one (the
// command is in docs/job-store.md).

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <csignal>
#include <cstdlib>
#include <iostream>
#include <map>
#include <memory>
#include <random>
#include <regex>
#include <set>
#include <stdexcept>
#include <string>
#include <thread>

#include "db/job_store.hpp"
#include "engine/core/checksum.hpp"
#include "engine/io/checkpoint.hpp"
#include "jobs/psq_child.hpp"
#include "runner/cantilever_workspace.hpp"
#include "support/test_paths.hpp"

namespace psq {
namespace {

namespace fs = std::filesystem;

constexpr double kLease = 0.5;  // seconds: a killed worker's job is free again soon

/// The value of the environment variable `name`, a positive integer, or `fallback` if unset.
int positive_from_environment(const char* name, int fallback) {
  const char* text = std::getenv(name);
  if (!text || !*text) return fallback;
  char* end = nullptr;
  const long value = std::strtol(text, &end, 10);
  if (*end != '\0' || value < 1 || value > 100'000)
    throw std::invalid_argument(
        fmt::format("{}='{}' is not a whole number in [1, 100000]; unset it for the default {}",
                    name, text, fallback));
  return static_cast<int>(value);
}

/// SIGKILLs of the soak: 15 in CI, PSQ_SOAK_KILLS for a full soak.
int kill_count() { return positive_from_environment("PSQ_SOAK_KILLS", 15); }
unsigned seed() { return static_cast<unsigned>(positive_from_environment("PSQ_SOAK_SEED", 1)); }

/// A workspace with the soak sweep: the cantilever over 40 frames (four times the scene's, so
/// that a job lasts through a few signals) at depths 1 and 2, `thicknesses` thicknesses.
struct SoakSweep : test::CantileverWorkspace {
  SoakSweep(const std::string& name, int thicknesses) : CantileverWorkspace(name) {
    std::string values;
    for (int k = 0; k < thicknesses; ++k)
      values += fmt::format("{}{:.1e}", k ? ", " : "", 5e-4 + 1e-4 * k);
    const test::ProcessResult added =
        add_sweep("soak", fmt::format("depth = [1, 2]\n\"shell.strip.material.thickness\" = [{}]\n"
                                      "\"shell.strip.material.youngs_modulus\" = [5e6]\n"
                                      "\"time.frames\" = [40]\n",
                                      values));
    EXPECT_EQ(added.exit_code, 0) << added.errors;
  }

  /// `psq work` as one process with one worker; snapshots every 2 iterations, so that kills
  /// land around snapshot writes and store commits often.
  std::vector<std::string> work_arguments() const {
    return {"work",
            "--db",
            db.string(),
            "--workers",
            "1",
            "--lease",
            fmt::format("{}", kLease),
            "--snapshot-iterations",
            "2"};
  }

  /// Starts `psq work`, its output in a directory of its own (logs/<n>).
  std::unique_ptr<test::PsqChild> start_worker() {
    const fs::path logs = dir / "logs" / fmt::format("{:03}", started++);
    fs::create_directories(logs);
    return std::make_unique<test::PsqChild>(PSQ_EXECUTABLE, work_arguments(), logs);
  }

  /// True once no job is queued or running.
  bool settled() const {
    const std::vector<db::JobResult> jobs = results();
    return std::none_of(jobs.begin(), jobs.end(), [](const db::JobResult& r) {
      return r.job.state == db::JobState::queued || r.job.state == db::JobState::running;
    });
  }

  /// How often each job's "done" line appears in the logs of every process.
  std::map<std::string, int> done_lines() const {
    const std::regex done(R"(job (\S+): done in )");
    std::map<std::string, int> counts;
    for (const auto& entry : fs::recursive_directory_iterator(dir / "logs")) {
      if (entry.path().filename() != "child.err") continue;
      const std::string log = test::read_file(entry.path());
      for (auto it = std::sregex_iterator(log.begin(), log.end(), done);
           it != std::sregex_iterator(); ++it)
        ++counts[(*it)[1]];
    }
    return counts;
  }

  fs::path run_dir(const std::string& job) const { return dir / "runs" / job; }
  int started = 0;
};

std::set<std::string> file_names(const fs::path& dir) {
  std::set<std::string> names;
  for (const auto& entry : fs::directory_iterator(dir)) names.insert(entry.path().filename());
  return names;
}

double max_difference(const Positions& a, const Positions& b) {
  if (a.rows() != b.rows() || a.cols() != b.cols()) return INFINITY;
  return a.rows() == 0 ? 0.0 : (a - b).cwiseAbs().maxCoeff();
}

/// What the signals did.
struct Deliveries {
  int kills = 0;  ///< processes ended by SIGKILL
  int terms = 0;  ///< by SIGTERM (a clean stop: snapshot, release)
  int ints = 0;   ///< by SIGINT (likewise)
};

/// Whether a death of the worker process `pid` now would stop its job at the retry bound: it
/// holds a job (its lease names the process, "host:pid") whose deaths without progress leave
/// no failure to spare.
bool death_would_fail_its_job(const SoakSweep& sweep, pid_t pid) {
  const std::string owner_suffix = fmt::format(":{}", pid);
  for (const db::JobResult& r : sweep.results()) {
    const db::Job& job = r.job;
    if (job.state == db::JobState::running && job.lease_owner.ends_with(owner_suffix))
      return job.failures + 1 >= job.max_attempts;
  }
  return false;
}

/// Freezes `worker` (SIGSTOP) at the first moment its death would be an interruption, not the
/// end of its job; false if it ended by itself meanwhile. Frozen, it cannot claim a job or
/// record a checkpoint between the look at the store and the signal that follows.
///
/// The random delays alone let a slow worker (a sanitizer makes one several times slower) die
/// again and again before its first checkpoint, until the retry bound fails its job, as it
/// rightly does with a crash loop (docs/job-store.md); the soak is about interruptions. A
/// worker whose job is one death from the bound is therefore let go on until its job's next
/// checkpoint forgives the deaths before it, or until it holds another job.
bool freeze_where_death_is_an_interruption(const SoakSweep& sweep, test::PsqChild& worker) {
  for (;;) {
    worker.signal(SIGSTOP);
    if (!worker.wait_until_stopped()) return false;
    if (!death_would_fail_its_job(sweep, worker.pid())) return true;
    worker.signal(SIGCONT);
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
}

/// Keeps two `psq work` processes running on the sweep and ends one of them at random moments:
/// `kills` times with SIGKILL, once with SIGTERM (a third of the way) and once with SIGINT (two
/// thirds). Each ended process is replaced at once. Stops early if the sweep is settled; then
/// lets the two processes end by themselves.
///
/// The one ended is the older of the two: a process just started is still loading its job,
/// and each process lives through two intervals. A death that would fail a job waits for its
/// progress (freeze_where_death_is_an_interruption), so that the schedule is one of
/// interruptions however slowly the workers run.
Deliveries signal_at_random(SoakSweep& sweep, int kills, unsigned seed) {
  std::mt19937 random(seed);
  std::uniform_int_distribution<int> delay_ms(100, 600);
  const int signals = kills + 2;
  const int sigterm_at = signals / 3;
  const int sigint_at = 2 * signals / 3;
  std::array<std::unique_ptr<test::PsqChild>, 2> workers{sweep.start_worker(),
                                                         sweep.start_worker()};
  Deliveries delivered;
  std::size_t older = 0;
  for (int k = 0; k < signals && !sweep.settled(); ++k) {
    std::this_thread::sleep_for(std::chrono::milliseconds(delay_ms(random)));
    const int signal = k == sigterm_at ? SIGTERM : k == sigint_at ? SIGINT : SIGKILL;
    auto& worker = workers[older];
    older = 1 - older;
    if (freeze_where_death_is_an_interruption(sweep, *worker)) {
      worker->signal(signal);
      worker->signal(SIGCONT);  // SIGTERM and SIGINT wait for it; SIGKILL does not
    }
    const int code = worker->wait();
    // 0: the process had ended by itself, the queue being empty for it.
    EXPECT_TRUE(code == 128 + signal || code == 0) << code << worker->errors();
    delivered.kills += signal == SIGKILL && code == 128 + SIGKILL;
    delivered.terms += signal == SIGTERM && code == 128 + SIGTERM;
    delivered.ints += signal == SIGINT && code == 128 + SIGINT;
    worker = sweep.start_worker();
  }
  for (auto& worker : workers) EXPECT_EQ(worker->wait(), 0) << worker->errors();
  return delivered;
}

/// The jobs a killed worker held are reclaimed once their lease has expired: `psq work` again
/// until every job has settled (a run may end while another's lease is still to expire).
void work_until_settled(SoakSweep& sweep) {
  for (int round = 0; round < 20 && !sweep.settled(); ++round) {
    std::this_thread::sleep_for(std::chrono::duration<double>(kLease * 1.5));
    auto worker = sweep.start_worker();
    EXPECT_EQ(worker->wait(), 0) << worker->errors();
  }
}

TEST(Soak, TwoWorkersKilledAtRandomFinishEveryJobOnceWithTheUninterruptedResult) {
  const int kills = kill_count();
  // Enough work for the signals to land while jobs are running: a job takes about 0.5-1.5 s,
  // two run at once, a signal comes every 0.35 s on average.
  const int thicknesses = kills + 4;

  SoakSweep reference("soak_reference", thicknesses);
  ASSERT_EQ(reference.start_worker()->wait(), 0);
  SoakSweep sweep("soak", thicknesses);
  const Deliveries delivered = signal_at_random(sweep, kills, seed());
  work_until_settled(sweep);

  EXPECT_GE(delivered.kills, kills) << "the work ran out before the kills did";
  EXPECT_EQ(delivered.terms, 1);
  EXPECT_EQ(delivered.ints, 1);

  db::JobStore store(sweep.db);
  EXPECT_TRUE(store.integrity_problems().empty());
  const std::vector<db::JobResult> results = sweep.results();
  const std::vector<db::JobResult> expected = reference.results();
  ASSERT_EQ(results.size(), expected.size());
  const std::map<std::string, int> done_lines = sweep.done_lines();
  std::int64_t attempts = 0, failures = 0;
  int done_once = 0;
  double difference = 0.0;
  for (std::size_t j = 0; j < results.size(); ++j) {
    const db::JobResult& r = results[j];
    SCOPED_TRACE(r.job.id);
    ASSERT_EQ(r.job.id, expected[j].job.id);
    attempts += r.job.attempt;
    failures += r.job.failures;
    EXPECT_EQ(r.job.state, db::JobState::done) << r.job.error;
    // A worker killed between finishing a job and logging it leaves no line; none has two.
    const auto lines = done_lines.find(r.job.id);
    EXPECT_LE(lines == done_lines.end() ? 0 : lines->second, 1);
    done_once += r.job.state == db::JobState::done;
    // One record per level, each finished by an attempt of this job, nothing left over.
    ASSERT_EQ(r.levels.size(), static_cast<std::size_t>(r.job.depth));
    EXPECT_EQ(file_names(sweep.run_dir(r.job.id)), file_names(reference.run_dir(r.job.id)));
    for (int l = 0; l < r.job.depth; ++l) {
      const db::LevelRecord& level = r.levels[l];
      EXPECT_EQ(level.level, l);
      EXPECT_EQ(level.status, db::LevelStatus::done);
      EXPECT_LE(level.attempt, r.job.attempt);
      const Checkpoint c =
          read_checkpoint(level.checkpoint_path, parse_checksum(level.checkpoint_checksum));
      const Checkpoint e = read_checkpoint(expected[j].levels[l].checkpoint_path);
      const double level_difference =
          std::max(max_difference(c.positions, e.positions),
                   max_difference(c.finest_positions, e.finest_positions));
      EXPECT_EQ(level_difference, 0.0) << "level " << l;
      // The same Newton records, none repeated or lost across the interruptions.
      ASSERT_EQ(c.statistics.iterations.size(), e.statistics.iterations.size()) << "level " << l;
      for (std::size_t k = 0; k < e.statistics.iterations.size(); ++k) {
        EXPECT_EQ(c.statistics.iterations[k].frame, e.statistics.iterations[k].frame);
        EXPECT_EQ(c.statistics.iterations[k].iteration, e.statistics.iterations[k].iteration);
        EXPECT_EQ(c.statistics.iterations[k].step_length, e.statistics.iterations[k].step_length);
      }
      difference = std::max(difference, level_difference);
    }
  }
  std::cout << fmt::format(
      "soak (seed {}): {} SIGKILLs, {} SIGTERM, {} SIGINT delivered; {} jobs, {} attempts, {} "
      "done exactly once, {} failures counted; max |x - x_uninterrupted| = {}\n",
      seed(), delivered.kills, delivered.terms, delivered.ints, results.size(), attempts, done_once,
      failures, difference);
}

}  // namespace
}  // namespace psq
