#include "runner/workspace.hpp"

#include <fmt/format.h>

#include <cstdlib>
#include <iostream>
#include <memory>

#include "engine/core/error.hpp"

namespace psq::runner {

std::filesystem::path database_path(const std::string& option) {
  if (!option.empty()) return option;
  const char* from_environment = std::getenv("PSQ_DB");
  if (from_environment && *from_environment) return from_environment;
  return std::filesystem::path(".psq") / "psq.db";
}

void add_database_option(CLI::App& command, std::string& path) {
  command.add_option("--db", path,
                     "Job store (SQLite); default $PSQ_DB, else .psq/psq.db in the current "
                     "directory");
}

std::filesystem::path runs_directory(const std::filesystem::path& database) {
  return std::filesystem::absolute(database).parent_path() / "runs";
}

std::filesystem::path hierarchy_cache_directory(const std::filesystem::path& database) {
  return std::filesystem::absolute(database).parent_path() / "cache";
}

void require_database(const std::filesystem::path& database) {
  if (!std::filesystem::exists(database))
    throw InputError(
        fmt::format("{}: no job store here; add a sweep first (psq sweep add FILE) "
                    "or choose the store with --db or PSQ_DB",
                    database.string()));
}

db::JobSelection sweep_or_job(db::JobStore& store, const std::string& target) {
  for (const db::SweepStatus& sweep : store.status())
    if (sweep.name == target) return db::JobSelection::sweep(target);
  if (store.find_job(target)) return db::JobSelection::job(target);
  throw InputError(
      fmt::format("{}: '{}' is neither a sweep nor a job id (psq status lists the "
                  "sweeps, psq results SWEEP their jobs)",
                  store.path().string(), target));
}

void register_sweep_or_job_command(CLI::App& app, std::vector<Command>& commands,
                                   const std::string& name, const std::string& description,
                                   SweepOrJobAction action) {
  struct Options {
    std::string target;
    std::string database;
  };
  auto options = std::make_shared<Options>();
  CLI::App* command = app.add_subcommand(name, description);
  command->add_option("target", options->target, "Sweep name or job id")->required();
  add_database_option(*command, options->database);
  const auto run = [options, action = std::move(action)] {
    const std::filesystem::path database = database_path(options->database);
    require_database(database);
    db::JobStore store(database);
    std::cout << action(store, sweep_or_job(store, options->target), options->target) << '\n';
    return 0;
  };
  commands.push_back({command, run});
}

void add_work_options(CLI::App& command, WorkSettings& settings) {
  add_database_option(command, settings.database);
  command.add_option("--workers", settings.workers, "Worker processes (default: one per core)")
      ->check(CLI::NonNegativeNumber);
  command
      .add_option("--lease", settings.lease_seconds,
                  "Seconds a job stays claimed without a heartbeat (heartbeats every third)")
      ->check(CLI::PositiveNumber);
  command
      .add_option("--snapshot-iterations", settings.snapshot_iterations,
                  "Write an in-level snapshot after this many Newton iterations")
      ->check(CLI::PositiveNumber);
  command
      .add_option("--snapshot-seconds", settings.snapshot_seconds,
                  "...or after this many seconds since the last checkpoint")
      ->check(CLI::PositiveNumber);
  command.add_option("--worker-number", settings.worker_number)
      ->group("")  // internal: set by the supervisor for its worker processes
      ->check(CLI::NonNegativeNumber);
}

}  // namespace psq::runner
