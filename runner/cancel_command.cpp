// `psq cancel SWEEP|JOB`: cancels the queued and running jobs of a sweep, or one job by its id.

#include <fmt/format.h>

#include <iostream>

#include "db/job_store.hpp"
#include "runner/commands.hpp"
#include "runner/workspace.hpp"

namespace psq::runner {
namespace {

struct CancelOptions {
  std::string target;
  std::string database;
};

int run_cancel(const CancelOptions& options) {
  const std::filesystem::path database = database_path(options.database);
  require_database(database);
  db::JobStore store(database);
  const std::int64_t cancelled = store.cancel(sweep_or_job(store, options.target));
  std::cout << fmt::format(
      "cancelled {} job{} of '{}' (queued or running; running ones stop at "
      "their next heartbeat)\n",
      cancelled, cancelled == 1 ? "" : "s", options.target);
  return 0;
}

}  // namespace

void register_cancel_command(CLI::App& app, std::vector<Command>& commands) {
  auto options = std::make_shared<CancelOptions>();
  CLI::App* command =
      app.add_subcommand("cancel", "Cancel the queued and running jobs of a sweep, or one job");
  command->add_option("target", options->target, "Sweep name or job id")->required();
  add_database_option(*command, options->database);
  commands.push_back({command, [options] { return run_cancel(*options); }});
}

}  // namespace psq::runner
