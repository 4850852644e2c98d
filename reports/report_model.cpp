#include "reports/report_model.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <set>

#include "db/job_store.hpp"
#include "engine/core/checksum.hpp"
#include "engine/io/checkpoint.hpp"
#include "reports/level_metrics.hpp"
#include "reports/parameters.hpp"

namespace psq::reports {
namespace {

/// The file checksum recorded by the store (checksum_text's form); empty when nothing was
/// recorded. Throws CheckpointError for anything else.
std::optional<std::uint64_t> recorded_checksum(const std::string& text,
                                               const std::filesystem::path& file) {
  if (text.empty()) return std::nullopt;
  if (const std::optional<std::uint64_t> checksum = parse_checksum(text)) return checksum;
  throw CheckpointError(
      fmt::format("{}: the store records its checksum as '{}', which is not "
                  "an FNV-1a 64 digest (fnv1a64:<16 hex digits>)",
                  file.string(), text));
}

/// Where a checkpoint path recorded in the store lives: absolute as is; relative against the
/// store's directory (the workspace), else against the current directory.
std::filesystem::path resolve_checkpoint(const std::string& recorded,
                                         const std::filesystem::path& database) {
  const std::filesystem::path path(recorded);
  if (path.is_absolute()) return path;
  const std::filesystem::path in_workspace = database.parent_path() / path;
  if (std::filesystem::exists(in_workspace) || !std::filesystem::exists(path)) return in_workspace;
  return path;
}

LevelReport level_from_record(const db::LevelRecord& record) {
  LevelReport level;
  level.level = record.level;
  level.status = std::string(db::to_string(record.status));
  level.iterations = record.iterations;
  level.residuals = record.residuals;
  level.timings = record.timings;
  level.seconds = level_seconds(record.timings);
  level.final_residual = final_residual(record.residuals);
  level.static_residuals = record.static_residuals;
  if (!record.static_residuals.empty() && std::isfinite(record.static_residuals.back().second))
    level.static_residual = record.static_residuals.back().second;
  level.refinement = record.refinement;
  level.outputs = record.outputs;
  level.checkpoint = record.checkpoint_path;
  level.error = record.error;
  return level;
}

std::vector<LevelReport> levels_of(const db::JobResult& result) {
  std::vector<LevelReport> levels;
  for (int l = 0; l < result.job.depth; ++l) {
    const auto record = std::find_if(result.levels.begin(), result.levels.end(),
                                     [l](const db::LevelRecord& r) { return r.level == l; });
    if (record != result.levels.end()) {
      levels.push_back(level_from_record(*record));
    } else {
      levels.push_back({});
      levels.back().level = l;
      levels.back().status = "missing";
    }
  }
  return levels;
}

/// The checkpoints of a finished job's levels (empty where unreadable, with a problem noted).
std::vector<std::optional<Checkpoint>> read_level_checkpoints(const db::JobResult& result,
                                                              const std::filesystem::path& database,
                                                              JobReport& job) {
  std::vector<std::optional<Checkpoint>> checkpoints(job.levels.size());
  for (const db::LevelRecord& record : result.levels) {
    if (record.level < 0 || record.level >= static_cast<int>(checkpoints.size())) continue;
    if (record.checkpoint_path.empty()) continue;
    const std::filesystem::path file = resolve_checkpoint(record.checkpoint_path, database);
    try {
      checkpoints[record.level] =
          read_checkpoint(file, recorded_checksum(record.checkpoint_checksum, file));
    } catch (const InputError& e) {
      job.problems.push_back(fmt::format("level {}: {}", record.level, e.what()));
    }
  }
  for (std::size_t l = 0; l < checkpoints.size(); ++l)
    if (!checkpoints[l] && job.levels[l].checkpoint.empty())
      job.problems.push_back(fmt::format("level {}: no checkpoint recorded", l));
  return checkpoints;
}

/// Errors to the finest level, outputs and shapes of a finished job, from its checkpoints.
void add_checkpoint_results(std::vector<std::optional<Checkpoint>>& checkpoints, JobReport& job) {
  const std::optional<Checkpoint>& finest = checkpoints.back();
  if (finest) {
    try {
      job.outputs.max_displacement = max_point_distance(finest->positions, finest->rest_positions);
    } catch (const std::invalid_argument& e) {
      job.problems.push_back(
          fmt::format("finest level: positions against rest shape: {}", e.what()));
    }
    if (const auto energy = finest->solver.scalars.find(kElasticEnergyScalar);
        energy != finest->solver.scalars.end())
      job.outputs.elastic_energy = energy->second;
  }
  for (std::size_t l = 0; l < checkpoints.size(); ++l) {
    if (!checkpoints[l]) continue;
    if (finest) {
      try {
        job.levels[l].error_to_finest =
            relative_error_to_finest(checkpoints[l]->finest_positions, finest->positions);
      } catch (const std::invalid_argument& e) {
        job.problems.push_back(fmt::format("level {}: error to the finest level: {}", l, e.what()));
      }
    }
    job.levels[l].shape =
        LevelShape{std::move(checkpoints[l]->positions), std::move(checkpoints[l]->triangles)};
  }
}

std::optional<double> total_seconds(const std::vector<LevelReport>& levels) {
  double total = 0.0;
  for (const LevelReport& level : levels) {
    if (!level.seconds) return std::nullopt;
    total += *level.seconds;
  }
  return total;
}

JobReport job_report(const db::JobResult& result, int number,
                     const std::filesystem::path& database) {
  JobReport job;
  job.number = number;
  job.job = result.job;
  job.parameters = flatten_parameters(result.job.parameters);
  job.levels = levels_of(result);
  if (!job.finished() || job.levels.empty()) return job;
  job.outputs.total_seconds = total_seconds(job.levels);
  std::vector<std::optional<Checkpoint>> checkpoints =
      read_level_checkpoints(result, database, job);
  add_checkpoint_results(checkpoints, job);
  return job;
}

}  // namespace

SweepReport gather_sweep_report(db::JobStore& store, const std::string& sweep) {
  const db::SweepStatus status = store.status(sweep);
  SweepReport report;
  report.name = status.name;
  report.source = status.source;
  report.database = store.path();
  report.counts = status.counts;
  report.refine = status.refine;
  const std::vector<db::JobResult> results = store.results(db::JobSelection::sweep(sweep));
  std::vector<std::map<std::string, nlohmann::json>> parameter_sets;
  std::set<std::string> names;
  for (std::size_t i = 0; i < results.size(); ++i) {
    report.jobs.push_back(job_report(results[i], static_cast<int>(i) + 1, report.database));
    parameter_sets.push_back(report.jobs.back().parameters);
    for (const auto& [name, value] : report.jobs.back().parameters) names.insert(name);
    report.max_depth = std::max(report.max_depth, results[i].job.depth);
  }
  report.parameter_names.assign(names.begin(), names.end());
  report.swept_parameters = varying_parameters(parameter_sets);
  return report;
}

}  // namespace psq::reports
