#pragma once
// report.html: one self-contained page (no network resources) with the sweep's tables, the
// plots drawn by gnuplot (SVG images inlined as data: URIs) and a picture of each level's
// final shape (inline SVG).

#include <string>

#include "reports/gnuplot.hpp"
#include "reports/report_model.hpp"

namespace psq::reports {

/// The HTML page of a sweep report. Plots: time per level and error against run time (when
/// they have points), the sweep plots, and per finished job its residual plot; pictures: one
/// per level of a finished job with a readable checkpoint. Unfinished and failed jobs appear
/// in the tables only. Throws what Gnuplot::render_svgs throws.
std::string html_report(const SweepReport& report, Gnuplot& gnuplot);

/// A page linking the reports of several sweeps: (sweep name, relative link, summary line).
struct SweepLink {
  std::string name;
  std::string href;
  std::string summary;
};
std::string html_index(const std::vector<SweepLink>& sweeps);

}  // namespace psq::reports
