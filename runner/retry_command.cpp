// `psq retry SWEEP|JOB`: puts the failed and cancelled jobs of a sweep (or one job by its id)
// back in the queue with their failure count reset. They continue from their checkpoints.

#include <fmt/format.h>

#include <iostream>

#include "db/job_store.hpp"
#include "runner/commands.hpp"
#include "runner/workspace.hpp"

namespace psq::runner {
namespace {

struct RetryOptions {
  std::string target;
  std::string database;
};

int run_retry(const RetryOptions& options) {
  const std::filesystem::path database = database_path(options.database);
  require_database(database);
  db::JobStore store(database);
  const std::int64_t requeued =
      store.retry(sweep_or_job(store, options.target), /*include_cancelled=*/true);
  std::cout << fmt::format("requeued {} failed or cancelled job{} of '{}'; run psq work\n",
                           requeued, requeued == 1 ? "" : "s", options.target);
  return 0;
}

}  // namespace

void register_retry_command(CLI::App& app, std::vector<Command>& commands) {
  auto options = std::make_shared<RetryOptions>();
  CLI::App* command =
      app.add_subcommand("retry", "Requeue the failed and cancelled jobs of a sweep, or one job");
  command->add_option("target", options->target, "Sweep name or job id")->required();
  add_database_option(*command, options->database);
  commands.push_back({command, [options] { return run_retry(*options); }});
}

}  // namespace psq::runner
