// Reading CCD benchmark query files: exact rational coordinates rounded correctly, the query
// kind told by the folder, and every malformed input reported with its file and line.

#include <gtest/gtest.h>

#include <limits>
#include <stdexcept>
#include <string>

#include "engine/contact/ccd_query_file.hpp"
#include "engine/core/error.hpp"
#include "support/test_paths.hpp"

namespace psq {
namespace {

/// 2^k in decimal, by repeated doubling of a digit string (independent of any big-number
/// library the reader uses).
std::string power_of_two(int k) {
  std::string digits = "1";  // least significant digit first
  for (int i = 0; i < k; ++i) {
    int carry = 0;
    for (char& c : digits) {
      const int doubled = 2 * (c - '0') + carry;
      c = char('0' + doubled % 10);
      carry = doubled / 10;
    }
    if (carry) digits.push_back(char('0' + carry));
  }
  return {digits.rbegin(), digits.rend()};
}

TEST(RationalToDouble, RoundsToNearestLikeIeeeDivision) {
  EXPECT_EQ(rational_to_double("1", "3"), 1.0 / 3.0);
  EXPECT_EQ(rational_to_double("1", "10"), 0.1);
  EXPECT_EQ(rational_to_double("-7", "2"), -3.5);
  EXPECT_EQ(rational_to_double("+5", "+1"), 5.0);
  EXPECT_EQ(rational_to_double("22", "-7"), 22.0 / -7.0);
  EXPECT_EQ(rational_to_double("0", "9"), 0.0);
  // Numerators and denominators far beyond 64 bits.
  EXPECT_EQ(rational_to_double(power_of_two(300), power_of_two(299)), 2.0);
  // Values from the shared set; expected values from Python's float(Fraction(n, d)).
  EXPECT_EQ(rational_to_double("2130248372295421", "40564819207303340847894502572032"),
            0x1.e45cc660e5bf4p-55);
}

TEST(RationalToDouble, BreaksTiesToEvenAndSeesBeyondTheTie) {
  // 2⁵³ + 1 lies halfway between two doubles: ties go to the even one, 2⁵³.
  EXPECT_EQ(rational_to_double("9007199254740993", "1"), 9007199254740992.0);
  EXPECT_EQ(rational_to_double("9007199254740995", "1"), 9007199254740996.0);
  // (2⁵³ + 1) + 2⁻⁷⁰ is just above the tie and must round up. A conversion through a 64-bit
  // long double would lose the 2⁻⁷⁰ and round down.
  EXPECT_EQ(rational_to_double("10633823966279328163822077199654060033", power_of_two(70)),
            9007199254740994.0);
}

TEST(RationalToDouble, RoundsSubnormalsOnce) {
  const double smallest = std::numeric_limits<double>::denorm_min();  // 2⁻¹⁰⁷⁴
  EXPECT_EQ(rational_to_double("1", power_of_two(1074)), smallest);
  EXPECT_EQ(rational_to_double("3", power_of_two(1075)), 2 * smallest);  // 1.5 → even 2
  EXPECT_EQ(rational_to_double("7", power_of_two(1075)), 4 * smallest);  // 3.5 → even 4
  EXPECT_EQ(rational_to_double("1", power_of_two(1076)), 0.0);           // 0.25 → 0
  // The normal range is unaffected afterwards.
  EXPECT_EQ(rational_to_double("1", "3"), 1.0 / 3.0);
}

TEST(RationalToDouble, RejectsMalformedIntegersZeroDenominatorsAndHugeValues) {
  for (const auto& [numerator, denominator] :
       std::vector<std::pair<std::string, std::string>>{{"1.5", "2"},
                                                        {"", "1"},
                                                        {"1", ""},
                                                        {"-", "1"},
                                                        {"1 2", "3"},
                                                        {"0x10", "1"},
                                                        {"1", "0"},
                                                        {"5", "-0"}})
    EXPECT_THROW(rational_to_double(numerator, denominator), std::invalid_argument)
        << numerator << "/" << denominator;
  EXPECT_THROW(rational_to_double("1" + std::string(400, '0'), "1"), std::out_of_range);
}

TEST(CcdQueryKind, IsToldByTheNearestKindFolder) {
  EXPECT_EQ(ccd_query_kind("data/scene/vertex-face/q.csv"), CcdQueryKind::vertex_face);
  EXPECT_EQ(ccd_query_kind("/x/edge-edge/more/q.csv"), CcdQueryKind::edge_edge);
  EXPECT_EQ(ccd_query_kind("/x/vertex-face/edge-edge/q.csv"), CcdQueryKind::edge_edge);
  try {
    ccd_query_kind("/x/queries/q.csv");
    FAIL() << "a file outside a kind folder was accepted";
  } catch (const InputError& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("/x/queries/q.csv"), std::string::npos) << message;
    EXPECT_NE(message.find("vertex-face"), std::string::npos) << message;
    EXPECT_NE(message.find("edge-edge"), std::string::npos) << message;
  }
}

/// Eight rows of one query: vertex i at t = 0 is (i, 1/2, -i/4), at t = 1 (i, 3, 0).
std::string query_rows(int truth) {
  std::string rows;
  for (int i = 0; i < 4; ++i)
    rows +=
        std::to_string(i) + ",1, 1,2, -" + std::to_string(i) + ",4," + std::to_string(truth) + "\n";
  for (int i = 0; i < 4; ++i)
    rows += std::to_string(i) + ",1,3,1,0,1," + std::to_string(truth) + "\r\n";
  return rows;
}

TEST(ReadCcdQueries, ReadsPositionsTruthAndFirstLines) {
  const auto dir = test::fresh_temp_dir("ccd-queries");
  const auto file = test::write_file(dir / "q.csv", query_rows(1) + "\n  \n" + query_rows(0));
  const std::vector<CcdQuery> queries = read_ccd_queries(file);
  ASSERT_EQ(queries.size(), 2u);
  EXPECT_TRUE(queries[0].truth);
  EXPECT_FALSE(queries[1].truth);
  EXPECT_EQ(queries[0].line, 1);
  EXPECT_EQ(queries[1].line, 11);  // after two blank lines
  for (const CcdQuery& query : queries)
    for (int i = 0; i < 4; ++i) {
      EXPECT_EQ(query.start[i], Eigen::Vector3d(i, 0.5, -i / 4.0)) << i;
      EXPECT_EQ(query.end[i], Eigen::Vector3d(i, 3, 0)) << i;
    }
  EXPECT_TRUE(read_ccd_queries(test::write_file(dir / "empty.csv", "")).empty());
}

/// The message of the InputError that reading `text` raises ("accepted" if none).
std::string read_error(const std::string& text) {
  const auto file = test::write_file(test::fresh_temp_dir("ccd-queries") / "bad.csv", text);
  try {
    read_ccd_queries(file);
  } catch (const InputError& e) {
    return e.what();
  }
  return "accepted";
}

void expect_located(const std::string& message, const std::string& location,
                    const std::string& detail) {
  EXPECT_NE(message.find("bad.csv:" + location + ":"), std::string::npos) << message;
  EXPECT_NE(message.find(detail), std::string::npos) << message;
}

TEST(ReadCcdQueries, MalformedRowsNameFileLineAndProblem) {
  const std::string good = query_rows(1);
  auto with_line_3 = [&](const std::string& row) {
    std::string text = good;
    const std::size_t begin = text.find('\n', text.find('\n') + 1) + 1;
    return text.replace(begin, text.find('\n', begin) - begin, row);
  };
  expect_located(read_error(with_line_3("1,1,2,1,3,1")), "3", "found 6");
  expect_located(read_error(with_line_3("1,1,2,1,3,1,1,9")), "3", "found 8");
  expect_located(read_error(with_line_3("1,1,2.5,1,3,1,1")), "3", "y coordinate 2.5/1");
  expect_located(read_error(with_line_3("1,1,2,1,3,0,1")), "3", "zero denominator");
  expect_located(read_error(with_line_3("1,1,2,1,3,1,2")), "3", "truth");
  expect_located(read_error(with_line_3("1,1,2,1,3,1,0")), "3", "differs");
  expect_located(read_error(good + good.substr(0, good.find('\n') + 1)), "9", "1 of its 8 rows");
}

TEST(ReadCcdQueries, MissingFileIsAnInputError) {
  const auto missing = test::fresh_temp_dir("ccd-queries") / "none.csv";
  try {
    read_ccd_queries(missing);
    FAIL() << "a missing file was read";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("none.csv"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace psq
