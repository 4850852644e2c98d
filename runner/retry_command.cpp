// `psq retry SWEEP|JOB`: puts the failed and cancelled jobs of a sweep (or one job by its id)
// back in the queue with their failure count reset. They continue from their checkpoints.

#include <fmt/format.h>

#include "runner/commands.hpp"
#include "runner/workspace.hpp"

namespace psq::runner {

void register_retry_command(CLI::App& app, std::vector<Command>& commands) {
  register_sweep_or_job_command(
      app, commands, "retry", "Requeue the failed and cancelled jobs of a sweep, or one job",
      [](db::JobStore& store, const db::JobSelection& jobs, const std::string& target) {
        const std::int64_t requeued = store.retry(jobs, /*include_cancelled=*/true);
        return fmt::format("requeued {} failed or cancelled job{} of '{}'; run psq work", requeued,
                           requeued == 1 ? "" : "s", target);
      });
}

}  // namespace psq::runner
