#include "runner/slurm_cluster.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <regex>
#include <sstream>
#include <thread>

#include "db/job_store.hpp"
#include "support/test_paths.hpp"

namespace psq::test {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

const char* const kFourCantilevers =
    "\"shell.strip.material.thickness\" = [5e-4, 6e-4, 7e-4, 8e-4]\n"
    "\"shell.strip.material.youngs_modulus\" = [5e6]\n"
    "\"time.frames\" = [200]\n";

SlurmSweep::SlurmSweep(const std::string& name, const std::string& grid)
    : CantileverWorkspace(name) {
  const ProcessResult added = add_sweep("k", grid);
  EXPECT_EQ(added.exit_code, 0) << added.errors;
}

Checkpoint SlurmSweep::final_checkpoint(const std::string& job) const {
  return read_checkpoint(dir / "runs" / job / "level_0.h5");
}

ProcessResult run(const std::string& program, const std::vector<std::string>& arguments) {
  return run_process(program, arguments);
}

namespace {

bool node_ready() {
  const std::string state =
      run("/usr/bin/sinfo", {"--noheader", "--nodes=localhost", "--format=%T"}).output;
  return state.starts_with("idle") || state.starts_with("mixed") || state.starts_with("allocated");
}

}  // namespace

void require_cluster() {
  if (node_ready()) return;
  const ProcessResult started =
      run((source_dir() / "scripts/slurm-localhost.sh").string(), {"start"});
  ASSERT_EQ(started.exit_code, 0) << "the localhost SLURM cluster did not start (run as root; see "
                                     "scripts/slurm-localhost.sh):\n"
                                  << started.output << started.errors;
  ASSERT_TRUE(node_ready());
}

std::map<std::string, Seen> task_states(const std::string& array_id) {
  const ProcessResult q = run("/usr/bin/squeue", {"--noheader", "--array", "--states=all",
                                                  "--jobs=" + array_id, "--format=%i %T %r"});
  std::map<std::string, Seen> states;
  std::istringstream lines(q.output);
  for (std::string task, state, reason; lines >> task >> state >> reason;)
    states[task] = {state, reason};
  return states;
}

bool is_live(const std::string& state) {
  // SIGNALING: a running task while slurmctld delivers its --signal warning.
  return state == "PENDING" || state == "RUNNING" || state == "COMPLETING" || state == "REQUEUED" ||
         state == "CONFIGURING" || state == "SIGNALING";
}

bool array_ended(const std::string& array_id) {
  const std::map<std::string, Seen> states = task_states(array_id);
  // An array squeue does not list (it failed, say, under load) has not been seen to end.
  if (states.empty()) return false;
  for (const auto& [name, seen] : states)
    if (is_live(seen.state)) return false;
  return true;
}

/// A requeued task waits two minutes (SLURM's requeue delay); an administrator may start it
/// sooner, but not within the second of the requeue: slurmd refuses a launch whose credential
/// is no newer than the revoked one of the killed instance ("Job credential revoked").
void start_requeued_now(const std::string& array_id) {
  static std::map<std::string, Clock::time_point> first_seen;
  for (const auto& [task, seen] : task_states(array_id)) {
    if (seen.state != "PENDING" || seen.reason != "BeginTime") {
      first_seen.erase(task);
      continue;
    }
    const auto [at, added] = first_seen.emplace(task, Clock::now());
    if (Clock::now() - at->second > std::chrono::seconds(3)) {
      run("/usr/bin/scontrol", {"update", "JobId=" + task, "StartTime=now"});
      first_seen.erase(at);
    }
  }
}

void wait_until(const std::function<bool()>& done, double seconds, const std::string& what,
                const std::string& array_id) {
  const auto deadline = Clock::now() + std::chrono::duration<double>(seconds);
  while (!done()) {
    ASSERT_LT(Clock::now(), deadline) << "timed out waiting for " << what;
    start_requeued_now(array_id);
    std::this_thread::sleep_for(std::chrono::milliseconds(200));
  }
}

std::string submitted_array(const ProcessResult& submit) {
  std::smatch match;
  EXPECT_TRUE(std::regex_search(submit.output, match, std::regex("array job ([0-9]+)")))
      << submit.output << submit.errors;
  return match.size() > 1 ? match[1].str() : "";
}

std::string all_task_logs(const SlurmSweep& sweep) {
  std::string text;
  for (const auto& entry : fs::recursive_directory_iterator(sweep.dir / "slurm"))
    if (entry.path().extension() == ".log") text += read_file(entry.path());
  return text;
}

std::size_t count(const std::string& text, const std::string& what) {
  std::size_t n = 0;
  for (auto at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

void expect_equal_to_local_run(const SlurmSweep& cluster, const SlurmSweep& local) {
  const std::vector<db::JobResult> expected = local.results();
  const std::vector<db::JobResult> actual = cluster.results();
  ASSERT_EQ(actual.size(), expected.size());
  for (std::size_t j = 0; j < actual.size(); ++j) {
    SCOPED_TRACE(actual[j].job.id);
    ASSERT_EQ(actual[j].job.id, expected[j].job.id);
    EXPECT_EQ(actual[j].job.state, db::JobState::done) << actual[j].job.error;
    ASSERT_EQ(actual[j].levels.size(), expected[j].levels.size());
    for (std::size_t l = 0; l < actual[j].levels.size(); ++l) {
      EXPECT_EQ(actual[j].levels[l].status, db::LevelStatus::done);
      EXPECT_EQ(actual[j].levels[l].iterations, expected[j].levels[l].iterations);
      ASSERT_EQ(actual[j].levels[l].residuals.size(), expected[j].levels[l].residuals.size());
      for (std::size_t k = 0; k < actual[j].levels[l].residuals.size(); ++k)
        EXPECT_NEAR(actual[j].levels[l].residuals[k], expected[j].levels[l].residuals[k],
                    1e-9 * (1.0 + std::abs(expected[j].levels[l].residuals[k])));
    }
    const Checkpoint a = cluster.final_checkpoint(actual[j].job.id);
    const Checkpoint b = local.final_checkpoint(expected[j].job.id);
    ASSERT_EQ(a.positions.rows(), b.positions.rows());
    EXPECT_LE((a.positions - b.positions).cwiseAbs().maxCoeff(), 1e-12);
  }
}

}  // namespace psq::test
