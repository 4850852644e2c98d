// `psq resume [SWEEP]`: puts the interrupted jobs of a sweep (running, but their worker stopped
// heartbeating and the lease expired) back in the queue, without counting a failure, and runs
// the sweep's queued jobs like `psq work`. Released jobs are queued already. Each job continues
// from its last valid checkpoint.

#include <fmt/format.h>

#include <iostream>

#include "db/job_store.hpp"
#include "runner/commands.hpp"
#include "runner/workspace.hpp"

namespace psq::runner {
namespace {

int run_resume(const WorkSettings& settings) {
  const std::filesystem::path database = database_path(settings.database);
  require_database(database);
  const db::JobSelection selection =
      settings.sweep.empty() ? db::JobSelection::all() : db::JobSelection::sweep(settings.sweep);
  const std::int64_t requeued = db::JobStore(database).requeue_interrupted(selection);
  std::cerr << fmt::format("psq resume: {} interrupted job{} back in the queue\n", requeued,
                           requeued == 1 ? "" : "s");
  return run_work(settings);
}

}  // namespace

void register_resume_command(CLI::App& app, std::vector<Command>& commands) {
  auto settings = std::make_shared<WorkSettings>();
  CLI::App* command = app.add_subcommand(
      "resume", "Requeue interrupted jobs (expired leases) and run them from their checkpoints");
  command->add_option("sweep", settings->sweep, "Only this sweep (default: every sweep)");
  add_work_options(*command, *settings);
  commands.push_back({command, [settings] { return run_resume(*settings); }});
}

}  // namespace psq::runner
