#include "reports/report_model.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <set>

#include "db/job_store.hpp"
#include "engine/core/checksum.hpp"
#include "engine/io/checkpoint.hpp"
#include "jobs/job_identity.hpp"
#include "jobs/run_directory.hpp"
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
  level.frames = record.frames;
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
      const bool stopped_at_preview = result.job.state == db::JobState::previewed &&
                                      result.job.preview_levels && l >= *result.job.preview_levels;
      levels.push_back({});
      levels.back().level = l;
      levels.back().status = stopped_at_preview ? "not refined" : "missing";
    }
  }
  return levels;
}

/// A level's checkpoint, read, and the file it was read from.
struct LevelCheckpoint {
  Checkpoint checkpoint;
  std::filesystem::path file;
};

/// The checkpoints of the first `count` levels of a job (empty where unreadable, with a problem
/// noted).
std::vector<std::optional<LevelCheckpoint>> read_level_checkpoints(
    const db::JobResult& result, const std::filesystem::path& database, std::size_t count,
    JobReport& job) {
  std::vector<std::optional<LevelCheckpoint>> checkpoints(count);
  for (const db::LevelRecord& record : result.levels) {
    if (record.level < 0 || record.level >= static_cast<int>(checkpoints.size())) continue;
    if (record.checkpoint_path.empty()) continue;
    const std::filesystem::path file = resolve_checkpoint(record.checkpoint_path, database);
    try {
      checkpoints[record.level] = LevelCheckpoint{
          read_checkpoint(file, recorded_checksum(record.checkpoint_checksum, file)), file};
    } catch (const InputError& e) {
      job.problems.push_back(fmt::format("level {}: {}", record.level, e.what()));
    }
  }
  for (std::size_t l = 0; l < checkpoints.size(); ++l)
    if (!checkpoints[l] && job.levels[l].checkpoint.empty())
      job.problems.push_back(fmt::format("level {}: no checkpoint recorded", l));
  return checkpoints;
}

/// The level's shells and colliders: from its part-meshes file (written beside the checkpoint
/// by the executor) when it is there and matches, else the checkpoint's mesh as one shell.
LevelShape level_shape(LevelCheckpoint& level, JobReport& job) {
  const std::filesystem::path parts_file =
      jobs::RunDirectory(level.file.parent_path()).part_meshes(level.checkpoint.level);
  if (std::filesystem::exists(parts_file)) {
    try {
      PartMeshes meshes = read_part_meshes(parts_file);
      Eigen::Index vertices = 0;
      for (const PartMesh& part : meshes.parts) vertices += part.positions.rows();
      if (vertices == level.checkpoint.positions.rows()) return {std::move(meshes.parts)};
      job.problems.push_back(fmt::format(
          "level {}: {} has {} vertices, its checkpoint {}; the picture shows the checkpoint",
          level.checkpoint.level, parts_file.string(), vertices,
          level.checkpoint.positions.rows()));
    } catch (const InputError& e) {
      job.problems.push_back(fmt::format("level {}: {}", level.checkpoint.level, e.what()));
    }
  }
  PartMesh whole{"shells", PartKind::shell, std::move(level.checkpoint.positions),
                 std::move(level.checkpoint.rest_positions),
                 std::move(level.checkpoint.triangles)};
  return {{std::move(whole)}};
}

/// Outputs of a finished job from its finest checkpoint, and every level's error to it and to
/// `reference` (the finest positions of the design point's reference, if there is one).
void add_finest_results(const std::vector<std::optional<LevelCheckpoint>>& checkpoints,
                        const Positions* reference, JobReport& job) {
  if (!checkpoints.back()) return;
  const Checkpoint& finest = checkpoints.back()->checkpoint;
  // The executor measures the answer on the finest mesh, where a coarse-prolonged job's
  // checkpoint holds no rest shape; stores before level outputs have only the checkpoint.
  const std::map<std::string, double>& stored = job.levels.back().outputs;
  if (const auto displacement = stored.find("max_displacement"); displacement != stored.end()) {
    job.outputs.max_displacement = displacement->second;
  } else {
    try {
      job.outputs.max_displacement = max_point_distance(finest.positions, finest.rest_positions);
    } catch (const std::invalid_argument& e) {
      job.problems.push_back(
          fmt::format("finest level: positions against rest shape: {}", e.what()));
    }
  }
  if (const auto energy = finest.solver.scalars.find(kElasticEnergyScalar);
      energy != finest.solver.scalars.end())
    job.outputs.elastic_energy = energy->second;
  // Against the answer on the finest mesh: a coarse-prolonged job's positions are its coarse
  // mesh's.
  for (std::size_t l = 0; l < checkpoints.size(); ++l) {
    if (!checkpoints[l]) continue;
    try {
      job.levels[l].error_to_finest = relative_error_to_finest(
          checkpoints[l]->checkpoint.finest_positions, finest.finest_positions);
    } catch (const std::invalid_argument& e) {
      job.problems.push_back(fmt::format("level {}: error to the finest level: {}", l, e.what()));
    }
    if (!reference) continue;
    try {
      job.levels[l].error_to_reference =
          relative_error_to_finest(checkpoints[l]->checkpoint.finest_positions, *reference);
    } catch (const std::invalid_argument& e) {
      job.problems.push_back(
          fmt::format("level {}: error to the direct_final reference: {}", l, e.what()));
    }
  }
}

