// Shape pictures: orthographic projection, painter's order, two-sided colours.

#include "reports/shape_picture.hpp"

#include <gtest/gtest.h>

#include <regex>

namespace psq::reports {
namespace {

/// Two horizontal triangles, one above the other: seen from above, the upper is nearer.
LevelShape stacked_triangles() {
  LevelShape shape;
  shape.positions.resize(6, 3);
  shape.positions << 0, 0, 1, 1, 0, 1, 0, 1, 1,  // upper (index 0), counter-clockwise from +z
      0, 0, 0, 0, 1, 0, 1, 0, 0;                 // lower (index 1), clockwise from +z
  shape.triangles.resize(2, 3);
  shape.triangles << 0, 1, 2, 3, 4, 5;
  return shape;
}

std::vector<std::string> polygon_fills(const std::string& svg) {
  std::vector<std::string> fills;
  const std::regex polygon(R"re(<polygon points="[^"]*" fill="(#[0-9a-f]{6})"/>)re");
  for (auto it = std::sregex_iterator(svg.begin(), svg.end(), polygon);
       it != std::sregex_iterator(); ++it)
    fills.push_back((*it)[1]);
  return fills;
}

TEST(ShapePicture, ProjectionKeepsUpUpAndDepthGrowsTowardTheCamera) {
  const ShapePicture picture(ShapeView{0.0, 30.0});  // looking along +y, from above
  EXPECT_NEAR(picture.project({1, 0, 0}).x(), 1.0, 1e-12);
  EXPECT_NEAR(picture.project({1, 0, 0}).y(), 0.0, 1e-12);
  EXPECT_NEAR(picture.project({0, 0, 1}).y(), std::cos(M_PI / 6), 1e-12);
  EXPECT_NEAR(picture.project({0, 1, 0}).x(), 0.0, 1e-12);
  EXPECT_GT(picture.depth({0, -1, 0}), picture.depth({0, 1, 0}));  // the camera is at −y
  EXPECT_GT(picture.depth({0, 0, 1}), picture.depth({0, 0, 0}));   // and above
}

TEST(ShapePicture, FarTrianglesAreDrawnFirstAndBackFacesHaveTheirOwnColour) {
  const LevelShape shape = stacked_triangles();
  ShapePicture from_above(ShapeView{20.0, 60.0});
  from_above.include(shape.positions);
  const std::string svg = from_above.svg(shape, "two <triangles>");
  EXPECT_NE(svg.find("<title>two &lt;triangles&gt;</title>"), std::string::npos);
  EXPECT_EQ(svg.find("xmlns"), std::string::npos);
  const std::vector<std::string> fills = polygon_fills(svg);
  ASSERT_EQ(fills.size(), 2u);
  // Drawn first: the lower triangle, seen from its back (orange: red channel above blue).
  EXPECT_GT(std::stoi(fills[0].substr(1, 2), nullptr, 16),
            std::stoi(fills[0].substr(5, 2), nullptr, 16));
  EXPECT_LT(std::stoi(fills[1].substr(1, 2), nullptr, 16),
            std::stoi(fills[1].substr(5, 2), nullptr, 16));

  ShapePicture from_below(ShapeView{20.0, -60.0});
  from_below.include(shape.positions);
  const std::vector<std::string> below = polygon_fills(from_below.svg(shape, "below"));
  ASSERT_EQ(below.size(), 2u);
  // From below the upper triangle is the far one and is drawn first, seen from its back.
  EXPECT_GT(std::stoi(below[0].substr(1, 2), nullptr, 16),
            std::stoi(below[0].substr(5, 2), nullptr, 16));
}

TEST(ShapePicture, EveryVertexOfTheFrameLandsInsideThePicture) {
  LevelShape shape = stacked_triangles();
  shape.positions *= 1e-3;  // millimetre-sized shells are scaled up to the picture
  ShapePicture picture;
  picture.include(shape.positions);
  const std::string svg = picture.svg(shape, "small", 200);
  const std::regex size(R"re(width="(\d+)" height="(\d+)")re");
  std::smatch match;
  ASSERT_TRUE(std::regex_search(svg, match, size));
  const double width = std::stod(match[1]), height = std::stod(match[2]);
  EXPECT_EQ(width, 200);
  const std::regex number_pair(R"re((-?[0-9.]+),(-?[0-9.]+))re");
  int points = 0;
  for (auto it = std::sregex_iterator(svg.begin(), svg.end(), number_pair);
       it != std::sregex_iterator(); ++it, ++points) {
    EXPECT_GE(std::stod((*it)[1]), 0.0);
    EXPECT_LE(std::stod((*it)[1]), width);
    EXPECT_GE(std::stod((*it)[2]), 0.0);
    EXPECT_LE(std::stod((*it)[2]), height);
  }
  EXPECT_EQ(points, 6);
}

}  // namespace
}  // namespace psq::reports
