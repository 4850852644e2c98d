// `psq sweep add FILE [--dry-run]`: expands a sweep file and adds its new jobs to the store.
// The file is read and every job validated before the store is opened, so a bad file changes
// nothing; the addition itself is one transaction.

#include <fmt/format.h>

#include <iostream>

#include "db/job_store.hpp"
#include "jobs/sweep_file.hpp"
#include "runner/commands.hpp"
#include "runner/workspace.hpp"

namespace psq::runner {
namespace {

struct SweepAddOptions {
  std::string file;
  std::string database;
  bool dry_run = false;
};

/// What adding would do without touching the store; a store that does not exist yet is not
/// created (every job is new).
db::SweepAddition preview(const std::filesystem::path& database, const jobs::Sweep& sweep,
                          const std::vector<db::NewJob>& jobs) {
  if (!std::filesystem::exists(database)) {
    db::SweepAddition addition;
    for (const db::NewJob& job : jobs) addition.added.push_back(job.id);
    return addition;
  }
  return db::JobStore(database).preview_sweep(sweep.name, jobs);
}

void print_addition(const jobs::Sweep& sweep, const db::SweepAddition& addition, bool dry_run) {
  std::map<std::string, const jobs::SweepJob*> by_id;
  for (const jobs::SweepJob& job : sweep.jobs) by_id[job.id] = &job;
  std::cout << fmt::format("sweep '{}' ({} jobs): {} {}, {} already present{}\n", sweep.name,
                           sweep.jobs.size(), addition.added.size(),
                           dry_run ? "would be added" : "added", addition.already_present,
                           dry_run ? " (dry run: nothing written)" : "");
  if (sweep.refine.previews()) std::cout << "  " << db::describe(sweep.refine) << '\n';
  for (const std::string& id : addition.added)
    std::cout << fmt::format("  + {}  {}\n", id, jobs::describe_parameters(*by_id.at(id)));
}

int run_sweep_add(const SweepAddOptions& options) {
  const jobs::Sweep sweep = jobs::read_sweep(options.file);
  const std::vector<db::NewJob> jobs = jobs::new_jobs(sweep);
  const std::filesystem::path database = database_path(options.database);
  const db::SweepAddition addition =
      options.dry_run ? preview(database, sweep, jobs)
                      : db::JobStore(database).add_sweep(sweep.name, sweep.file.string(), jobs,
                                                         sweep.refine);
  print_addition(sweep, addition, options.dry_run);
  return 0;
}

}  // namespace

void register_sweep_command(CLI::App& app, std::vector<Command>& commands) {
  CLI::App* sweep = app.add_subcommand("sweep", "Manage parameter sweeps");
  sweep->require_subcommand(1);
  auto options = std::make_shared<SweepAddOptions>();
  CLI::App* add = sweep->add_subcommand(
      "add", "Add the jobs of a sweep file (docs/sweep-format.md) that are not stored yet");
  add->add_option("file", options->file, "Sweep file (TOML)")->required();
  add->add_flag("--dry-run", options->dry_run, "Show what would be added; write nothing");
  add_database_option(*add, options->database);
  commands.push_back({add, [options] { return run_sweep_add(*options); }});
}

}  // namespace psq::runner
