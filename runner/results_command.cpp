// `psq results SWEEP [--csv | --json]`: the jobs of a sweep with their parameters, states and
// per-level records (status, iterations, final residual, time, checkpoint).

#include <fmt/format.h>

#include <iostream>
#include <nlohmann/json.hpp>
#include <set>

#include "db/job_store.hpp"
#include "jobs/job_identity.hpp"
#include "runner/commands.hpp"
#include "runner/workspace.hpp"

namespace psq::runner {
namespace {

struct ResultsOptions {
  std::string sweep;
  std::string database;
  bool csv = false;
  bool json = false;
};

/// A job's parameter overrides by path.
nlohmann::json overrides_of(const db::Job& job) {
  return job.parameters.value("overrides", nlohmann::json::object());
}

/// The overridden parameter paths of any job, sorted: the parameter columns.
std::vector<std::string> parameter_columns(const std::vector<db::JobResult>& results) {
  std::set<std::string> paths;
  for (const db::JobResult& r : results) {
    const nlohmann::json overrides = overrides_of(r.job);
    for (const auto& [path, value] : overrides.items()) paths.insert(path);
  }
  return {paths.begin(), paths.end()};
}

std::string parameter_value(const db::Job& job, const std::string& path) {
  const nlohmann::json overrides = overrides_of(job);
  return overrides.contains(path) ? overrides[path].dump() : "";
}

double timing(const db::LevelRecord& level, const std::string& phase) {
  const auto found = level.timings.find(phase);
  return found == level.timings.end() ? 0.0 : found->second;
}

double final_residual(const db::LevelRecord& level) {
  return level.residuals.empty() ? std::nan("") : level.residuals.back();
}

/// The static residual of the level's last settled frame; NaN when no frame was settled.
double static_residual(const db::LevelRecord& level) {
  return level.static_residuals.empty() ? std::nan("") : level.static_residuals.back().second;
}

nlohmann::json finite_or_null(double value) {
  return std::isfinite(value) ? nlohmann::json(value) : nlohmann::json();
}

/// CSV field: quoted when it holds a comma, quote or line break.
std::string csv_field(const std::string& text) {
  if (text.find_first_of(",\"\n") == std::string::npos) return text;
  std::string quoted = "\"";
  for (char c : text) quoted += c == '"' ? std::string("\"\"") : std::string(1, c);
  return quoted + "\"";
}

void print_csv(const std::vector<db::JobResult>& results) {
  const std::vector<std::string> columns = parameter_columns(results);
  std::cout << "job,state,depth,method";
  for (const std::string& c : columns) std::cout << ',' << csv_field(c);
  std::cout << ",level,level_status,iterations,final_residual,static_residual,wall_seconds,"
               "checkpoint,error\n";
  for (const db::JobResult& r : results) {
    std::string prefix = fmt::format("{},{},{},{}", r.job.id, db::to_string(r.job.state),
                                     r.job.depth, db::to_string(r.job.method));
    for (const std::string& c : columns) prefix += "," + csv_field(parameter_value(r.job, c));
    if (r.levels.empty()) std::cout << prefix << ",,,,,,,," << csv_field(r.job.error) << '\n';
    for (const db::LevelRecord& level : r.levels)
      std::cout << fmt::format("{},{},{},{},{:.6e},{:.6e},{:.3f},{},{}\n", prefix, level.level,
                               db::to_string(level.status), level.iterations, final_residual(level),
                               static_residual(level), timing(level, "wall"),
                               csv_field(level.checkpoint_path),
                               csv_field(level.error.empty() ? r.job.error : level.error));
  }
}

nlohmann::json to_json(const std::string& sweep, const std::vector<db::JobResult>& results) {
  nlohmann::json jobs = nlohmann::json::array();
  for (const db::JobResult& r : results) {
    nlohmann::json levels = nlohmann::json::array();
    for (const db::LevelRecord& level : r.levels) {
      nlohmann::json residuals = nlohmann::json::array();
      for (double value : level.residuals) residuals.push_back(finite_or_null(value));
      nlohmann::json settled = nlohmann::json::array();
      for (const auto& [frame, residual] : level.static_residuals)
        settled.push_back({frame, finite_or_null(residual)});
      levels.push_back({{"level", level.level},
                        {"status", db::to_string(level.status)},
                        {"iterations", level.iterations},
                        {"residuals", residuals},
                        {"static_residual", finite_or_null(static_residual(level))},
                        {"static_residuals", settled},
                        {"timings", level.timings},
                        {"checkpoint", level.checkpoint_path},
                        {"checkpoint_checksum", level.checkpoint_checksum},
                        {"error", level.error},
                        {"attempt", level.attempt},
                        {"outputs", level.outputs}});
    }
    jobs.push_back({{"id", r.job.id},
                    {"state", db::to_string(r.job.state)},
                    {"parameters", r.job.parameters},
                    {"scene", r.job.scene},
                    {"depth", r.job.depth},
                    {"method", db::to_string(r.job.method)},
                    {"attempt", r.job.attempt},
                    {"failures", r.job.failures},
                    {"preview_levels", r.job.preview_levels ? nlohmann::json(*r.job.preview_levels)
                                                             : nlohmann::json()},
                    {"promoted", r.job.promoted},
                    {"error", r.job.error},
                    {"levels", levels}});
  }
  return {{"sweep", sweep}, {"jobs", jobs}};
}

/// How far a coarse-first job runs: "  (preview: 2 levels, promoted)"; empty for the others.
std::string preview_note(const db::Job& job) {
  if (!job.preview_levels) return "";
  return fmt::format("  (preview: {} level{}{})", *job.preview_levels,
                     *job.preview_levels == 1 ? "" : "s", job.promoted ? ", promoted" : "");
}

/// Which hierarchy a coarse-prolonged job solved the coarsest level of; empty for the others.
std::string coarse_note(const db::Job& job) {
  if (job.method != db::Method::coarse_prolonged) return "";
  return fmt::format(" (coarsest of {} levels)", jobs::hierarchy_depth(job));
}

void print_text(const std::string& sweep, const std::vector<db::JobResult>& results) {
  std::cout << fmt::format("sweep '{}': {} jobs\n", sweep, results.size());
  for (const db::JobResult& r : results) {
    std::string parameters;
    const nlohmann::json overrides = overrides_of(r.job);
    for (const auto& [path, value] : overrides.items())
      parameters += fmt::format(" {}={}", path, value.dump());
    std::cout << fmt::format("{} {:<9} depth={} method={}{}{}{}\n", r.job.id,
                             db::to_string(r.job.state), r.job.depth, db::to_string(r.job.method),
                             coarse_note(r.job), parameters, preview_note(r.job));
    for (const db::LevelRecord& level : r.levels)
      std::cout << fmt::format("    level {} {:<7} {:>5} iterations  ‖g‖ {:.3e}  {:.2f} s{}\n",
                               level.level, db::to_string(level.status), level.iterations,
                               final_residual(level), timing(level, "wall"),
                               level.error.empty() ? "" : "  " + level.error);
    if (r.levels.empty() && !r.job.error.empty()) std::cout << "    " << r.job.error << '\n';
  }
}

int run_results(const ResultsOptions& options) {
  if (options.csv && options.json)
    throw InputError("psq results: choose --csv or --json, not both");
  const std::filesystem::path database = database_path(options.database);
  require_database(database);
  db::JobStore store(database);
  store.status(options.sweep);  // throws InputError naming the known sweeps
  const std::vector<db::JobResult> results = store.results(db::JobSelection::sweep(options.sweep));
  if (options.csv)
    print_csv(results);
  else if (options.json)
    std::cout << to_json(options.sweep, results).dump(2) << '\n';
  else
    print_text(options.sweep, results);
  return 0;
}

}  // namespace

void register_results_command(CLI::App& app, std::vector<Command>& commands) {
  auto options = std::make_shared<ResultsOptions>();
  CLI::App* command = app.add_subcommand(
      "results", "The jobs of a sweep with their per-level results (text, CSV or JSON)");
  command->add_option("sweep", options->sweep, "Sweep name")->required();
  command->add_flag("--csv", options->csv, "CSV, one row per job level");
  command->add_flag("--json", options->json, "JSON with the residual histories");
  add_database_option(*command, options->database);
  commands.push_back({command, [options] { return run_results(*options); }});
}

}  // namespace psq::runner
