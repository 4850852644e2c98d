#pragma once
// The plots of a sweep report, as data for gnuplot. Only finished jobs are plotted.

#include <string>
#include <vector>

#include "reports/gnuplot.hpp"
#include "reports/report_model.hpp"

namespace psq::reports {

/// Per level of the job with recorded Newton solves, its convergence: the residual ‖∇E‖ against
/// the Newton iteration within each solve (log scale), one curve per solve; the solves of one
/// frame (its step and any settling steps) share a colour and one legend entry, frames coloured
/// in order. Levels without solves have no plot.
std::vector<PlotSpec> convergence_plots(const JobReport& job);

/// Per probe of the job's finest level, its reading against the load scale, frame by frame: the
/// components that are not negligible (below 1e-9 of the largest magnitude at every frame) and
/// the magnitude, one curve each; metres for a displacement probe, newtons for a reaction. No
/// plots without probe readings.
std::vector<PlotSpec> probe_plots(const JobReport& job);

/// Seconds per level against the level, log scale, one curve per finished job.
PlotSpec time_per_level_plot(const SweepReport& report);

/// Error to the finest level against the run time so far (the sum of the seconds of the
/// levels up to and including it), log scales, one curve per finished job through its levels,
/// labelled with its method (method_label). The finest level's error
/// is 0 and cannot be drawn on a log scale.
PlotSpec error_against_time_plot(const SweepReport& report);

/// Run time against error (benchmark_scenes), one plot per scene: every level of every
/// finished job as a point (wall time up to the level, error to its design point's direct_final
/// reference), log scales, one curve per job through its levels, coloured by its method (one
/// legend entry per method) and marked by its design point, and each design point's Pareto
/// front as a thick dashed black line with its marker through the points it selects. The
/// reference's own point (error 0) cannot be drawn on a log scale: its time is in its front's
/// legend entry, and the benchmark table lists it. With several design points (a resolution sweep),
/// each is measured against its own reference, which the title says.
std::vector<PlotSpec> benchmark_plots(const SweepReport& report);

/// One plot per job output (max displacement, elastic energy, time) against the sweep's axis
/// parameter: the numeric swept parameter with the most distinct values among finished jobs.
/// One curve per combination of the swept parameters that vary independently of the axis;
/// parameters zipped with it (one value per axis value) only label the axis. A logarithmic
/// axis is used where positive values span a factor of 20 or more. No plots without a numeric
/// swept parameter.
std::vector<PlotSpec> sweep_plots(const SweepReport& report);

}  // namespace psq::reports
