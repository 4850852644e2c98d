// The report's plots as data: convergence per Newton solve grouped by frame, one sweep plot per
// output against the axis parameter with zipped parameters folded into the axis, and the
// hierarchy cache's hits and saved time.

#include "reports/report_plots.hpp"

#include <gtest/gtest.h>

namespace psq::reports {
namespace {

/// A finished job with the given parameters and outputs.
JobReport finished_job(int number, std::map<std::string, nlohmann::json> parameters,
                       double displacement) {
  JobReport job;
  job.number = number;
  job.job.state = db::JobState::done;
  job.parameters = std::move(parameters);
  job.outputs.max_displacement = displacement;
  return job;
}

TEST(ConvergencePlots, OneCurvePerSolveTheSolvesOfAFrameShareColourAndLegendEntry) {
  JobReport job = finished_job(7, {}, 0.0);
  job.job.depth = 2;
  job.levels.resize(2);
  job.levels[0].level = 0;
  job.levels[0].solves = {{1, {1.0, 1e-3, 1e-9}}, {2, {0.5, 1e-6}}, {2, {1e-2, 1e-8}}};
  job.levels[1].level = 1;  // no solves (no readable checkpoint): no plot

  const std::vector<PlotSpec> plots = convergence_plots(job);
  ASSERT_EQ(plots.size(), 1u);
  const PlotSpec& plot = plots.front();
  EXPECT_NE(plot.title.find("#7, level 0"), std::string::npos) << plot.title;
  EXPECT_TRUE(plot.log_y);
  ASSERT_EQ(plot.series.size(), 3u);
  EXPECT_EQ(plot.series[0].title, "frame 1");
  EXPECT_EQ(plot.series[1].title, "frame 2");
  EXPECT_EQ(plot.series[2].title, "");  // frame 2's settling step: no second legend entry
  EXPECT_EQ(plot.series[1].colour, plot.series[2].colour);
  EXPECT_NE(plot.series[0].colour, plot.series[1].colour);
  // Each solve starts again at iteration 0 (not one line through every frame's iterations).
  ASSERT_EQ(plot.series[2].points.size(), 2u);
  EXPECT_EQ(plot.series[2].points[0], std::make_pair(0.0, 1e-2));
  EXPECT_EQ(plot.series[2].points[1], std::make_pair(1.0, 1e-8));
  EXPECT_TRUE(plot.integer_x);  // short solves: a tic per iteration

  job.levels[0].solves = {{1, std::vector<double>(40, 1.0)}};
  EXPECT_FALSE(convergence_plots(job).front().integer_x);  // 40 tics would crowd the axis
}

TEST(ProbePlots, OnePlotPerProbeOfTheFinestLevelAgainstTheLoadScale) {
  JobReport job = finished_job(3, {}, 0.0);
  job.levels.resize(2);
  // A coarse level's frames are not the answer: only the finest level's are plotted.
  job.levels[0].frames = {{1, 0.5, {{"coarse_only", "displacement", {1, 1, 1}}}}};
  job.levels[1].frames = {
      {1, 0.5, {{"tip", "displacement", {0.3, 1e-13, -0.4}}, {"clamp", "reaction", {0, 0, -2}}}},
      {2, 1.0, {{"tip", "displacement", {0.6, 0, -0.8}}, {"clamp", "reaction", {0, 0, -4}}}}};
  const std::vector<PlotSpec> plots = probe_plots(job);
  ASSERT_EQ(plots.size(), 2u);
  EXPECT_EQ(plots[0].title, "job #3: probe 'tip' against the load scale");
  EXPECT_EQ(plots[0].x_label, "load scale");
  EXPECT_EQ(plots[0].y_label, "mean displacement (m)");
  // x and z, the magnitude; y is at round-off (1e-13) and left out.
  ASSERT_EQ(plots[0].series.size(), 3u);
  EXPECT_EQ(plots[0].series[0].title, "x");
  EXPECT_EQ(plots[0].series[1].title, "z");
  EXPECT_EQ(plots[0].series[2].title, "magnitude");
  const std::vector<std::pair<double, double>> magnitude{{0.5, 0.5}, {1.0, 1.0}};
  ASSERT_EQ(plots[0].series[2].points.size(), 2u);
  for (std::size_t k = 0; k < 2; ++k) {
    EXPECT_EQ(plots[0].series[2].points[k].first, magnitude[k].first);
    EXPECT_NEAR(plots[0].series[2].points[k].second, magnitude[k].second, 1e-15);
  }
  EXPECT_EQ(plots[1].y_label, "reaction (N)");
  EXPECT_EQ(plots[1].series[0].points.back(), std::make_pair(1.0, -4.0));

  job.levels[1].frames.clear();
  EXPECT_TRUE(probe_plots(job).empty());
}

TEST(NewtonSolves, ASettlingStepStartsANewSolveWhereTheCountRepeatsAndAFrameWhereItChanges) {
  // As psq work records them: frame 1 is a step of 2 iterations ended by a record without a
  // step, then a settling step continuing the frame's count; frame 2 is already at rest.
  const auto record = [](int frame, int iteration, double residual, double step) {
    return IterationRecord{frame, iteration, 0.0, residual, 0.0, step, 0.0};
  };
  const std::vector<NewtonSolve> solves = newton_solves({record(1, 0, 1e-1, 1.0),
                                                         record(1, 1, 1e-4, 1.0),
                                                         record(1, 2, 1e-9, 0.0),
                                                         record(1, 2, 1e-3, 1.0),
                                                         record(1, 3, 1e-10, 0.0),
                                                         record(2, 0, 1e-10, 0.0)});
  ASSERT_EQ(solves.size(), 3u);
  EXPECT_EQ(solves[0].frame, 1);
  EXPECT_EQ(solves[0].residuals, (std::vector<double>{1e-1, 1e-4, 1e-9}));
  EXPECT_EQ(solves[1].frame, 1);
  EXPECT_EQ(solves[1].residuals, (std::vector<double>{1e-3, 1e-10}));
  EXPECT_EQ(solves[2].frame, 2);
  EXPECT_EQ(solves[2].residuals, (std::vector<double>{1e-10}));
  EXPECT_TRUE(newton_solves({}).empty());
}

TEST(ConvergencePlots, ManyFramesKeepAShortLegendWithTheFirstAndLastFrame) {
  JobReport job = finished_job(1, {}, 0.0);
  job.levels.resize(1);
  for (int frame = 1; frame <= 40; ++frame) job.levels[0].solves.push_back({frame, {1.0, 0.1}});
  const PlotSpec plot = convergence_plots(job).front();
  std::vector<std::string> titles;
  for (const PlotSeries& series : plot.series)
    if (!series.title.empty()) titles.push_back(series.title);
  EXPECT_LE(titles.size(), 11u);
  EXPECT_GE(titles.size(), 5u);
  EXPECT_EQ(titles.front(), "frame 1");
  EXPECT_EQ(titles.back(), "frame 40");
}

TEST(SweepPlots, OnePlotPerOutputAgainstTheWidestParameterZippedOnesOnTheAxis) {
  // thickness: 3 values; modulus follows it (one value per thickness, two in all); load: 2
  // values crossed with thickness; depth alternates, so it follows nothing.
  SweepReport report;
  report.swept_parameters = {"depth", "load", "modulus", "thickness"};
  int number = 0;
  for (double load : {1.0, 2.0})
    for (double thickness : {1e-3, 2e-3, 3e-3})
      report.jobs.push_back(finished_job(
          ++number,
          {{"depth", number % 2 + 1},
           {"load", load},
           {"modulus", thickness < 2.5e-3 ? 1e6 : 2e6},
           {"thickness", thickness}},
          load * thickness));
  const std::vector<PlotSpec> plots = sweep_plots(report);
  ASSERT_EQ(plots.size(), 1u);  // only the max displacement is known
  const PlotSpec& plot = plots.front();
  EXPECT_EQ(plot.x_label, "thickness (with modulus)");
  EXPECT_EQ(plot.title, "max displacement against thickness");
  std::size_t points = 0;
  for (const PlotSeries& series : plot.series) {
    EXPECT_NE(series.title.find("load="), std::string::npos) << series.title;
    EXPECT_EQ(series.title.find("modulus"), std::string::npos) << series.title;
    points += series.points.size();
  }
  EXPECT_EQ(points, 6u);
  EXPECT_EQ(plot.series.size(), 4u);  // (depth, load) combinations
}

TEST(SweepPlots, NoNumericSweptParameterNoPlots) {
  SweepReport report;
  report.swept_parameters = {"scene"};
  report.jobs.push_back(finished_job(1, {{"scene", "a.toml"}}, 1.0));
  report.jobs.push_back(finished_job(2, {{"scene", "b.toml"}}, 2.0));
  EXPECT_TRUE(sweep_plots(report).empty());
}

TEST(HierarchyCacheSummary, HitsSaveTheMeanBuildTimeOfTheirKeyLessTheirOwnRead) {
  const HierarchyCacheSummary summary = summarize_cache_uses({
      {"a", false, 4.0},  // two builds of a (two workers raced): mean 5 s
      {"a", false, 6.0},
      {"a", true, 0.5},   // saves 4.5 s
      {"a", true, 1.0},   // saves 4 s
      {"b", false, 2.0},
      {"b", true, 0.25},  // saves 1.75 s
      {"c", true, 0.1},   // built before this sweep: saving unknown
  });
  EXPECT_EQ(summary.hits, 4);
  EXPECT_EQ(summary.builds, 3);
  EXPECT_DOUBLE_EQ(summary.build_seconds, 12.0);
  EXPECT_DOUBLE_EQ(summary.hit_seconds, 1.85);
  EXPECT_DOUBLE_EQ(summary.saved_seconds, 4.5 + 4.0 + 1.75);
  EXPECT_EQ(summary.hits_without_build, 1);
  EXPECT_EQ(summarize_cache_uses({}).hits, 0);
}

}  // namespace
}  // namespace psq::reports
