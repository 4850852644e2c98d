#include "reports/html_report.hpp"

#include <fmt/format.h>

#include <map>

#include "reports/html_text.hpp"
#include "reports/parameters.hpp"
#include "reports/report_plots.hpp"
#include "reports/report_tables.hpp"
#include "reports/shape_picture.hpp"

namespace psq::reports {
namespace {

constexpr std::string_view kStyle = R"(
body { font-family: sans-serif; margin: 1.5em; color: #1b2733; }
table { border-collapse: collapse; margin: 0.5em 0 1.5em; font-size: 0.9em; }
th, td { border: 1px solid #c5ccd3; padding: 0.2em 0.5em; text-align: left; }
th { background: #eef1f4; overflow-wrap: anywhere; }
.figures { display: flex; flex-wrap: wrap; gap: 1em; }
figure { margin: 0; }
figure img { max-width: 100%; border: 1px solid #e1e5e9; }
figure.plot img { width: 600px; }
figure svg.shape { border: 1px solid #e1e5e9; display: block; }
.point { border: 2px solid #e1e5e9; padding: 0.4em; max-width: 470px; font-size: 0.9em; }
.point.selected { border: 3px solid #d0541b; background: #fff6f0; }
.point .pictures { display: flex; gap: 0.4em; }
.mark { font-weight: bold; color: #d0541b; }
figcaption { font-size: 0.85em; color: #4a5866; }
.problem { color: #b00020; }
)";

std::string page_html(const std::string& title, const std::string& body) {
  return fmt::format(
      "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n"
      "<title>{0}</title>\n<style>{1}</style>\n</head>\n<body>\n<h1>{0}</h1>\n{2}</body>\n"
      "</html>\n",
      escape_html(title), kStyle, body);
}

std::string html_table(const Table& table) {
  std::string html = "<table>\n<tr>";
  for (const std::string& name : table.header) html += "<th>" + escape_html(name) + "</th>";
  html += "</tr>\n";
  for (const auto& row : table.rows) {
    html += "<tr>";
    for (const std::string& cell : row) html += "<td>" + escape_html(cell) + "</td>";
    html += "</tr>\n";
  }
  return html + "</table>\n";
}

/// The page's plots as <figure> elements: collected first, then drawn in one gnuplot run.
class PlotFigures {
 public:
  /// Adds a plot (it must have drawable points); returns its index.
  std::size_t add(PlotSpec plot) {
    plots_.push_back(std::move(plot));
    return plots_.size() - 1;
  }
  void draw(Gnuplot& gnuplot) {
    const std::vector<std::string> svgs = gnuplot.render_svgs(plots_);
    for (std::size_t p = 0; p < plots_.size(); ++p)
      figures_.push_back(fmt::format(
          "<figure class=\"plot\"><img alt=\"{0}\" src=\"data:image/svg+xml;base64,{1}\">"
          "</figure>\n",
          escape_html(plots_[p].title), base64(svgs[p])));
  }
  /// The figures of these plots, in order (after draw).
  std::string figures(const std::vector<std::size_t>& which) const {
    std::string html;
    for (std::size_t p : which) html += figures_.at(p);
    return html;
  }

 private:
  std::vector<PlotSpec> plots_;
  std::vector<std::string> figures_;
};

/// Where each plot of the page is in its PlotFigures.
struct PagePlots {
  std::vector<std::size_t> cost;       ///< time per level, error against run time
  std::vector<std::size_t> benchmark;  ///< per scene, error to direct_final against run time
  std::vector<std::size_t> sweep;      ///< outputs against the axis parameter
  std::map<int, std::vector<std::size_t>> convergence;  ///< by job number, one per level
  std::map<int, std::vector<std::size_t>> probes;  ///< by job number, one per probe
};

PagePlots collect_plots(const SweepReport& report, PlotFigures& plots) {
  PagePlots page;
  for (PlotSpec& plot : std::vector{time_per_level_plot(report), error_against_time_plot(report)})
    if (has_drawable_points(plot)) page.cost.push_back(plots.add(std::move(plot)));
  for (PlotSpec& plot : benchmark_plots(report))
    page.benchmark.push_back(plots.add(std::move(plot)));
  for (PlotSpec& plot : sweep_plots(report)) page.sweep.push_back(plots.add(std::move(plot)));
  for (const JobReport& job : report.jobs)
    if (job.finished()) {
      for (PlotSpec& plot : convergence_plots(job))
        page.convergence[job.number].push_back(plots.add(std::move(plot)));
      for (PlotSpec& plot : probe_plots(job))
        page.probes[job.number].push_back(plots.add(std::move(plot)));
    }
  return page;
}

std::string figure_row(const std::string& content) {
  return "<div class=\"figures\">\n" + content + "</div>\n";
}

std::string overview(const SweepReport& report) {
  std::string counts;
  for (const auto& [state, count] : report.counts)
    counts += fmt::format("{}{} {}", counts.empty() ? "" : ", ", db::to_string(state), count);
  return fmt::format(
      "<p>Sweep file: <code>{}</code><br>Job store: <code>{}</code><br>"
      "{} jobs: {}<br>{}</p>\n",
      escape_html(report.source), escape_html(report.database.string()), report.jobs.size(),
      escape_html(counts), escape_html(cache_summary_text(report.hierarchy_cache)));
}

std::string problems_section(const SweepReport& report) {
  std::string items;
  for (const JobReport& job : report.jobs)
    for (const std::string& problem : job.problems)
      items += fmt::format("<li>job #{} (<code>{}</code>): {}</li>\n", job.number,
                           escape_html(job.job.id), escape_html(problem));
  if (items.empty()) return {};
  return "<h2>Problems</h2>\n<ul class=\"problem\">\n" + items + "</ul>\n";
}

/// "level 1 of 3 (preview)": which level a picture shows and what it is.
std::string level_name(const JobReport& job, int level) {
  // A coarse-first job's preview is its preview levels; any other job's is its coarsest level.
  const bool preview = level < job.job.preview_levels.value_or(1);
  const char* role = level + 1 == job.job.depth ? "final" : preview ? "preview" : "intermediate";
  return fmt::format("level {} of {} ({})", level, job.job.depth, role);
}

/// A level's picture with its caption as a <figure>.
std::string shape_figure(const ShapePicture& picture, const JobReport& job, int level,
                         int width) {
  const LevelShape& shape = *job.levels[static_cast<std::size_t>(level)].shape;
  std::size_t triangles = 0;
  for (const PartMesh& part : shape.parts) triangles += part.triangles.rows();
  const std::string caption =
      fmt::format("job #{}, {}: {} triangles", job.number, level_name(job, level), triangles);
  return fmt::format("<figure>{}<figcaption>{}</figcaption></figure>\n",
                     picture.svg(shape, caption, width), escape_html(caption));
}

/// A figure with the colour bar of `picture`'s displacement scale.
std::string colour_bar_figure(const ShapePicture& picture) {
  return "<figure>" + picture.colour_bar() +
         "<figcaption>shells coloured by displacement from rest; colliders grey</figcaption>"
         "</figure>\n";
}

/// The levels of a coarse-first job the gallery shows: its last preview level, and its finest
/// level once refined; only those with a picture.
std::vector<int> gallery_levels(const JobReport& job) {
  std::vector<int> levels;
  if (!job.job.preview_levels) return levels;
  const auto shown = [&](int level) {
    return level < static_cast<int>(job.levels.size()) && job.levels[level].shape;
  };
  if (const int preview = *job.job.preview_levels - 1; shown(preview)) levels.push_back(preview);
  if (const int finest = job.job.depth - 1; job.finished() && shown(finest))
    levels.push_back(finest);
  return levels;
}

/// Every point's preview beside its refined answer (when it was refined), all on one frame and
/// colour scale, the selected points marked.
std::string preview_gallery(const SweepReport& report) {
  ShapePicture picture;
  for (const JobReport& job : report.jobs)
    for (const int level : gallery_levels(job)) picture.include(*job.levels[level].shape);
  std::string points;
  for (const JobReport& job : report.jobs) {
    std::string pictures;
    for (const int level : gallery_levels(job)) pictures += shape_figure(picture, job, level, 220);
    if (pictures.empty()) continue;
    const std::string verdict =
        !job.job.promoted ? "not selected: stopped at its preview"
        : job.finished()  ? "<span class=\"mark\">selected</span>: refined"
                          : "<span class=\"mark\">selected</span>: not refined yet";
    points += fmt::format(
        "<div class=\"point{}\"><div>#{} {}: {}</div><div class=\"pictures\">{}</div></div>\n",
        job.job.promoted ? " selected" : "", job.number,
        escape_html(parameter_values(job.parameters, report.swept_parameters)), verdict, pictures);
  }
  if (points.empty()) return {};
  return "<h3>Every point's preview, with the refined answers of the selected ones</h3>\n" +
         figure_row(colour_bar_figure(picture) + points);
}

std::string sweep_figures(const PagePlots& page, const PlotFigures& plots) {
  std::string html = "<h2>Convergence and cost</h2>\n";
  html += page.cost.empty() ? "<p>No finished job has timings or more than one level.</p>\n"
                            : figure_row(plots.figures(page.cost));
  html += "<h2>Outputs against the swept parameters</h2>\n";
  html += page.sweep.empty() ? "<p>No numeric parameter varies between finished jobs.</p>\n"
                             : figure_row(plots.figures(page.sweep));
  return html;
}

/// The job's levels side by side, preview to final, on one frame and colour scale.
std::string shape_figures(const JobReport& job) {
  ShapePicture picture;
  for (const LevelReport& level : job.levels)
    if (level.shape) picture.include(*level.shape);
  std::string html;
  for (const LevelReport& level : job.levels)
    if (level.shape) html += shape_figure(picture, job, level.level, 320);
  return html.empty() ? html : html + colour_bar_figure(picture);
}

std::string job_section(const JobReport& job, const PagePlots& page, const PlotFigures& plots) {
  std::string parameters;
  for (const auto& [name, value] : job.parameters)
    parameters += fmt::format("{}<code>{}</code> = {}", parameters.empty() ? "" : "<br>",
                              escape_html(name), escape_html(cell_text(value)));
  const auto figures_of = [&](const std::map<int, std::vector<std::size_t>>& plotted) {
    const auto found = plotted.find(job.number);
    return found == plotted.end() ? std::string() : figure_row(plots.figures(found->second));
  };
  const std::string shapes = shape_figures(job);
  return fmt::format(
      "<h2 id=\"job-{0}\">Job #{0}</h2>\n<p>id <code>{1}</code><br>{2}</p>\n{3}{4}{5}",
      job.number, escape_html(job.job.id), parameters, figures_of(page.convergence),
      figures_of(page.probes), shapes.empty() ? std::string() : figure_row(shapes));
}

}  // namespace

std::string html_report(const SweepReport& report, Gnuplot& gnuplot) {
  PlotFigures plots;
  const PagePlots page = collect_plots(report, plots);
  plots.draw(gnuplot);
  std::string body = overview(report);
  body += "<h2>Jobs</h2>\n" + html_table(jobs_table(report));
  if (const Table previews = preview_table(report); !previews.rows.empty())
    body += fmt::format("<h2>Coarse-first selection</h2>\n<p>{}</p>\n{}{}",
                        escape_html(db::describe(report.refine)), html_table(previews),
                        preview_gallery(report));
  if (const Table speedups = speedup_table(report); !speedups.rows.empty())
    body += "<h2>Speed-ups over the direct solves</h2>\n" + html_table(speedups);
  if (const Table benchmark = benchmark_table(report); !benchmark.rows.empty())
    body += fmt::format("<h2>Run time against error</h2>\n<p>{}</p>\n{}{}",
                        escape_html(kBenchmarkExplanation),
                        figure_row(plots.figures(page.benchmark)), html_table(benchmark));
  body += "<h2>Levels</h2>\n" + html_table(levels_table(report));
  if (const Table refinements = refinements_table(report); !refinements.rows.empty())
    body += "<h2>Refinements</h2>\n" + html_table(refinements);
  body += problems_section(report);
  body += sweep_figures(page, plots);
  for (const JobReport& job : report.jobs)
    if (job.finished()) body += job_section(job, page, plots);
  return page_html("Sweep " + report.name, body);
}

std::string html_index(const std::vector<SweepLink>& sweeps) {
  std::string items;
  for (const SweepLink& sweep : sweeps)
    items += fmt::format("<li><a href=\"{}\">{}</a>: {}</li>\n", escape_html(sweep.href),
                         escape_html(sweep.name), escape_html(sweep.summary));
  return page_html("PSQ sweeps", "<ul>\n" + items + "</ul>\n");
}

}  // namespace psq::reports
