#include "runner/slurm_files.hpp"

#include <fmt/format.h>

#include <cmath>
#include <fstream>
#include <limits>
#include <nlohmann/json.hpp>

#include "engine/core/atomic_file.hpp"
#include "engine/core/error.hpp"

namespace psq::runner::slurm {
namespace fs = std::filesystem;
namespace {

constexpr const char* kManifestFormat = "psq-slurm-manifest-1";
constexpr const char* kResultFormat = "psq-slurm-task-result-1";

void write_json(const fs::path& file, const nlohmann::json& value) {
  write_file_atomically(file, [&](std::ostream& out) { out << value.dump(2) << '\n'; });
}

nlohmann::json read_json(const fs::path& file, const char* format, const char* what) {
  std::ifstream in(file);
  if (!in) throw InputError(fmt::format("{}: cannot read the {}", file.string(), what));
  try {
    nlohmann::json value = nlohmann::json::parse(in);
    if (value.value("format", "") != format)
      throw InputError(fmt::format("{}: not a {} of this psq (format '{}', expected '{}')",
                                   file.string(), what, value.value("format", ""), format));
    return value;
  } catch (const nlohmann::json::exception& error) {
    throw InputError(fmt::format("{}: a damaged {}: {}", file.string(), what, error.what()));
  }
}

// JSON has no NaN: a NaN residual (a failed iteration) travels as null.
nlohmann::json residuals_json(const std::vector<double>& residuals) {
  nlohmann::json values = nlohmann::json::array();
  for (double r : residuals) values.push_back(std::isfinite(r) ? nlohmann::json(r) : nullptr);
  return values;
}

std::vector<double> residuals_from(const nlohmann::json& values) {
  std::vector<double> residuals;
  for (const nlohmann::json& r : values)
    residuals.push_back(r.is_null() ? std::numeric_limits<double>::quiet_NaN() : r.get<double>());
  return residuals;
}

nlohmann::json level_json(const db::LevelRecord& level) {
  return {{"level", level.level},
          {"status", db::to_string(level.status)},
          {"iterations", level.iterations},
          {"residuals", residuals_json(level.residuals)},
          {"timings", level.timings},
          {"checkpoint_path", level.checkpoint_path},
          {"checkpoint_checksum", level.checkpoint_checksum},
          {"error", level.error}};
}

db::LevelRecord level_from(const nlohmann::json& value) {
  db::LevelRecord level;
  level.level = value.at("level").get<int>();
  level.status = db::level_status_from_string(value.at("status").get<std::string>());
  level.iterations = value.at("iterations").get<std::int64_t>();
  level.residuals = residuals_from(value.at("residuals"));
  level.timings = value.at("timings").get<std::map<std::string, double>>();
  level.checkpoint_path = value.at("checkpoint_path").get<std::string>();
  level.checkpoint_checksum = value.at("checkpoint_checksum").get<std::string>();
  level.error = value.at("error").get<std::string>();
  return level;
}

}  // namespace

void write_manifest(const fs::path& file, const Manifest& manifest) {
  nlohmann::json jobs = nlohmann::json::array();
  for (const db::NewJob& job : manifest.jobs)
    jobs.push_back({{"id", job.id},
                    {"parameters", job.parameters},
                    {"scene", job.scene},
                    {"depth", job.depth},
                    {"method", db::to_string(job.method)},
                    {"max_attempts", job.max_attempts}});
  write_json(file, {{"format", kManifestFormat},
                    {"sweep", manifest.sweep},
                    {"runs", manifest.runs.string()},
                    {"snapshot_iterations", manifest.snapshot_iterations},
                    {"snapshot_seconds", manifest.snapshot_seconds},
                    {"jobs", jobs}});
}

Manifest read_manifest(const fs::path& file) {
  const nlohmann::json value = read_json(file, kManifestFormat, "SLURM manifest");
  try {
    Manifest manifest;
    manifest.sweep = value.at("sweep").get<std::string>();
    manifest.runs = value.at("runs").get<std::string>();
    manifest.snapshot_iterations = value.at("snapshot_iterations").get<int>();
    manifest.snapshot_seconds = value.at("snapshot_seconds").get<double>();
    for (const nlohmann::json& job : value.at("jobs")) {
      const int depth = job.at("depth").get<int>();
      // A manifest written before methods existed names none.
      const db::Method method =
          job.contains("method") ? db::method_from_string(job.at("method").get<std::string>())
                                 : db::method_of_depth(depth);
      manifest.jobs.push_back({job.at("id").get<std::string>(), job.at("parameters"),
                               job.at("scene").get<std::string>(), depth, method,
                               job.at("max_attempts").get<int>(), std::nullopt});
    }
    return manifest;
  } catch (const std::exception& error) {  // a JSON error, or a method that is not one
    throw InputError(fmt::format("{}: a damaged SLURM manifest: {}", file.string(), error.what()));
  }
}

fs::path task_directory(const fs::path& runs, const std::string& job_id) {
  return runs / job_id / "slurm";
}

fs::path task_store(const fs::path& runs, const std::string& job_id) {
  return task_directory(runs, job_id) / "task.db";
}

fs::path task_result(const fs::path& runs, const std::string& job_id) {
  return task_directory(runs, job_id) / "result.json";
}

void write_task_result(const fs::path& file, const TaskResult& result) {
  nlohmann::json levels = nlohmann::json::array();
  for (const db::LevelRecord& level : result.levels) levels.push_back(level_json(level));
  write_json(file, {{"format", kResultFormat},
                    {"array_id", result.array_id},
                    {"index", result.index},
                    {"state", db::to_string(result.state)},
                    {"error", result.error},
                    {"levels", levels}});
}

std::optional<TaskResult> read_task_result(const fs::path& file) {
  if (!fs::exists(file)) return std::nullopt;
  const nlohmann::json value = read_json(file, kResultFormat, "SLURM task result");
  try {
    TaskResult result;
    result.array_id = value.at("array_id").get<std::string>();
    result.index = value.at("index").get<int>();
    result.state = db::job_state_from_string(value.at("state").get<std::string>());
    result.error = value.at("error").get<std::string>();
    for (const nlohmann::json& level : value.at("levels"))
      result.levels.push_back(level_from(level));
    return result;
  } catch (const std::exception& error) {
    throw InputError(
        fmt::format("{}: a damaged SLURM task result: {}", file.string(), error.what()));
  }
}

}  // namespace psq::runner::slurm
