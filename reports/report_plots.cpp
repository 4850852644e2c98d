#include "reports/report_plots.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <functional>

#include "reports/parameters.hpp"

namespace psq::reports {
namespace {

/// Residual histories longer than this are drawn as lines without point markers.
constexpr std::size_t kMaxMarkedPoints = 60;

std::string job_label(const JobReport& job) { return fmt::format("#{}", job.number); }

/// True if every value is positive and the largest is at least `ratio` times the smallest.
bool wide_positive_range(const std::vector<double>& values, double ratio) {
  if (values.empty()) return false;
  const auto [low, high] = std::minmax_element(values.begin(), values.end());
  return *low > 0 && *high >= ratio * *low;
}

/// The last part of a dotted parameter name: "overrides.shell.strip.material.thickness" →
/// "thickness".
std::string short_name(const std::string& name) {
  const auto dot = name.rfind('.');
  return dot == std::string::npos ? name : name.substr(dot + 1);
}

struct JobOutput {
  std::string name;
  std::string unit;
  std::function<std::optional<double>(const JobOutputs&)> value;
};

const std::vector<JobOutput>& job_outputs() {
  static const std::vector<JobOutput> outputs = {
      {"max displacement", "m", [](const JobOutputs& o) { return o.max_displacement; }},
      {"elastic energy", "J", [](const JobOutputs& o) { return o.elastic_energy; }},
      {"time", "s", [](const JobOutputs& o) { return o.total_seconds; }},
  };
  return outputs;
}

/// The value of `name` in a job as a number, if it is one.
std::optional<double> numeric_parameter(const JobReport& job, const std::string& name) {
  const auto found = job.parameters.find(name);
  if (found == job.parameters.end() || !found->second.is_number()) return std::nullopt;
  return found->second.get<double>();
}

/// "thickness=0.001, youngs_modulus=2e9": the swept parameters other than `axis`.
std::string other_parameters(const SweepReport& report, const JobReport& job,
                             const std::string& axis) {
  std::string text;
  for (const std::string& name : report.swept_parameters) {
    if (name == axis) continue;
    const auto found = job.parameters.find(name);
    const std::string value = found == job.parameters.end() ? "-" : cell_text(found->second);
    text += fmt::format("{}{}={}", text.empty() ? "" : ", ", short_name(name), value);
  }
  return text;
}

std::optional<PlotSpec> sweep_plot(const SweepReport& report, const std::string& axis,
                                   const JobOutput& output) {
  PlotSpec plot;
  plot.title = fmt::format("{} against {}", output.name, short_name(axis));
  plot.x_label = axis;
  plot.y_label = fmt::format("{} ({})", output.name, output.unit);
  plot.style = PlotSpec::Style::linespoints;
  std::vector<double> xs, ys;
  std::map<std::string, std::size_t> curve_of_group;
  for (const JobReport& job : report.jobs) {
    const std::optional<double> x = numeric_parameter(job, axis);
    const std::optional<double> y = output.value(job.outputs);
    if (!job.finished() || !x || !y) continue;
    const std::string group = other_parameters(report, job, axis);
    const auto [entry, added] = curve_of_group.try_emplace(group, plot.series.size());
    if (added) plot.series.push_back({group.empty() ? output.name : group, {}});
    plot.series[entry->second].points.emplace_back(*x, *y);
    xs.push_back(*x);
    ys.push_back(*y);
  }
  for (PlotSeries& series : plot.series) std::sort(series.points.begin(), series.points.end());
  plot.log_x = wide_positive_range(xs, 20);
  plot.log_y = wide_positive_range(ys, 20);
  if (!has_drawable_points(plot)) return std::nullopt;
  return plot;
}

}  // namespace

PlotSpec residual_plot(const JobReport& job) {
  PlotSpec plot;
  plot.title = fmt::format("job {}: residual against iteration", job_label(job));
  plot.x_label = "iteration";
  plot.y_label = "residual";
  plot.log_y = true;
  std::size_t longest = 0;
  for (const LevelReport& level : job.levels) {
    PlotSeries series{fmt::format("level {}", level.level), {}};
    for (std::size_t i = 0; i < level.residuals.size(); ++i)
      series.points.emplace_back(static_cast<double>(i + 1), level.residuals[i]);
    longest = std::max(longest, series.points.size());
    plot.series.push_back(std::move(series));
  }
  plot.style = longest > kMaxMarkedPoints ? PlotSpec::Style::lines : PlotSpec::Style::linespoints;
  return plot;
}

PlotSpec time_per_level_plot(const SweepReport& report) {
  PlotSpec plot;
  plot.title = "time per level";
  plot.x_label = "level (0 = coarsest)";
  plot.y_label = "time (s)";
  plot.log_y = true;
  plot.integer_x = true;
  for (const JobReport& job : report.jobs) {
    if (!job.finished()) continue;
    PlotSeries series{job_label(job), {}};
    for (const LevelReport& level : job.levels)
      if (level.seconds) series.points.emplace_back(level.level, *level.seconds);
    plot.series.push_back(std::move(series));
  }
  return plot;
}

PlotSpec error_against_time_plot(const SweepReport& report) {
  PlotSpec plot;
  plot.title = "error to the finest level against run time";
  plot.x_label = "run time up to the level (s)";
  plot.y_label = "max vertex error / bounding box diagonal";
  plot.log_x = true;
  plot.log_y = true;
  for (const JobReport& job : report.jobs) {
    if (!job.finished()) continue;
    PlotSeries series{job_label(job), {}};
    double elapsed = 0.0;
    for (const LevelReport& level : job.levels) {
      if (!level.seconds) break;
      elapsed += *level.seconds;
      if (level.error_to_finest) series.points.emplace_back(elapsed, *level.error_to_finest);
    }
    plot.series.push_back(std::move(series));
  }
  return plot;
}

std::vector<PlotSpec> sweep_plots(const SweepReport& report) {
  std::vector<PlotSpec> plots;
  for (const std::string& axis : report.swept_parameters)
    for (const JobOutput& output : job_outputs())
      if (std::optional<PlotSpec> plot = sweep_plot(report, axis, output))
        plots.push_back(std::move(*plot));
  return plots;
}

}  // namespace psq::reports
