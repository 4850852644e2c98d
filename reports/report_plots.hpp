#pragma once
// The plots of a sweep report, as data for gnuplot. Only finished jobs are plotted.

#include <string>
#include <vector>

#include "reports/gnuplot.hpp"
#include "reports/report_model.hpp"

namespace psq::reports {

/// Residual against iteration (1-based, counted through the level's frames), log scale, one
/// curve per level of the job.
PlotSpec residual_plot(const JobReport& job);

/// Seconds per level against the level, log scale, one curve per finished job.
PlotSpec time_per_level_plot(const SweepReport& report);

/// Error to the finest level against the run time so far (the sum of the seconds of the
/// levels up to and including it), log scales, one curve per finished job through its levels.
/// The finest level's error is 0 and cannot be drawn on a log scale.
PlotSpec error_against_time_plot(const SweepReport& report);

/// For each numeric swept parameter and each job output (max displacement, elastic energy,
/// time): the output against the parameter, one curve per combination of the other swept
/// parameters. A logarithmic axis is used where positive values span a factor of 20 or more.
std::vector<PlotSpec> sweep_plots(const SweepReport& report);

}  // namespace psq::reports
