// Run time against error: the Pareto front on hand-made points, and the benchmark points, table
// and plot of a hand-made sweep of two design points whose errors and times are given.

#include "reports/benchmark.hpp"

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "reports/parameters.hpp"
#include "reports/report_plots.hpp"
#include "reports/report_tables.hpp"

namespace psq::reports {
namespace {

TEST(ReportParetoFront, KeepsThePointsNoOtherBeatsInBothCoordinatesSortedByTheFirst) {
  // (seconds, error), drawn on paper: the front is the staircase 1, 0, 4, 6.
  const std::vector<std::pair<double, double>> points{
      {2.0, 1e-3},  // 0: on the front
      {1.0, 1e-2},  // 1: the fastest
      {3.0, 2e-3},  // 2: slower and worse than 0
      {2.0, 5e-3},  // 3: as fast as 0 but worse
      {4.0, 1e-4},  // 4: on the front
      {5.0, 1e-4},  // 5: as good as 4 but slower
      {6.0, 0.0},   // 6: the reference: exact, the slowest on the front
      {0.5, std::numeric_limits<double>::quiet_NaN()},  // 7: unmeasured: never on the front
      {7.0, 1e-5}};                                     // 8: slower than the exact 6
  EXPECT_EQ(pareto_front(points), (std::vector<std::size_t>{1, 0, 4, 6}));
}

TEST(ReportParetoFront, KeepsEqualPointsAndHandlesNone) {
  EXPECT_EQ(pareto_front({{1.0, 1.0}, {1.0, 1.0}, {2.0, 2.0}}), (std::vector<std::size_t>{0, 1}));
  EXPECT_TRUE(pareto_front({}).empty());
  EXPECT_EQ(pareto_front({{3.0, 0.5}}), (std::vector<std::size_t>{0}));
}

/// A finished job at the design point `edge` whose level l took seconds[l] and has error
/// errors[l] to its reference.
JobReport measured_job(int number, db::Method method, double edge, std::vector<double> seconds,
                       std::vector<double> errors) {
  JobReport job;
  job.number = number;
  job.job.id = fmt::format("job{:05}", number);
  job.job.state = db::JobState::done;
  job.job.method = method;
  job.job.scene = "/library/scenes/drape_sphere.toml";
  job.job.depth = static_cast<int>(seconds.size());
  job.job.parameters = {{"depth", std::max(job.job.depth, 2)},
                        {"overrides", {{"shell.cloth.mesh.edge_length", edge}}},
                        {"scene", "fnv1a64:0000000000000001"}};
  if (method != db::Method::progressive && method != db::Method::direct)
    job.job.parameters["method"] = std::string(db::to_string(method));
  job.parameters = flatten_parameters(job.job.parameters);
  for (std::size_t l = 0; l < seconds.size(); ++l) {
    LevelReport level;
    level.level = static_cast<int>(l);
    level.seconds = seconds[l];
    level.error_to_reference = errors[l];
    job.levels.push_back(level);
  }
  job.outputs.total_seconds = job.seconds_through(job.levels.size() - 1);
  return job;
}

/// Two resolutions: at the coarse one every method; at the fine one no `direct` job, and a
/// progressive job whose finest level is beaten by the coarse-prolonged job's.
SweepReport measured_sweep() {
  SweepReport report;
  report.swept_parameters = {"depth", "method", "overrides.shell.cloth.mesh.edge_length"};
  report.jobs = {measured_job(1, db::Method::direct, 0.08, {12.0}, {1e-6}),
                 measured_job(2, db::Method::direct_final, 0.08, {8.0}, {0.0}),
                 measured_job(3, db::Method::progressive, 0.08, {0.5, 1.5}, {2e-2, 1e-4}),
                 measured_job(4, db::Method::coarse_prolonged, 0.08, {1.0}, {3e-2}),
                 measured_job(5, db::Method::direct_final, 0.04, {40.0}, {0.0}),
                 measured_job(6, db::Method::progressive, 0.04, {2.0, 8.0}, {1e-2, 1e-3}),
                 measured_job(7, db::Method::coarse_prolonged, 0.04, {1.0}, {5e-4}),
                 // A design point without a reference: not compared.
                 measured_job(8, db::Method::progressive, 0.02, {3.0, 9.0}, {1e-2, 1e-3})};
  report.jobs[7].levels[0].error_to_reference.reset();
  report.jobs[7].levels[1].error_to_reference.reset();
  return report;
}

TEST(ReportBenchmark, EachDesignPointIsMeasuredAgainstItsOwnReferenceWithItsOwnFront) {
  const SweepReport report = measured_sweep();
  const std::vector<BenchmarkScene> scenes = benchmark_scenes(report);
  ASSERT_EQ(scenes.size(), 1u);
  EXPECT_EQ(scenes[0].scene, "/library/scenes/drape_sphere.toml");
  ASSERT_EQ(scenes[0].design_points.size(), 2u);
  const BenchmarkDesignPoint& coarse = scenes[0].design_points[0];
  EXPECT_EQ(coarse.label, "edge_length=0.08");
  EXPECT_EQ(coarse.reference->number, 2);
  // #1 (12 s) is beaten by the exact reference (8 s), #4's 3e-2 in 1 s by #3's level 0.
  std::vector<std::pair<int, std::size_t>> front;
  for (const BenchmarkPoint& point : coarse.points)
    if (point.on_front) front.emplace_back(point.job->number, point.level);
  EXPECT_EQ(front, (std::vector<std::pair<int, std::size_t>>{{2, 0}, {3, 0}, {3, 1}}));
  ASSERT_EQ(coarse.points.size(), 5u);
  EXPECT_EQ(coarse.points[3].seconds, 2.0);  // level 1 of #3: both levels' time
  const BenchmarkDesignPoint& fine = scenes[0].design_points[1];
  EXPECT_EQ(fine.reference->number, 5);
  front.clear();
  for (const BenchmarkPoint& point : fine.points)
    if (point.on_front) front.emplace_back(point.job->number, point.level);
  EXPECT_EQ(front, (std::vector<std::pair<int, std::size_t>>{{5, 0}, {7, 0}}));
}

TEST(ReportBenchmark, TheTableGivesEachLevelsTimeErrorSpeedUpsAndWhetherItIsOnTheFront) {
  const Table table = benchmark_table(measured_sweep());
  ASSERT_EQ(table.rows.size(), 9u);  // 5 + 4 levels; the point without a reference has none
  const auto cell = [&](std::size_t row, const std::string& column) {
    const auto found = std::find(table.header.begin(), table.header.end(), column);
    EXPECT_NE(found, table.header.end()) << column;
    return table.rows[row][static_cast<std::size_t>(found - table.header.begin())];
  };
  EXPECT_EQ(std::count(table.header.begin(), table.header.end(), "depth"), 0);
  EXPECT_EQ(cell(0, "overrides.shell.cloth.mesh.edge_length"), "0.08");
  EXPECT_EQ(cell(1, "#"), "2");  // the reference
  EXPECT_EQ(cell(1, "error to direct_final"), "0");
  EXPECT_EQ(cell(1, "speed-up over direct_final"), "1");
  EXPECT_EQ(cell(1, "speed-up over direct"), "1.5");
  EXPECT_EQ(cell(1, "Pareto front"), "yes");
  EXPECT_EQ(cell(3, "method"), "progressive, 2 levels");
  EXPECT_EQ(cell(3, "level"), "1 of 2");
  EXPECT_EQ(cell(3, "time (s)"), "2");
  EXPECT_EQ(cell(3, "error to direct_final"), "0.0001");
  EXPECT_EQ(cell(3, "speed-up over direct_final"), "4");
  EXPECT_EQ(cell(3, "speed-up over direct"), "6");
  EXPECT_EQ(cell(4, "Pareto front"), "");  // #4, beaten by #3's level 0
  EXPECT_EQ(cell(6, "#"), "6");
  EXPECT_EQ(cell(6, "speed-up over direct_final"), "20");
  EXPECT_EQ(cell(6, "speed-up over direct"), "");         // no direct job at this resolution
  EXPECT_EQ(cell(7, "speed-up over direct_final"), "4");  // level 1 of #6: 40 s over 10 s
}

TEST(ReportBenchmark, OnePlotPerSceneWithACurvePerJobAndAFrontPerDesignPoint) {
  const std::vector<PlotSpec> plots = benchmark_plots(measured_sweep());
  ASSERT_EQ(plots.size(), 1u);
  const PlotSpec& plot = plots[0];
  EXPECT_TRUE(plot.log_x && plot.log_y);
  EXPECT_NE(plot.title.find("drape_sphere"), std::string::npos) << plot.title;
  // Two resolutions, each against its own reference: the title says so.
  EXPECT_NE(plot.title.find("of the same mesh"), std::string::npos) << plot.title;
  std::vector<const PlotSeries*> fronts, curves;
  for (const PlotSeries& series : plot.series)
    (series.style == PlotStyle::thick_linespoints ? fronts : curves).push_back(&series);
  ASSERT_EQ(fronts.size(), 2u);
  // The references' points (error 0) cannot be drawn: their times are in the legend.
  EXPECT_EQ(fronts[0]->title, "Pareto front, edge_length=0.08 (direct_final 8 s)");
  EXPECT_EQ(fronts[1]->title, "Pareto front, edge_length=0.04 (direct_final 40 s)");
  EXPECT_EQ(fronts[0]->points,
            (std::vector<std::pair<double, double>>{{0.5, 2e-2}, {2.0, 1e-4}, {8.0, 0.0}}));
  // Every job but the references (error 0 has no place on a log scale): #1, #3, #4, #6, #7,
  // one legend entry per method, a colour per method and a marker per resolution.
  ASSERT_EQ(curves.size(), 5u);
  EXPECT_EQ(curves[0]->title, "direct");
  EXPECT_EQ(curves[1]->title, "progressive, 2 levels");
  EXPECT_EQ(curves[1]->points, (std::vector<std::pair<double, double>>{{0.5, 2e-2}, {2.0, 1e-4}}));
  EXPECT_EQ(curves[3]->title, "");  // #6: progressive again
  EXPECT_EQ(curves[3]->colour, curves[1]->colour);
  EXPECT_NE(curves[2]->colour, curves[1]->colour);
  EXPECT_EQ(curves[1]->marker, fronts[0]->marker);
  EXPECT_EQ(curves[3]->marker, fronts[1]->marker);
  EXPECT_NE(fronts[0]->marker, fronts[1]->marker);
  // Taller than a plain plot by its five legend lines (three methods, two fronts).
  EXPECT_GT(plot.height, PlotSpec().height);
  const std::string script = gnuplot_script(plot, "out.svg");
  EXPECT_NE(script.find("with linespoints lw 3 dt 2 pt 7 ps 1.2 lc rgb '#000000' title "
                        "'Pareto front, edge_length=0.08 (direct_final 8 s)'"),
            std::string::npos)
      << script;
}

TEST(ReportBenchmark, NothingToCompareWithoutAReference) {
  SweepReport report = measured_sweep();
  report.jobs[1].job.state = db::JobState::failed;
  report.jobs[4].job.state = db::JobState::failed;
  EXPECT_TRUE(benchmark_scenes(report).empty());
  EXPECT_TRUE(benchmark_table(report).rows.empty());
  EXPECT_TRUE(benchmark_plots(report).empty());
}

}  // namespace
}  // namespace psq::reports
