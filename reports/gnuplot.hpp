#pragma once
// Plots drawn by gnuplot (a child process running a script file) as SVG text.

#include <filesystem>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace psq::reports {

/// How a curve is drawn; `thick_linespoints` (thick, dashed, large markers) stands out over
/// the others: a Pareto front over the points it selects.
enum class PlotStyle { lines, points, linespoints, thick_linespoints };

/// One curve: its legend title (empty: not in the legend) and its (x, y) points in drawing
/// order; `colour` ("#rrggbb") overrides gnuplot's colour sequence, so that several curves can
/// read as one group; `style` overrides the plot's style for this curve, and `marker` its point
/// marker (gnuplot's point type; 0: a filled circle), so that curves of one colour can still be
/// told apart.
struct PlotSeries {
  std::string title;
  std::vector<std::pair<double, double>> points;
  std::string colour;
  std::optional<PlotStyle> style = std::nullopt;
  int marker = 0;
};

/// A 2D plot. On a logarithmic axis, points with a non-positive coordinate are left out;
/// non-finite points are always left out.
struct PlotSpec {
  using Style = PlotStyle;
  std::string title;
  std::string x_label;
  std::string y_label;
  bool log_x = false;
  bool log_y = false;
  bool integer_x = false;  ///< x tics on whole numbers only (levels, job numbers)
  int height = 400;        ///< pixels, legend included (the legend goes below the plot)
  Style style = Style::linespoints;
  std::vector<PlotSeries> series;
};

/// True if at least one point of `plot` can be drawn (see PlotSpec).
bool has_drawable_points(const PlotSpec& plot);

/// The gnuplot script that draws `plot` into the SVG file `output`: data inline as data blocks,
/// text not interpreted (noenhanced), strings single-quoted.
std::string gnuplot_script(const PlotSpec& plot, const std::filesystem::path& output);

/// Draws plots with a gnuplot program, using a scratch directory for scripts and images.
class Gnuplot {
 public:
  /// `program`: "gnuplot" (looked up in PATH) or a path to it.
  Gnuplot(std::string program, std::filesystem::path scratch);

  /// Runs gnuplot once on the scripts of all `plots` (gnuplot_script, each followed by a
  /// reset) and returns the SVG of each, in order. Throws InputError if gnuplot cannot be
  /// started (naming the package to install), psq::Error if it fails (with its exit status and
  /// messages) or leaves a plot undrawn. Every plot must have drawable points.
  std::vector<std::string> render_svgs(const std::vector<PlotSpec>& plots);

 private:
  std::string program_;
  std::filesystem::path scratch_;
  int runs_ = 0;
};

}  // namespace psq::reports
