// Job parameters as flat columns, and which of them a sweep varies.

#include "reports/parameters.hpp"

#include <gtest/gtest.h>

namespace psq::reports {
namespace {

TEST(Parameters, NestedObjectsBecomeDottedNames) {
  const auto flat = flatten_parameters(nlohmann::json::parse(
      R"({"depth": 2, "overrides": {"shell.a.thickness": 0.001, "list": [1, 2]},
          "scene": "fnv1a64:ab", "deep": {"x": {"y": true}}})"));
  ASSERT_EQ(flat.size(), 5u);
  EXPECT_EQ(flat.at("depth"), 2);
  EXPECT_EQ(flat.at("overrides.shell.a.thickness"), 0.001);
  EXPECT_EQ(flat.at("overrides.list"), nlohmann::json::array({1, 2}));
  EXPECT_EQ(flat.at("scene"), "fnv1a64:ab");
  EXPECT_EQ(flat.at("deep.x.y"), true);
  EXPECT_EQ(flatten_parameters(3.5).at("value"), 3.5);
}

TEST(Parameters, VaryingNamesDifferInValueOrPresence) {
  std::vector<std::map<std::string, nlohmann::json>> sets = {
      {{"a", 1}, {"b", "x"}, {"c", 1.5}},
      {{"a", 1}, {"b", "y"}, {"c", 1.5}},
      {{"a", 1}, {"b", "x"}, {"c", 1.5}, {"d", 0}},
  };
  EXPECT_EQ(varying_parameters(sets), (std::vector<std::string>{"b", "d"}));
  EXPECT_TRUE(varying_parameters({sets[0]}).empty());
  EXPECT_TRUE(varying_parameters({}).empty());
}

TEST(Parameters, ExactTextIsShortAndReadsBackExactly) {
  for (double value : {0.1, 1e-3, 2e9, 1.0 / 3.0, -7.25e-300, 123456789.0, 0.0}) {
    const std::string text = exact_text(value);
    EXPECT_EQ(std::stod(text), value) << text;
    EXPECT_LE(text.size(), 24u);
  }
  EXPECT_EQ(exact_text(5e-4), "0.0005");
  EXPECT_EQ(exact_text(1e7), "1e+07");
  EXPECT_EQ(exact_text(40.0), "40");
  EXPECT_EQ(exact_text(123456789.0), "123456789");
}

TEST(Parameters, CellTextOfEachKindOfValue) {
  EXPECT_EQ(cell_text("plain"), "plain");
  EXPECT_EQ(cell_text(0.1), "0.1");
  EXPECT_EQ(cell_text(2e9), "2e+09");
  EXPECT_EQ(cell_text(1.0 / 3.0), "0.3333333333333333");
  EXPECT_EQ(cell_text(7), "7");
  EXPECT_EQ(cell_text(nlohmann::json()), "");
  EXPECT_EQ(cell_text(nlohmann::json::array({1, "a"})), R"([1,"a"])");
}

}  // namespace
}  // namespace psq::reports