/// Newton solves and shapes of the levels with a checkpoint (which they consume).
void add_level_pictures(std::vector<std::optional<LevelCheckpoint>>& checkpoints, JobReport& job) {
  for (std::size_t l = 0; l < checkpoints.size(); ++l) {
    if (!checkpoints[l]) continue;
    job.levels[l].solves = newton_solves(checkpoints[l]->checkpoint.statistics.iterations);
    job.levels[l].shape = level_shape(*checkpoints[l], job);
  }
}

JobReport job_report(const db::JobResult& result, int number, const std::filesystem::path& database,
                     const Positions* reference) {
  JobReport job;
  job.number = number;
  job.job = result.job;
  job.parameters = flatten_parameters(result.job.parameters);
  job.levels = levels_of(result);
  if (job.levels.empty() || !(job.finished() || job.previewed())) return job;
  // A previewed job has only its preview levels; their shapes are shown beside the refined
  // points', while the outputs and errors of a job are its finest level's.
  const std::size_t shown =
      job.finished() ? job.levels.size() : static_cast<std::size_t>(job.job.levels_to_run());
  std::vector<std::optional<LevelCheckpoint>> checkpoints =
      read_level_checkpoints(result, database, shown, job);
  if (job.finished()) {
    job.outputs.total_seconds = job.seconds_through(job.levels.size() - 1);
    add_finest_results(checkpoints, reference, job);
  }
  add_level_pictures(checkpoints, job);
  return job;
}

/// The finest positions of each design point's reference: its finished direct_final job's
/// checkpoint. An unreadable one is left out here; that job's own report names the problem.
std::map<std::string, Positions> reference_positions(const std::vector<db::JobResult>& results,
                                                     const std::filesystem::path& database) {
  std::map<std::string, Positions> references;
  for (const db::JobResult& result : results) {
    if (result.job.method != db::Method::direct_final || result.job.state != db::JobState::done ||
        result.levels.empty() || result.levels.back().checkpoint_path.empty())
      continue;
    const db::LevelRecord& record = result.levels.back();
    const std::filesystem::path file = resolve_checkpoint(record.checkpoint_path, database);
    try {
      references.emplace(design_point(result.job),
                         read_checkpoint(file, recorded_checksum(record.checkpoint_checksum, file))
                             .finest_positions);
    } catch (const InputError&) {
    }
  }
  return references;
}

}  // namespace

std::string design_point(const db::Job& job) {
  return job.parameters.value("scene", "") +
         job.parameters.value("overrides", nlohmann::json::object()).dump();
}

std::optional<double> JobReport::seconds_through(std::size_t level) const {
  double elapsed = 0.0;
  for (std::size_t l = 0; l <= level && l < levels.size(); ++l) {
    if (!levels[l].seconds) return std::nullopt;
    elapsed += *levels[l].seconds;
  }
  return elapsed;
}

std::vector<NewtonSolve> newton_solves(const std::vector<IterationRecord>& iterations) {
  std::vector<NewtonSolve> solves;
  for (std::size_t i = 0; i < iterations.size(); ++i) {
    const IterationRecord& it = iterations[i];
    if (i == 0 || it.frame != iterations[i - 1].frame ||
        it.iteration <= iterations[i - 1].iteration)
      solves.push_back({it.frame, {}});
    solves.back().residuals.push_back(it.gradient_norm);
  }
  return solves;
}

HierarchyCacheSummary summarize_cache_uses(const std::vector<db::HierarchyCacheUse>& uses) {
  HierarchyCacheSummary summary;
  std::map<std::string, std::pair<double, int>> builds_of_key;  // key → (seconds, builds)
  for (const db::HierarchyCacheUse& use : uses) {
    if (use.hit) {
      ++summary.hits;
      summary.hit_seconds += use.seconds;
    } else {
      ++summary.builds;
      summary.build_seconds += use.seconds;
      builds_of_key[use.key].first += use.seconds;
      ++builds_of_key[use.key].second;
    }
  }
  for (const db::HierarchyCacheUse& use : uses) {
    if (!use.hit) continue;
    const auto built = builds_of_key.find(use.key);
    if (built == builds_of_key.end())
      ++summary.hits_without_build;
    else
      summary.saved_seconds += built->second.first / built->second.second - use.seconds;
  }
  return summary;
}

std::string method_label(const db::Job& job) {
  switch (job.method) {
    case db::Method::direct:
      return "direct";
    case db::Method::direct_final:
      return "direct, settled from the refine frame";
    case db::Method::progressive:
      return fmt::format("progressive, {} levels", job.depth);
    case db::Method::coarse_prolonged:
      return fmt::format("coarse of {} levels, prolonged", jobs::hierarchy_depth(job));
  }
  return "unknown method";
}

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
  std::vector<db::HierarchyCacheUse> cache_uses;
  const std::map<std::string, Positions> references = reference_positions(results, report.database);
  for (std::size_t i = 0; i < results.size(); ++i) {
    const auto reference = references.find(design_point(results[i].job));
    report.jobs.push_back(job_report(results[i], static_cast<int>(i) + 1, report.database,
                                     reference == references.end() ? nullptr : &reference->second));
    parameter_sets.push_back(report.jobs.back().parameters);
    for (const auto& [name, value] : report.jobs.back().parameters) names.insert(name);
    report.max_depth = std::max(report.max_depth, results[i].job.depth);
    cache_uses.insert(cache_uses.end(), results[i].hierarchy_uses.begin(),
                      results[i].hierarchy_uses.end());
  }
  report.hierarchy_cache = summarize_cache_uses(cache_uses);
  report.parameter_names.assign(names.begin(), names.end());
  report.swept_parameters = varying_parameters(parameter_sets);
  return report;
}

}  // namespace psq::reports
