// gnuplot scripts and the gnuplot child process.

#include "reports/gnuplot.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "engine/core/error.hpp"
#include "support/test_paths.hpp"

namespace psq::reports {
namespace {

PlotSpec two_curves() {
  PlotSpec plot;
  plot.title = "residual of 'job' #1";
  plot.x_label = "iteration";
  plot.y_label = "residual";
  plot.log_y = true;
  plot.series = {{"level 0", {{1, 1.0}, {2, 0.1}, {3, 0.0}, {4, NAN}, {5, 1e-7}}, {}},
                 {"level_1", {{1, -1.0}}, {}}};
  return plot;
}

TEST(Gnuplot, ScriptQuotesTextAndLeavesOutUndrawablePoints) {
  const std::string script = gnuplot_script(two_curves(), "/tmp/out dir/p.svg");
  EXPECT_NE(script.find("set output '/tmp/out dir/p.svg'"), std::string::npos) << script;
  EXPECT_NE(script.find("set title 'residual of ''job'' #1'"), std::string::npos) << script;
  EXPECT_NE(script.find("noenhanced"), std::string::npos);
  EXPECT_NE(script.find("set logscale y"), std::string::npos);
  EXPECT_EQ(script.find("set logscale x"), std::string::npos);
  // Zero, NaN and the negative point cannot be drawn on the log scale; the second curve is empty.
  EXPECT_NE(
      script.find("$series0 << EOD\n1 1\n2 0.10000000000000001\n5 9.9999999999999995e-08\nEOD"),
      std::string::npos)
      << script;
  EXPECT_EQ(script.find("$series1"), std::string::npos);
  EXPECT_NE(script.find("title 'level 0'"), std::string::npos);
}

TEST(Gnuplot, SeriesWithAColourUseItAndUntitledOnesStayOutOfTheLegend) {
  PlotSpec plot = two_curves();
  plot.series = {{"frame 1", {{0, 1.0}}, "#3b528b"}, {"", {{0, 0.5}}, "#3b528b"}};
  const std::string script = gnuplot_script(plot, "p.svg");
  EXPECT_NE(script.find("$series0 using 1:2 with linespoints lw 1.5 pt 7 ps 0.6 lc rgb '#3b528b' "
                        "title 'frame 1'"),
            std::string::npos)
      << script;
  EXPECT_NE(script.find("$series1 using 1:2 with linespoints lw 1.5 pt 7 ps 0.6 lc rgb '#3b528b' "
                        "notitle"),
            std::string::npos)
      << script;
}

TEST(Gnuplot, DrawablePointsDependOnTheAxes) {
  PlotSpec plot = two_curves();
  plot.series = {{"negative", {{1, -1.0}}, {}}};
  EXPECT_FALSE(has_drawable_points(plot));
  plot.log_y = false;
  EXPECT_TRUE(has_drawable_points(plot));
}

TEST(Gnuplot, DrawsAnSvg) {
  Gnuplot gnuplot("gnuplot", test::fresh_temp_dir("gnuplot_draws"));
  PlotSpec second = two_curves();
  second.title = "second plot";
  second.log_y = false;
  const std::vector<std::string> svgs = gnuplot.render_svgs({two_curves(), second});
  ASSERT_EQ(svgs.size(), 2u);
  for (const std::string& svg : svgs) {
    EXPECT_NE(svg.find("<svg"), std::string::npos);
    EXPECT_NE(svg.find("level 0"), std::string::npos);
    EXPECT_NE(svg.find("</svg>"), std::string::npos);
  }
  EXPECT_NE(svgs[0].find("residual of 'job' #1"), std::string::npos);
  EXPECT_NE(svgs[1].find("second plot"), std::string::npos);
  // The reset between plots: the second one has a linear axis again, so its negative point
  // (level_1) is drawn and named in the legend.
  EXPECT_EQ(svgs[0].find("level_1"), std::string::npos);
  EXPECT_NE(svgs[1].find("level_1"), std::string::npos);
}

TEST(Gnuplot, AMissingProgramNamesThePackageToInstall) {
  Gnuplot gnuplot("/nonexistent/gnuplot", test::fresh_temp_dir("gnuplot_missing"));
  try {
    gnuplot.render_svgs({two_curves()});
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/gnuplot"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("gnuplot-nox"), std::string::npos) << e.what();
  }
}

TEST(Gnuplot, AFailingProgramIsReportedWithItsStatus) {
  Gnuplot gnuplot("false", test::fresh_temp_dir("gnuplot_fails"));
  try {
    gnuplot.render_svgs({two_curves()});
    FAIL() << "no error";
  } catch (const InputError&) {
    FAIL() << "not an input error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("failed with status 1"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace psq::reports
