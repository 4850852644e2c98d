// CSV and Markdown printing of tables.

#include "reports/report_tables.hpp"

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <algorithm>

#include "reports/parameters.hpp"

namespace psq::reports {
namespace {

TEST(ReportTables, CsvQuotesOnlyFieldsThatNeedIt) {
  const Table table{{"id", "error"},
                    {{"a1", "plain"}, {"b2", "diverged, \"badly\""}, {"c3", "two\nlines"}}};
  EXPECT_EQ(to_csv(table),
            "id,error\r\na1,plain\r\nb2,\"diverged, \"\"badly\"\"\"\r\nc3,\"two\nlines\"\r\n");
}

TEST(ReportTables, MarkdownEscapesPipesAndLineBreaks) {
  const Table table{{"#", "note"}, {{"1", "a|b\nc"}}};
  EXPECT_EQ(to_markdown(table), "| # | note |\n| --- | --- |\n| 1 | a\\|b c |\n");
}

TEST(ReportTables, ReadableNumbersHaveFourSignificantDigits) {
  EXPECT_EQ(readable_number(1.0 / 3.0), "0.3333");
  EXPECT_EQ(readable_number(1.23456e-7), "1.235e-07");
  EXPECT_EQ(readable_number(std::nullopt), "");
}

TEST(ReportTables, RefinementsHaveOneRowPerRefinedLevelAndEmptyCellsForMissingStatistics) {
  SweepReport report;
  JobReport job;
  job.number = 3;
  LevelReport coarse;  // level 0: nothing refined into it
  LevelReport fine;
  fine.level = 1;
  fine.refinement = {{"expansions", 18.0}, {"final_gap", 1.129e-4}, {"seconds", 0.88}};
  job.levels = {coarse, fine};
  report.jobs = {job};
  const Table table = refinements_table(report);
  ASSERT_EQ(table.rows.size(), 1u);
  const auto cell = [&](const std::string& column) {
    const auto found = std::find(table.header.begin(), table.header.end(), column);
    EXPECT_NE(found, table.header.end()) << column;
    return table.rows[0][static_cast<std::size_t>(found - table.header.begin())];
  };
  EXPECT_EQ(cell("#"), "3");
  EXPECT_EQ(cell("level"), "1");
  EXPECT_EQ(cell("expansions"), "18");
  EXPECT_EQ(cell("final gap (m)"), "0.0001129");
  EXPECT_EQ(cell("total (s)"), "0.88");
  EXPECT_EQ(cell("stretch after"), "");  // no strain limit: no correction ran

  report.jobs[0].levels[1].refinement.clear();  // a direct solve, or a contact-free scene
  EXPECT_TRUE(refinements_table(report).rows.empty());
}

/// A finished job of `method` at the design point `thickness` that took `seconds`.
JobReport timed_job(int number, db::Method method, int depth, double thickness, double seconds) {
  JobReport job;
  job.number = number;
  job.job.id = fmt::format("job{:05}", number);
  job.job.state = db::JobState::done;
  job.job.method = method;
  job.job.depth = method == db::Method::progressive ? depth : 1;
  job.job.parameters = {{"depth", depth},
                        {"overrides", {{"shell.s.material.thickness", thickness}}},
                        {"scene", "fnv1a64:0000000000000001"}};
  job.parameters = flatten_parameters(job.job.parameters);
  job.outputs.total_seconds = seconds;
  return job;
}

TEST(ReportTables, SpeedUpsCompareEachHierarchyJobWithBothDirectBaselinesOfItsDesignPoint) {
  SweepReport report;
  report.swept_parameters = {"depth", "method", "overrides.shell.s.material.thickness"};
  report.jobs = {timed_job(1, db::Method::direct, 1, 1e-3, 10.0),
                 timed_job(2, db::Method::direct_final, 1, 1e-3, 6.0),
                 timed_job(3, db::Method::progressive, 3, 1e-3, 2.0),
                 timed_job(4, db::Method::coarse_prolonged, 3, 1e-3, 0.5),
                 // Another design point with no direct baseline: no row.
                 timed_job(5, db::Method::progressive, 3, 2e-3, 1.0),
                 // Only the every-frame direct solve at this one: its baseline cells stay empty.
                 timed_job(6, db::Method::direct, 1, 3e-3, 4.0),
                 timed_job(7, db::Method::progressive, 2, 3e-3, 1.0)};
  const Table table = speedup_table(report);
  ASSERT_EQ(table.rows.size(), 3u);
  // The point's parameters, and the method (with its depth) once.
  EXPECT_EQ(std::count(table.header.begin(), table.header.end(), "method"), 1);
  EXPECT_EQ(std::count(table.header.begin(), table.header.end(), "depth"), 0);
  const auto cell = [&](std::size_t row, const std::string& column) {
    const auto found = std::find(table.header.begin(), table.header.end(), column);
    EXPECT_NE(found, table.header.end()) << column;
    return table.rows[row][static_cast<std::size_t>(found - table.header.begin())];
  };
  EXPECT_EQ(cell(0, "#"), "3");
  EXPECT_EQ(cell(0, "overrides.shell.s.material.thickness"), "0.001");
  EXPECT_EQ(cell(0, "method"), "progressive, 3 levels");
  EXPECT_EQ(cell(0, "speed-up over direct_final"), "3");
  EXPECT_EQ(cell(0, "speed-up over direct"), "5");
  EXPECT_EQ(cell(1, "method"), "coarse of 3 levels, prolonged");
  EXPECT_EQ(cell(1, "speed-up over direct_final"), "12");
  EXPECT_EQ(cell(2, "#"), "7");
  EXPECT_EQ(cell(2, "direct_final time (s)"), "");
  EXPECT_EQ(cell(2, "speed-up over direct_final"), "");
  EXPECT_EQ(cell(2, "speed-up over direct"), "4");

  report.jobs[1].job.state = db::JobState::failed;  // an unfinished baseline does not count
  EXPECT_EQ(speedup_table(report).rows[0][table.header.size() - 3], "");
}

}  // namespace
}  // namespace psq::reports
