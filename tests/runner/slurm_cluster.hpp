#pragma once
// What the `psq slurm` tests share: the localhost cluster of scripts/slurm-localhost.sh
// (started if it is not running; a test fails, never skips, when it cannot be), a sweep's
// workspace, the scheduler's view of an array, and the comparison with a local run.

#include <functional>
#include <map>
#include <string>
#include <vector>

#include "engine/io/checkpoint.hpp"
#include "runner/cantilever_workspace.hpp"
#include "support/run_process.hpp"

namespace psq::test {

/// The [grid] of the sweep `k` unless a test gives its own: four cantilevers of 200 frames.
extern const char* const kFourCantilevers;

/// A workspace whose store holds the sweep `k` of `grid`.
struct SlurmSweep : CantileverWorkspace {
  explicit SlurmSweep(const std::string& name, const std::string& grid = kFourCantilevers);
  Checkpoint final_checkpoint(const std::string& job) const;
};

ProcessResult run(const std::string& program, const std::vector<std::string>& arguments);

/// Uses the localhost cluster, starting it (as root) if its node is not ready. Call it under
/// ASSERT_NO_FATAL_FAILURE: a cluster that cannot start fails the test.
void require_cluster();

struct Seen {
  std::string state;
  std::string reason;
};

/// array task name ("A_i") → SLURM state and reason, from squeue.
std::map<std::string, Seen> task_states(const std::string& array_id);

bool is_live(const std::string& state);

/// Whether no task of the array is pending, running or on its way to either.
bool array_ended(const std::string& array_id);

/// Starts the array's tasks that wait out SLURM's requeue delay (see the definition for why
/// not at once).
void start_requeued_now(const std::string& array_id);

/// Polls `done`, starting requeued tasks of the array meanwhile; fails after `seconds`.
void wait_until(const std::function<bool()>& done, double seconds, const std::string& what,
                const std::string& array_id);

/// The array job id that `psq slurm submit` printed ("" and a failure if none).
std::string submitted_array(const ProcessResult& submit);

/// The text of every task log of every submission of the sweep.
std::string all_task_logs(const SlurmSweep& sweep);

std::size_t count(const std::string& text, const std::string& what);

/// Every job done, with the level records and final positions of the same sweep run locally.
void expect_equal_to_local_run(const SlurmSweep& cluster, const SlurmSweep& local);

}  // namespace psq::test
