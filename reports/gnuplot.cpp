#include "reports/gnuplot.hpp"

#include <fmt/format.h>

#include <cmath>

#include "engine/core/atomic_file.hpp"
#include "engine/core/error.hpp"
#include "reports/child_process.hpp"
#include "reports/html_text.hpp"

namespace psq::reports {
namespace {

bool drawable(const PlotSpec& plot, const std::pair<double, double>& point) {
  const auto [x, y] = point;
  return std::isfinite(x) && std::isfinite(y) && (!plot.log_x || x > 0) && (!plot.log_y || y > 0);
}

/// A gnuplot single-quoted string on one line: no escapes are interpreted, a quote is doubled.
std::string quoted(const std::string& text) {
  return "'" + one_line_escaped(text, '\'', "''") + "'";
}

std::string style_name(PlotSpec::Style style, int marker) {
  const int point_type = marker > 0 ? marker : 7;
  switch (style) {
    case PlotSpec::Style::lines:
      return "lines lw 1.5";
    case PlotSpec::Style::points:
      return fmt::format("points pt {} ps 0.8", point_type);
    case PlotSpec::Style::linespoints:
      return fmt::format("linespoints lw 1.5 pt {} ps 0.6", point_type);
    case PlotSpec::Style::thick_linespoints:
      return fmt::format("linespoints lw 3 dt 2 pt {} ps 1.2", point_type);
  }
  return "linespoints";
}

/// Throws InputError with the file system's reason if `scratch` has no room left: gnuplot says
/// nothing when it cannot write a plot (a full disk), so a missing plot is put to the file system
/// before gnuplot is blamed.
void require_room(const std::filesystem::path& scratch, const std::string& title) {
  try {
    write_file_atomically(scratch / "room", std::string(4096, ' '));
  } catch (const InputError& error) {
    throw InputError(fmt::format("gnuplot could not draw the plot '{}' ({})", title, error.what()));
  }
}

}  // namespace

bool has_drawable_points(const PlotSpec& plot) {
  for (const PlotSeries& series : plot.series)
    for (const auto& point : series.points)
      if (drawable(plot, point)) return true;
  return false;
}

std::string gnuplot_script(const PlotSpec& plot, const std::filesystem::path& output) {
  std::string script;
  script +=
      fmt::format("set terminal svg size 640,{} font 'Sans,11' background rgb 'white' noenhanced\n",
                  plot.height);
  script += fmt::format("set output {}\n", quoted(output.string()));
  script += fmt::format("set title {}\n", quoted(plot.title));
  script +=
      fmt::format("set xlabel {}\nset ylabel {}\n", quoted(plot.x_label), quoted(plot.y_label));
  // The legend goes below the plot, where long labels do not squeeze it; the offsets keep
  // points off the frame.
  script += "set grid\nset key below\n";
  script += "set offsets graph 0.04, graph 0.04, graph 0.04, graph 0.04\n";
  if (plot.log_x) script += "set logscale x 10\nset format x '%.0e'\n";
  if (plot.log_y) script += "set logscale y 10\nset format y '%.0e'\n";
  if (plot.integer_x) script += "set xtics 1\n";
  std::vector<std::string> clauses;
  for (std::size_t s = 0; s < plot.series.size(); ++s) {
    std::string block;
    for (const auto& point : plot.series[s].points)
      if (drawable(plot, point))
        block += fmt::format("{:.17g} {:.17g}\n", point.first, point.second);
    if (block.empty()) continue;
    script += fmt::format("$series{} << EOD\n{}EOD\n", s, block);
    const PlotSeries& series = plot.series[s];
    clauses.push_back(
        fmt::format("$series{} using 1:2 with {}{} {}", s,
                    style_name(series.style.value_or(plot.style), series.marker),
                    series.colour.empty() ? "" : fmt::format(" lc rgb {}", quoted(series.colour)),
                    series.title.empty() ? "notitle" : "title " + quoted(series.title)));
  }
  script += "plot ";
  for (std::size_t c = 0; c < clauses.size(); ++c) script += (c ? ", \\\n     " : "") + clauses[c];
  return script + "\n";
}

Gnuplot::Gnuplot(std::string program, std::filesystem::path scratch)
    : program_(std::move(program)), scratch_(std::move(scratch)) {}

std::vector<std::string> Gnuplot::render_svgs(const std::vector<PlotSpec>& plots) {
  if (plots.empty()) return {};
  // One process for all plots: starting gnuplot costs more than drawing a plot.
  const int run = runs_++;
  const auto image = [&](std::size_t p) { return scratch_ / fmt::format("run{}-{}.svg", run, p); };
  const std::filesystem::path script = scratch_ / fmt::format("run{}.gp", run);
  write_file_atomically(script, [&](std::ostream& out) {
    for (std::size_t p = 0; p < plots.size(); ++p)
      out << gnuplot_script(plots[p], image(p)) << "reset\n";
  });
  ChildExit exit;
  try {
    exit = run_child(program_, {script.string()}, scratch_ / fmt::format("run{}.err", run));
  } catch (const InputError& e) {
    throw InputError(
        fmt::format("{}; the report draws its plots with gnuplot: install it "
                    "(Debian package gnuplot-nox, see scripts/setup.sh) or name it "
                    "with --gnuplot PATH",
                    e.what()));
  }
  if (exit.status != 0)
    throw Error(fmt::format("gnuplot ('{}') failed with status {} on {}: {}", program_, exit.status,
                            script.string(), exit.errors));
  std::vector<std::string> svgs;
  for (std::size_t p = 0; p < plots.size(); ++p) {
    svgs.push_back(read_child_output(image(p)));
    if (svgs.back().find("</svg>") == std::string::npos) {
      require_room(scratch_, plots[p].title);
      throw Error(fmt::format("gnuplot ('{}') did not draw the plot '{}': {}", program_,
                              plots[p].title, exit.errors));
    }
  }
  return svgs;
}

}  // namespace psq::reports
