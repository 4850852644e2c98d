#include "reports/report_plots.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <functional>
#include <set>

#include "reports/benchmark.hpp"
#include "reports/parameters.hpp"
#include "reports/report_tables.hpp"
#include "reports/shape_picture.hpp"

namespace psq::reports {
namespace {

/// At most this many frames get a legend entry in a convergence plot (evenly spread).
constexpr std::size_t kMaxLegendFrames = 10;

std::string job_label(const JobReport& job) { return fmt::format("#{}", job.number); }

/// A probe plot leaves out a component that stays below this fraction of the largest magnitude.
constexpr double kNegligibleComponent = 1e-9;

/// Convergence plots of longer solves are drawn as lines without point markers.
constexpr std::size_t kMaxMarkedIterations = 60;

/// Convergence plots of solves up to this many iterations get one x tic per iteration.
constexpr std::size_t kMaxIterationTics = 12;

/// The most iterations of any of the solves.
std::size_t longest_solve(const std::vector<NewtonSolve>& solves) {
  std::size_t longest = 0;
  for (const NewtonSolve& solve : solves) longest = std::max(longest, solve.residuals.size());
  return longest;
}

/// The distinct frames of the solves, in order of first appearance.
std::vector<int> frames_of(const std::vector<NewtonSolve>& solves) {
  std::vector<int> frames;
  for (const NewtonSolve& solve : solves)
    if (std::find(frames.begin(), frames.end(), solve.frame) == frames.end())
      frames.push_back(solve.frame);
  return frames;
}

/// Whether the frame at `index` of `count` gets a legend entry: all of few frames, else an
/// evenly spread selection with the first and the last.
bool labelled_frame(std::ptrdiff_t index, std::size_t count) {
  if (count <= kMaxLegendFrames) return true;
  const std::size_t stride = (count + kMaxLegendFrames - 2) / (kMaxLegendFrames - 1);
  return index % stride == 0 || index + 1 == static_cast<std::ptrdiff_t>(count);
}

/// Frames in order along the displacement colour scale, stopping short of its palest end
/// (hard to see on white).
std::string frame_colour(std::ptrdiff_t index, std::size_t count) {
  return hex_colour(displacement_colour(count > 1 ? 0.85 * index / (count - 1.0) : 0.0));
}

/// True if every value is positive and the largest is at least `ratio` times the smallest.
bool wide_positive_range(const std::vector<double>& values, double ratio) {
  if (values.empty()) return false;
  const auto [low, high] = std::minmax_element(values.begin(), values.end());
  return *low > 0 && *high >= ratio * *low;
}

/// "poisson_ratio, youngs_modulus": the short names, comma-separated.
std::string short_names(const std::vector<std::string>& names) {
  std::string text;
  for (const std::string& name : names) text += (text.empty() ? "" : ", ") + short_name(name);
  return text;
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

/// The job's value of `name` as text ("-" when absent), to compare values of any type.
std::string value_text(const JobReport& job, const std::string& name) {
  const auto found = job.parameters.find(name);
  return found == job.parameters.end() ? "-" : found->second.dump();
}

/// The numeric swept parameter with the most distinct values among finished jobs; the hierarchy
/// depth (the method, not a design parameter) only when nothing else is numeric.
std::optional<std::string> axis_parameter(const SweepReport& report) {
  std::optional<std::string> axis;
  std::pair<bool, std::size_t> best{false, 0};  // (not the depth, distinct values)
  for (const std::string& name : report.swept_parameters) {
    std::set<double> values;
    for (const JobReport& job : report.jobs)
      if (const std::optional<double> x = numeric_parameter(job, name); job.finished() && x)
        values.insert(*x);
    const std::pair<bool, std::size_t> rank{name != "depth", values.size()};
    if (!values.empty() && rank > best) {
      best = rank;
      axis = name;
    }
  }
  return axis;
}

/// Whether `name` takes one value per value of `axis` among finished jobs (zipped with it).
bool determined_by(const SweepReport& report, const std::string& name, const std::string& axis) {
  std::map<std::string, std::string> value_at;
  for (const JobReport& job : report.jobs) {
    if (!job.finished()) continue;
    const auto [entry, added] = value_at.try_emplace(value_text(job, axis), value_text(job, name));
    if (!added && entry->second != value_text(job, name)) return false;
  }
  return true;
}

std::optional<PlotSpec> sweep_plot(const SweepReport& report, const std::string& axis,
                                   const JobOutput& output) {
  std::vector<std::string> grouping, zipped;
  for (const std::string& name : report.swept_parameters)
    if (name != axis) (determined_by(report, name, axis) ? zipped : grouping).push_back(name);
  PlotSpec plot;
  plot.title = fmt::format("{} against {}", output.name, short_name(axis));
  plot.x_label = axis;
  if (!zipped.empty()) plot.x_label += " (with " + short_names(zipped) + ")";
  plot.y_label = fmt::format("{} ({})", output.name, output.unit);
  plot.style = PlotSpec::Style::linespoints;
  std::vector<double> xs, ys;
  std::map<std::string, std::size_t> curve_of_group;
  for (const JobReport& job : report.jobs) {
    const std::optional<double> x = numeric_parameter(job, axis);
    const std::optional<double> y = output.value(job.outputs);
    if (!job.finished() || !x || !y) continue;
    const std::string group = parameter_values(job.parameters, grouping);
    const auto [entry, added] = curve_of_group.try_emplace(group, plot.series.size());
    if (added) plot.series.push_back({group.empty() ? output.name : group, {}, {}});
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

std::vector<PlotSpec> convergence_plots(const JobReport& job) {
  std::vector<PlotSpec> plots;
  for (const LevelReport& level : job.levels) {
    if (level.solves.empty()) continue;
    PlotSpec plot;
    plot.title = fmt::format("job {}, level {}: residual in each Newton solve", job_label(job),
                             level.level);
    plot.x_label = "Newton iteration within the solve";
    plot.y_label = "residual |grad E|";
    plot.log_y = true;
    // A tic per iteration reads well for short solves; long ones are left to gnuplot's tics.
    const std::size_t longest = longest_solve(level.solves);
    plot.integer_x = longest <= kMaxIterationTics;
    plot.style =
        longest > kMaxMarkedIterations ? PlotSpec::Style::lines : PlotSpec::Style::linespoints;
    const std::vector<int> frames = frames_of(level.solves);
    for (std::size_t k = 0; k < level.solves.size(); ++k) {
      const NewtonSolve& solve = level.solves[k];
      const auto index = std::find(frames.begin(), frames.end(), solve.frame) - frames.begin();
      const bool first_of_frame = k == 0 || solve.frame != level.solves[k - 1].frame;
      PlotSeries series{first_of_frame && labelled_frame(index, frames.size())
                            ? fmt::format("frame {}", solve.frame)
                            : std::string(),
                        {},
                        frame_colour(index, frames.size())};
      for (std::size_t i = 0; i < solve.residuals.size(); ++i)
        series.points.emplace_back(static_cast<double>(i), solve.residuals[i]);
      plot.series.push_back(std::move(series));
    }
    if (has_drawable_points(plot)) plots.push_back(std::move(plot));
  }
  return plots;
}

std::vector<PlotSpec> probe_plots(const JobReport& job) {
  std::vector<PlotSpec> plots;
  if (job.levels.empty()) return plots;
  const std::vector<db::FrameReadings>& frames = job.levels.back().frames;
  // The probes in the order of their first reading.
  std::vector<std::pair<std::string, std::string>> probes;  // (name, kind)
  for (const db::FrameReadings& frame : frames)
    for (const db::ProbeValue& value : frame.probes)
      if (std::none_of(probes.begin(), probes.end(),
                       [&](const auto& p) { return p.first == value.probe; }))
        probes.emplace_back(value.probe, value.kind);
  for (const auto& [name, kind] : probes) {
    PlotSpec plot;
    plot.title = fmt::format("job {}: probe '{}' against the load scale", job_label(job), name);
    plot.x_label = "load scale";
    plot.y_label = kind == "reaction" ? "reaction (N)" : "mean displacement (m)";
    std::array<PlotSeries, 4> series{PlotSeries{"x", {}, {}}, PlotSeries{"y", {}, {}},
                                     PlotSeries{"z", {}, {}}, PlotSeries{"magnitude", {}, {}}};
    std::array<double, 3> largest{0, 0, 0};  // per component, the largest |value|
    double largest_magnitude = 0;
    for (const db::FrameReadings& frame : frames)
      for (const db::ProbeValue& value : frame.probes) {
        if (value.probe != name) continue;
        double squares = 0;
        for (int c = 0; c < 3; ++c) {
          series[c].points.emplace_back(frame.load_scale, value.value[c]);
          largest[c] = std::max(largest[c], std::abs(value.value[c]));
          squares += value.value[c] * value.value[c];
        }
        series[3].points.emplace_back(frame.load_scale, std::sqrt(squares));
        largest_magnitude = std::max(largest_magnitude, std::sqrt(squares));
      }
    // A component at round-off (a symmetric strip's sideways displacement) would only crowd
    // the plot.
    for (int c = 0; c < 3; ++c)
      if (largest[c] > kNegligibleComponent * largest_magnitude)
        plot.series.push_back(std::move(series[c]));
    plot.series.push_back(std::move(series[3]));
    if (has_drawable_points(plot)) plots.push_back(std::move(plot));
  }
  return plots;
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
    PlotSeries series{job_label(job), {}, {}};
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
    PlotSeries series{fmt::format("{} ({})", job_label(job), method_label(job.job)), {}, {}};
    for (std::size_t l = 0; l < job.levels.size(); ++l) {
      const std::optional<double> elapsed = job.seconds_through(l);
      if (!elapsed) break;
      if (const std::optional<double> error = job.levels[l].error_to_finest)
        series.points.emplace_back(*elapsed, *error);
    }
    plot.series.push_back(std::move(series));
  }
  return plot;
}

std::vector<PlotSpec> benchmark_plots(const SweepReport& report) {
  // A colour per method and a marker per design point: a legend entry per job would crowd out
  // the plot of a methods × depth × resolution sweep; the table lists every job.
  static const std::array<const char*, 8> kMethodColours{
      "#1b9e77", "#d95f02", "#7570b3", "#e7298a", "#66a61e", "#e6ab02", "#a6761d", "#1f78b4"};
  static const std::array<int, 5> kMarkers{7, 5, 9, 13, 11};  // filled ● ■ ▲ ◆ ▼
  constexpr int kPlotHeight = 330, kLegendLineHeight = 20;    // pixels
  std::vector<PlotSpec> plots;
  for (const BenchmarkScene& scene : benchmark_scenes(report)) {
    const bool several = scene.design_points.size() > 1;
    PlotSpec plot;
    plot.title = fmt::format("{}: error to direct_final{} against run time",
                             std::filesystem::path(scene.scene).stem().string(),
                             several ? " of the same mesh and parameters," : "");
    plot.x_label = "run time up to the level (s)";
    plot.y_label = "max vertex error / bounding box diagonal";
    plot.log_x = true;
    plot.log_y = true;
    std::vector<std::string> methods;  // in order of first appearance: their colours
    std::size_t legend_lines = 0;
    for (std::size_t d = 0; d < scene.design_points.size(); ++d) {
      const BenchmarkDesignPoint& design = scene.design_points[d];
      const int marker = kMarkers[d % kMarkers.size()];
      // The reference ends every front, but its error, 0, has no place on a log scale: its
      // time goes in the legend instead.
      const std::string reference = fmt::format(
          "direct_final {} s", readable_number(design.reference->outputs.total_seconds));
      PlotSeries front{several ? fmt::format("Pareto front, {} ({})", design.label, reference)
                               : fmt::format("Pareto front ({})", reference),
                       {},
                       "#000000",
                       PlotStyle::thick_linespoints,
                       marker};
      std::map<const JobReport*, std::size_t> curve_of_job;
      for (const BenchmarkPoint& point : design.points) {
        if (point.on_front) front.points.emplace_back(point.seconds, point.error);
        // The reference's error is 0, which a log scale cannot draw.
        if (point.job == design.reference) continue;
        const auto [curve, added] = curve_of_job.try_emplace(point.job, plot.series.size());
        if (added) {
          const std::string method = method_label(point.job->job);
          auto known = std::find(methods.begin(), methods.end(), method);
          const bool first = known == methods.end();
          if (first) known = methods.insert(methods.end(), method);
          legend_lines += first;
          plot.series.push_back({first ? method : std::string(),
                                 {},
                                 kMethodColours[static_cast<std::size_t>(known - methods.begin()) %
                                                kMethodColours.size()],
                                 std::nullopt,
                                 marker});
        }
        plot.series[curve->second].points.emplace_back(point.seconds, point.error);
      }
      std::sort(front.points.begin(), front.points.end());
      plot.series.push_back(std::move(front));
      ++legend_lines;
    }
    plot.height = kPlotHeight + kLegendLineHeight * static_cast<int>(legend_lines);
    if (has_drawable_points(plot)) plots.push_back(std::move(plot));
  }
  return plots;
}

std::vector<PlotSpec> sweep_plots(const SweepReport& report) {
  std::vector<PlotSpec> plots;
  const std::optional<std::string> axis = axis_parameter(report);
  if (!axis) return plots;
  for (const JobOutput& output : job_outputs())
    if (std::optional<PlotSpec> plot = sweep_plot(report, *axis, output))
      plots.push_back(std::move(*plot));
  return plots;
}

}  // namespace psq::reports
