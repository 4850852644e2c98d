#include "reports/results_json.hpp"

#include <cmath>

namespace psq::reports {
namespace {

nlohmann::json number_or_null(std::optional<double> value) {
  return value && std::isfinite(*value) ? nlohmann::json(*value) : nlohmann::json();
}

/// The level's frames: load scale and probe readings ({name, kind, value [x, y, z]}).
nlohmann::json frames_json(const std::vector<db::FrameReadings>& frames) {
  nlohmann::json out = nlohmann::json::array();
  for (const db::FrameReadings& frame : frames) {
    nlohmann::json probes = nlohmann::json::array();
    for (const db::ProbeValue& probe : frame.probes)
      probes.push_back({{"name", probe.probe}, {"kind", probe.kind}, {"value", probe.value}});
    out.push_back({{"frame", frame.frame}, {"load_scale", frame.load_scale}, {"probes", probes}});
  }
  return out;
}

nlohmann::json level_json(const LevelReport& level) {
  nlohmann::json residuals = nlohmann::json::array();
  for (double residual : level.residuals) residuals.push_back(number_or_null(residual));
  nlohmann::json static_residuals = nlohmann::json::array();
  for (const auto& [frame, residual] : level.static_residuals)
    static_residuals.push_back({frame, number_or_null(residual)});
  return {{"level", level.level},
          {"status", level.status},
          {"iterations", level.iterations},
          {"seconds", number_or_null(level.seconds)},
          {"timings", level.timings},
          {"final_residual", number_or_null(level.final_residual)},
          {"static_residual", number_or_null(level.static_residual)},
          {"static_residuals", static_residuals},
          {"error_to_finest", number_or_null(level.error_to_finest)},
          {"error_to_reference", number_or_null(level.error_to_reference)},
          {"refinement", level.refinement},
          {"frames", frames_json(level.frames)},
          {"checkpoint", level.checkpoint},
          {"error", level.error},
          {"residuals", residuals}};
}

nlohmann::json job_json(const JobReport& job) {
  nlohmann::json levels = nlohmann::json::array();
  for (const LevelReport& level : job.levels) levels.push_back(level_json(level));
  return {{"number", job.number},
          {"id", job.job.id},
          {"parameters", job.job.parameters},
          {"flat_parameters", job.parameters},
          {"state", db::to_string(job.job.state)},
          {"attempts", job.job.attempt},
          {"failures", job.job.failures},
          {"error", job.job.error},
          {"outputs",
           {{"total_seconds", number_or_null(job.outputs.total_seconds)},
            {"max_displacement", number_or_null(job.outputs.max_displacement)},
            {"elastic_energy", number_or_null(job.outputs.elastic_energy)}}},
          {"problems", job.problems},
          {"levels", levels}};
}

}  // namespace

nlohmann::json results_json(const SweepReport& report) {
  nlohmann::json counts = nlohmann::json::object();
  for (const auto& [state, count] : report.counts)
    counts[std::string(db::to_string(state))] = count;
  nlohmann::json jobs = nlohmann::json::array();
  for (const JobReport& job : report.jobs) jobs.push_back(job_json(job));
  return {{"sweep", report.name},
          {"source", report.source},
          {"database", report.database.string()},
          {"counts", counts},
          {"swept_parameters", report.swept_parameters},
          {"hierarchy_cache",
           {{"hits", report.hierarchy_cache.hits},
            {"builds", report.hierarchy_cache.builds},
            {"hit_seconds", report.hierarchy_cache.hit_seconds},
            {"build_seconds", report.hierarchy_cache.build_seconds},
            {"saved_seconds", report.hierarchy_cache.saved_seconds},
            {"hits_without_build", report.hierarchy_cache.hits_without_build}}},
          {"jobs", jobs}};
}

}  // namespace psq::reports
