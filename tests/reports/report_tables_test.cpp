// CSV and Markdown printing of tables.

#include "reports/report_tables.hpp"

#include <gtest/gtest.h>

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

}  // namespace
}  // namespace psq::reports
