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
figure svg.shape { border: 1px solid #e1e5e9; }
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
  std::vector<std::size_t> cost;        ///< time per level, error against run time
  std::vector<std::size_t> sweep;       ///< outputs against swept parameters
  std::map<int, std::size_t> residual;  ///< by job number
};

PagePlots collect_plots(const SweepReport& report, PlotFigures& plots) {
  PagePlots page;
  for (PlotSpec& plot : std::vector{time_per_level_plot(report), error_against_time_plot(report)})
    if (has_drawable_points(plot)) page.cost.push_back(plots.add(std::move(plot)));
  for (PlotSpec& plot : sweep_plots(report)) page.sweep.push_back(plots.add(std::move(plot)));
  for (const JobReport& job : report.jobs)
    if (PlotSpec plot = residual_plot(job); job.finished() && has_drawable_points(plot))
      page.residual[job.number] = plots.add(std::move(plot));
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
      "{} jobs: {}</p>\n",
      escape_html(report.source), escape_html(report.database.string()), report.jobs.size(),
      escape_html(counts));
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

std::string sweep_figures(const PagePlots& page, const PlotFigures& plots) {
  std::string html = "<h2>Convergence and cost</h2>\n";
  html += page.cost.empty() ? "<p>No finished job has timings or more than one level.</p>\n"
                            : figure_row(plots.figures(page.cost));
  html += "<h2>Outputs against the swept parameters</h2>\n";
  html += page.sweep.empty() ? "<p>No numeric parameter varies between finished jobs.</p>\n"
                             : figure_row(plots.figures(page.sweep));
  return html;
}

std::string shape_figures(const JobReport& job) {
  ShapePicture picture;
  for (const LevelReport& level : job.levels)
    if (level.shape) picture.include(level.shape->positions);
  std::string html;
  for (const LevelReport& level : job.levels) {
    if (!level.shape) continue;
    const std::string caption = fmt::format("job #{}, level {}: final shape ({} triangles)",
                                            job.number, level.level, level.shape->triangles.rows());
    html += fmt::format("<figure>{}<figcaption>{}</figcaption></figure>\n",
                        picture.svg(*level.shape, caption), escape_html(caption));
  }
  return html;
}

std::string job_section(const JobReport& job, const PagePlots& page, const PlotFigures& plots) {
  std::string parameters;
  for (const auto& [name, value] : job.parameters)
    parameters += fmt::format("{}<code>{}</code> = {}", parameters.empty() ? "" : "<br>",
                              escape_html(name), escape_html(cell_text(value)));
  std::string content;
  if (const auto residual = page.residual.find(job.number); residual != page.residual.end())
    content = plots.figures({residual->second});
  content += shape_figures(job);
  return fmt::format("<h2 id=\"job-{0}\">Job #{0}</h2>\n<p>id <code>{1}</code><br>{2}</p>\n{3}",
                     job.number, escape_html(job.job.id), parameters, figure_row(content));
}

}  // namespace

std::string html_report(const SweepReport& report, Gnuplot& gnuplot) {
  PlotFigures plots;
  const PagePlots page = collect_plots(report, plots);
  plots.draw(gnuplot);
  std::string body = overview(report);
  body += "<h2>Jobs</h2>\n" + html_table(jobs_table(report));
  if (const Table previews = preview_table(report); !previews.rows.empty())
    body += fmt::format("<h2>Coarse-first selection</h2>\n<p>{}</p>\n{}",
                        escape_html(db::describe(report.refine)), html_table(previews));
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
