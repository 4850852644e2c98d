// CSV and Markdown printing of tables.

#include "reports/report_tables.hpp"

#include <gtest/gtest.h>

#include <algorithm>

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

}  // namespace
}  // namespace psq::reports
