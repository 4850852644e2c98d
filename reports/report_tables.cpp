#include "reports/report_tables.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>

#include "reports/benchmark.hpp"
#include "reports/html_text.hpp"
#include "reports/parameters.hpp"

namespace psq::reports {
namespace {

/// Shortest text that reads back to the same double; empty for no value.
std::string exact_number(std::optional<double> value) {
  return value ? exact_text(*value) : std::string();
}

std::string joined(const std::vector<std::string>& parts, const std::string& separator) {
  std::string text;
  for (const std::string& part : parts) text += (text.empty() ? "" : separator) + part;
  return text;
}

std::string parameter_cell(const JobReport& job, const std::string& name) {
  const auto found = job.parameters.find(name);
  return found == job.parameters.end() ? std::string() : cell_text(found->second);
}

std::string state_of(const JobReport& job) { return std::string(db::to_string(job.job.state)); }

/// The stored output `name` of level `level` of `job`, if recorded.
std::optional<double> level_output(const JobReport& job, int level, const std::string& name) {
  if (level < 0 || level >= static_cast<int>(job.levels.size())) return std::nullopt;
  const auto& outputs = job.levels[static_cast<std::size_t>(level)].outputs;
  const auto found = outputs.find(name);
  if (found == outputs.end()) return std::nullopt;
  return found->second;
}

/// `baseline` over `seconds`, when both are known and `seconds` is positive.
std::optional<double> speedup(std::optional<double> baseline, double seconds) {
  if (!baseline || !(seconds > 0)) return std::nullopt;
  return *baseline / seconds;
}

}  // namespace

std::string readable_number(std::optional<double> value) {
  return value ? fmt::format("{:.4g}", *value) : std::string();
}

Table results_table(const SweepReport& report) {
  Table table;
  table.header = {"number", "id"};
  table.header.insert(table.header.end(), report.parameter_names.begin(),
                      report.parameter_names.end());
  for (const char* column : {"state", "attempts", "failures", "error", "total_seconds",
                             "max_displacement", "elastic_energy", "problems"})
    table.header.push_back(column);
  for (int l = 0; l < report.max_depth; ++l)
    for (const char* column :
         {"status", "iterations", "seconds", "residual", "static_residual", "error"})
      table.header.push_back(fmt::format("level{}.{}", l, column));

  for (const JobReport& job : report.jobs) {
    std::vector<std::string> row = {std::to_string(job.number), job.job.id};
    for (const std::string& name : report.parameter_names) row.push_back(parameter_cell(job, name));
    row.insert(row.end(),
               {state_of(job), std::to_string(job.job.attempt), std::to_string(job.job.failures),
                job.job.error, exact_number(job.outputs.total_seconds),
                exact_number(job.outputs.max_displacement),
                exact_number(job.outputs.elastic_energy), joined(job.problems, "; ")});
    for (int l = 0; l < report.max_depth; ++l) {
      if (l >= static_cast<int>(job.levels.size())) {
        row.insert(row.end(), 6, std::string());
        continue;
      }
      const LevelReport& level = job.levels[l];
      row.insert(row.end(),
                 {level.status, std::to_string(level.iterations), exact_number(level.seconds),
                  exact_number(level.final_residual), exact_number(level.static_residual),
                  exact_number(level.error_to_finest)});
    }
    table.rows.push_back(std::move(row));
  }
  return table;
}

Table jobs_table(const SweepReport& report) {
  Table table;
  table.header = {"#", "id"};
  table.header.insert(table.header.end(), report.swept_parameters.begin(),
                      report.swept_parameters.end());
  for (const char* column :
       {"state", "time (s)", "max displacement (m)", "elastic energy (J)", "error"})
    table.header.push_back(column);
  for (const JobReport& job : report.jobs) {
    std::vector<std::string> row = {std::to_string(job.number), job.job.id.substr(0, 8)};
    for (const std::string& name : report.swept_parameters)
      row.push_back(parameter_cell(job, name));
    row.insert(row.end(), {state_of(job), readable_number(job.outputs.total_seconds),
                           readable_number(job.outputs.max_displacement),
                           readable_number(job.outputs.elastic_energy), job.job.error});
    table.rows.push_back(std::move(row));
  }
  return table;
}

Table preview_table(const SweepReport& report) {
  Table table;
  table.header = {"#", "id"};
  table.header.insert(table.header.end(), report.swept_parameters.begin(),
                      report.swept_parameters.end());
  for (const char* column : {"state", "promoted", "preview max displacement (m)",
                             "preview elastic energy (J)", "final max displacement (m)",
                             "final elastic energy (J)"})
    table.header.push_back(column);
  if (!report.refine.previews()) return table;
  for (const JobReport& job : report.jobs) {
    if (!job.job.preview_levels) continue;
    const int preview = *job.job.preview_levels - 1;
    const int finest = job.job.depth - 1;
    std::vector<std::string> row = {std::to_string(job.number), job.job.id.substr(0, 8)};
    for (const std::string& name : report.swept_parameters)
      row.push_back(parameter_cell(job, name));
    row.insert(row.end(),
               {state_of(job), job.job.promoted ? "yes" : "no",
                readable_number(level_output(job, preview, "max_displacement")),
                readable_number(level_output(job, preview, "elastic_energy")),
                readable_number(level_output(job, finest, "max_displacement")),
                readable_number(level_output(job, finest, "elastic_energy"))});
    table.rows.push_back(std::move(row));
  }
  return table;
}

Table levels_table(const SweepReport& report) {
  Table table;
  table.header = {"#",
                  "level",
                  "status",
                  "iterations",
                  "final residual",
                  "static residual (m/s)",
                  "time (s)",
                  "error to finest",
                  "checkpoint"};
  for (const JobReport& job : report.jobs)
    for (const LevelReport& level : job.levels)
      table.rows.push_back({std::to_string(job.number), std::to_string(level.level), level.status,
                            std::to_string(level.iterations), readable_number(level.final_residual),
                            readable_number(level.static_residual), readable_number(level.seconds),
                            readable_number(level.error_to_finest), level.checkpoint});
  return table;
}

Table refinements_table(const SweepReport& report) {
  // (column, statistic) in the order shown; refinement_statistics.hpp names the statistics.
  static const std::vector<std::pair<std::string, std::string>> columns{
      {"expansions", "expansions"},
      {"retries", "perturbation_retries"},
      {"CCD rounds", "ccd_rounds"},
      {"relaxed vertices", "relaxed_vertices"},
      {"smallest gap (m)", "smallest_gap"},
      {"final gap (m)", "final_gap"},
      {"max target distance (m)", "max_target_distance"},
      {"mean target distance (m)", "mean_target_distance"},
      {"stretch before", "stretch_before"},
      {"stretch after", "stretch_after"},
      {"gap (s)", "gap_seconds"},
      {"perturb (s)", "perturb_seconds"},
      {"CCD (s)", "ccd_seconds"},
      {"relax (s)", "relax_seconds"},
      {"check (s)", "check_seconds"},
      {"strain (s)", "strain_seconds"},
      {"total (s)", "seconds"}};
  Table table;
  table.header = {"#", "level"};
  for (const auto& [column, statistic] : columns) table.header.push_back(column);
  for (const JobReport& job : report.jobs)
    for (const LevelReport& level : job.levels) {
      if (level.refinement.empty()) continue;
      std::vector<std::string> row{std::to_string(job.number), std::to_string(level.level)};
      for (const auto& [column, statistic] : columns) {
        const auto found = level.refinement.find(statistic);
        row.push_back(found == level.refinement.end() ? std::string()
                                                      : readable_number(found->second));
      }
      table.rows.push_back(std::move(row));
    }
  return table;
}

Table speedup_table(const SweepReport& report) {
  // The method column names the depth and the method: the other swept parameters give the point.
  const std::vector<std::string> point_parameters = design_parameters(report);
  Table table;
  table.header = {"#", "id"};
  table.header.insert(table.header.end(), point_parameters.begin(), point_parameters.end());
  for (const char* column :
       {"method", "time (s)", "direct_final time (s)", "speed-up over direct_final",
        "direct time (s)", "speed-up over direct"})
    table.header.push_back(column);
  for (const JobReport& job : report.jobs) {
    if (!job.finished() || !db::uses_hierarchy(job.job.method) || !job.outputs.total_seconds)
      continue;
    const std::array baselines{baseline_of(report, job, db::Method::direct_final),
                               baseline_of(report, job, db::Method::direct)};
    if (!baselines[0] && !baselines[1]) continue;
    std::vector<std::string> row = {std::to_string(job.number), job.job.id.substr(0, 8)};
    for (const std::string& name : point_parameters) row.push_back(parameter_cell(job, name));
    row.push_back(method_label(job.job));
    row.push_back(readable_number(job.outputs.total_seconds));
    for (const JobReport* baseline : baselines) {
      const std::optional<double> seconds =
          baseline ? baseline->outputs.total_seconds : std::nullopt;
      row.push_back(readable_number(seconds));
      row.push_back(readable_number(speedup(seconds, *job.outputs.total_seconds)));
    }
    table.rows.push_back(std::move(row));
  }
  return table;
}

Table benchmark_table(const SweepReport& report) {
  const std::vector<std::string> point_parameters = design_parameters(report);
  Table table;
  table.header = {"#", "id"};
  table.header.insert(table.header.end(), point_parameters.begin(), point_parameters.end());
  for (const char* column : {"method", "level", "time (s)", "error to direct_final",
                             "speed-up over direct_final", "speed-up over direct", "Pareto front"})
    table.header.push_back(column);
  for (const BenchmarkScene& scene : benchmark_scenes(report))
    for (const BenchmarkDesignPoint& design : scene.design_points) {
      const JobReport* direct = baseline_of(report, *design.reference, db::Method::direct);
      for (const BenchmarkPoint& point : design.points) {
        const JobReport& job = *point.job;
        std::vector<std::string> row = {std::to_string(job.number), job.job.id.substr(0, 8)};
        for (const std::string& name : point_parameters) row.push_back(parameter_cell(job, name));
        row.insert(
            row.end(),
            {method_label(job.job), fmt::format("{} of {}", point.level, job.levels.size()),
             readable_number(point.seconds), readable_number(point.error),
             readable_number(speedup(design.reference->outputs.total_seconds, point.seconds)),
             readable_number(
                 speedup(direct ? direct->outputs.total_seconds : std::nullopt, point.seconds)),
             point.on_front ? "yes" : ""});
        table.rows.push_back(std::move(row));
      }
    }
  return table;
}

std::string cache_summary_text(const HierarchyCacheSummary& cache) {
  if (cache.hits + cache.builds == 0)
    return "Hierarchy cache: not used (direct solves only, or no cache use recorded)";
  const auto counted = [](std::int64_t n, const char* noun) {
    return fmt::format("{} {}{}", n, noun, n == 1 ? "" : "s");
  };
  std::string text = fmt::format(
      "Hierarchy cache: {} and {} ({} s building); the hits read their hierarchies in {} s and "
      "saved {} s of building",
      counted(cache.hits, "hit"), counted(cache.builds, "build"),
      readable_number(cache.build_seconds), readable_number(cache.hit_seconds),
      readable_number(cache.saved_seconds));
  if (cache.hits_without_build > 0)
    text += fmt::format(" ({} hits of hierarchies built outside this sweep are not counted)",
                        cache.hits_without_build);
  return text;
}

std::string to_csv(const Table& table) {
  const auto field = [](const std::string& text) {
    if (text.find_first_of(",\"\r\n") == std::string::npos) return text;
    std::string quoted = "\"";
    for (char c : text) quoted += c == '"' ? std::string("\"\"") : std::string(1, c);
    return quoted + "\"";
  };
  std::string csv;
  const auto add_line = [&](const std::vector<std::string>& cells) {
    std::vector<std::string> fields;
    for (const std::string& cell : cells) fields.push_back(field(cell));
    csv += joined(fields, ",") + "\r\n";
  };
  add_line(table.header);
  for (const auto& row : table.rows) add_line(row);
  return csv;
}

std::string to_markdown(const Table& table) {
  const auto line = [](const std::vector<std::string>& cells) {
    std::vector<std::string> escaped;
    for (const std::string& text : cells) escaped.push_back(one_line_escaped(text, '|', "\\|"));
    return "| " + joined(escaped, " | ") + " |\n";
  };
  std::string markdown = line(table.header);
  markdown += line(std::vector<std::string>(table.header.size(), "---"));
  for (const auto& row : table.rows) markdown += line(row);
  return markdown;
}

}  // namespace psq::reports
