// `psq cancel SWEEP|JOB`: cancels the queued and running jobs of a sweep, or one job by its id.

#include <fmt/format.h>

#include "runner/commands.hpp"
#include "runner/workspace.hpp"

namespace psq::runner {

void register_cancel_command(CLI::App& app, std::vector<Command>& commands) {
  register_sweep_or_job_command(
      app, commands, "cancel", "Cancel the queued and running jobs of a sweep, or one job",
      [](db::JobStore& store, const db::JobSelection& jobs, const std::string& target) {
        const std::int64_t cancelled = store.cancel(jobs);
        return fmt::format(
            "cancelled {} job{} of '{}' (queued or running; running ones stop at their next "
            "heartbeat)",
            cancelled, cancelled == 1 ? "" : "s", target);
      });
}

}  // namespace psq::runner
