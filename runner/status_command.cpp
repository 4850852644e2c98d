// `psq status [SWEEP] [--json]`: job counts per state of each sweep, the failures with their
// messages, and the SLURM array tasks holding its jobs as the last `psq slurm sync` saw them.

#include <fmt/format.h>

#include <iostream>
#include <nlohmann/json.hpp>

#include "db/job_store.hpp"
#include "runner/commands.hpp"
#include "runner/slurm_tasks.hpp"
#include "runner/workspace.hpp"

namespace psq::runner {
namespace {

struct StatusOptions {
  std::string sweep;
  std::string database;
  bool json = false;
};

/// One sweep's counts, failures and cluster tasks.
struct SweepReport {
  db::SweepStatus status;
  std::vector<db::Job> failures;
  /// Per SLURM array: how many of its tasks hold a job, by the state SLURM last reported.
  std::map<std::string, std::map<std::string, int>> cluster;
};

std::vector<SweepReport> gather(db::JobStore& store, const std::string& sweep) {
  std::vector<db::SweepStatus> statuses =
      sweep.empty() ? store.status() : std::vector{store.status(sweep)};
  slurm::SlurmTaskTable tasks(store.path());
  std::vector<SweepReport> reports;
  for (db::SweepStatus& status : statuses) {
    std::vector<db::Job> failures = store.failures(db::JobSelection::sweep(status.name));
    std::map<std::string, std::map<std::string, int>> cluster;
    for (const slurm::SlurmTask& task : tasks.holding(status.name))
      ++cluster[task.array_id][task.state];
    reports.push_back({std::move(status), std::move(failures), std::move(cluster)});
  }
  return reports;
}

nlohmann::json to_json(const std::filesystem::path& database,
                       const std::vector<SweepReport>& reports) {
  nlohmann::json sweeps = nlohmann::json::array();
  for (const SweepReport& report : reports) {
    nlohmann::json counts = nlohmann::json::object();
    for (const auto& [state, count] : report.status.counts)
      counts[std::string(db::to_string(state))] = count;
    nlohmann::json failures = nlohmann::json::array();
    for (const db::Job& job : report.failures)
      failures.push_back({{"id", job.id},
                          {"state", db::to_string(job.state)},
                          {"parameters", job.parameters},
                          {"failures", job.failures},
                          {"max_attempts", job.max_attempts},
                          {"error", job.error}});
    nlohmann::json cluster = nlohmann::json::array();
    for (const auto& [array_id, states] : report.cluster)
      cluster.push_back({{"array_id", array_id}, {"tasks", states}});
    sweeps.push_back({{"name", report.status.name},
                      {"source", report.status.source},
                      {"total", report.status.total()},
                      {"counts", counts},
                      {"expired_leases", report.status.expired_leases},
                      {"refine", db::to_json(report.status.refine)},
                      {"failures", failures},
                      {"slurm", cluster}});
  }
  return {{"database", database.string()}, {"sweeps", sweeps}};
}

void print_text(const std::filesystem::path& database, const std::vector<SweepReport>& reports) {
  if (reports.empty()) std::cout << fmt::format("no sweeps in {}\n", database.string());
  for (const SweepReport& report : reports) {
    std::string counts;
    for (const auto& [state, count] : report.status.counts)
      counts += fmt::format("{}{} {}", counts.empty() ? "" : ", ", db::to_string(state), count);
    std::cout << fmt::format("sweep '{}': {} jobs: {}\n", report.status.name, report.status.total(),
                             counts);
    if (report.status.refine.previews())
      std::cout << "  " << db::describe(report.status.refine) << '\n';
    if (report.status.expired_leases > 0)
      std::cout << fmt::format(
          "  {} running jobs stopped sending heartbeats (reclaimed by the "
          "next claim)\n",
          report.status.expired_leases);
    for (const auto& [array_id, states] : report.cluster) {
      std::string tasks;
      for (const auto& [state, count] : states)
        tasks += fmt::format("{}{} {}", tasks.empty() ? "" : ", ", count, state);
      std::cout << fmt::format("  SLURM array {}: {} (as of the last psq slurm sync)\n", array_id,
                               tasks);
    }
    for (const db::Job& job : report.failures)
      std::cout << fmt::format("  {} {} ({}/{} failed attempts) {}: {}\n", db::to_string(job.state),
                               job.id, job.failures, job.max_attempts, job.parameters.dump(),
                               job.error);
  }
}

int run_status(const StatusOptions& options) {
  const std::filesystem::path database = database_path(options.database);
  require_database(database);
  db::JobStore store(database);
  const std::vector<SweepReport> reports = gather(store, options.sweep);
  if (options.json)
    std::cout << to_json(database, reports).dump(2) << '\n';
  else
    print_text(database, reports);
  return 0;
}

}  // namespace

void register_status_command(CLI::App& app, std::vector<Command>& commands) {
  auto options = std::make_shared<StatusOptions>();
  CLI::App* command =
      app.add_subcommand("status", "Job counts per state of each sweep, and failures");
  command->add_option("sweep", options->sweep, "Only this sweep");
  command->add_flag("--json", options->json, "Print JSON instead of text");
  add_database_option(*command, options->database);
  commands.push_back({command, [options] { return run_status(*options); }});
}

}  // namespace psq::runner
