// Shape pictures: orthographic projection, painter's order, Lambert shading, displacement
// colours with their colour bar, grey half-transparent colliders.

#include "reports/shape_picture.hpp"

#include <gtest/gtest.h>

#include <regex>

namespace psq::reports {
namespace {

/// A part made of triangles given by their corners (9 numbers each), displaced by `lift`
/// along z from a rest state.
PartMesh part(PartKind kind, const std::vector<std::array<double, 9>>& corners, double lift = 0) {
  PartMesh mesh{"part", kind, Positions(3 * corners.size(), 3), {}, Triangles(corners.size(), 3)};
  for (std::size_t t = 0; t < corners.size(); ++t) {
    for (int k = 0; k < 3; ++k)
      mesh.positions.row(3 * t + k) << corners[t][3 * k], corners[t][3 * k + 1],
          corners[t][3 * k + 2];
    mesh.triangles.row(t) << 3 * t, 3 * t + 1, 3 * t + 2;
  }
  mesh.rest_positions = mesh.positions;
  mesh.rest_positions.col(2).array() -= lift;
  return mesh;
}

struct Fill {
  int red, green, blue;
  bool collider;
};

/// The fills of the polygons in drawing order.
std::vector<Fill> polygon_fills(const std::string& svg) {
  std::vector<Fill> fills;
  const std::regex polygon(
      R"re(<polygon points="[^"]*" fill="#([0-9a-f]{2})([0-9a-f]{2})([0-9a-f]{2})"([^/]*)/>)re");
  for (auto it = std::sregex_iterator(svg.begin(), svg.end(), polygon);
       it != std::sregex_iterator(); ++it)
    fills.push_back({std::stoi((*it)[1], nullptr, 16), std::stoi((*it)[2], nullptr, 16),
                     std::stoi((*it)[3], nullptr, 16),
                     (*it)[4].str().find("class=\"collider\"") != std::string::npos});
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

TEST(ShapePicture, FarTrianglesAreDrawnFirstAndCollidersAreGreyAndHalfTransparent) {
  // A shell triangle at z = 1 above a collider triangle at z = 0.
  const LevelShape shape{{part(PartKind::shell, {{0, 0, 1, 1, 0, 1, 0, 1, 1}}, 0.5),
                          part(PartKind::collider, {{0, 0, 0, 0, 1, 0, 1, 0, 0}})}};
  ShapePicture from_above(ShapeView{20.0, 60.0});
  from_above.include(shape);
  const std::string svg = from_above.svg(shape, "two <triangles>");
  EXPECT_NE(svg.find("<title>two &lt;triangles&gt;</title>"), std::string::npos);
  EXPECT_EQ(svg.find("xmlns"), std::string::npos);
  const std::vector<Fill> fills = polygon_fills(svg);
  ASSERT_EQ(fills.size(), 2u);
  EXPECT_TRUE(fills[0].collider);  // the lower one, drawn first
  EXPECT_FALSE(fills[1].collider);
  EXPECT_LE(std::abs(fills[0].red - fills[0].blue), 20);  // grey
  EXPECT_NE(svg.find("fill-opacity=\"0.45\""), std::string::npos);

  ShapePicture from_below(ShapeView{20.0, -60.0});
  from_below.include(shape);
  const std::vector<Fill> below = polygon_fills(from_below.svg(shape, "below"));
  ASSERT_EQ(below.size(), 2u);
  EXPECT_FALSE(below[0].collider);  // from below the shell is the far one
}

TEST(ShapePicture, ShellsAreColouredByDisplacementOnOneScale) {
  // Two horizontal triangles side by side: the same shading, one at rest, one lifted by 2 mm.
  const LevelShape shape{{part(PartKind::shell, {{0, 0, 0, 1, 0, 0, 0, 1, 0}}),
                          part(PartKind::shell, {{2, 0, 0, 3, 0, 0, 2, 1, 0}}, 2e-3)}};
  ShapePicture picture(ShapeView{0.0, 89.0});  // from straight above: equal depths
  picture.include(shape);
  EXPECT_DOUBLE_EQ(picture.largest_displacement(), 2e-3);
  const std::vector<Fill> fills = polygon_fills(picture.svg(shape, "scale"));
  ASSERT_EQ(fills.size(), 2u);
  const auto at_rest = std::find_if(fills.begin(), fills.end(), [](const Fill& f) {
    return f.blue > f.red;  // the low end of the scale is blue-violet
  });
  const auto lifted = std::find_if(fills.begin(), fills.end(), [](const Fill& f) {
    return f.red > 2 * f.blue;  // the high end is yellow
  });
  EXPECT_NE(at_rest, fills.end());
  EXPECT_NE(lifted, fills.end());

  const std::string bar = picture.colour_bar(300);
  EXPECT_NE(bar.find("0 to 2 mm"), std::string::npos) << bar;
  const std::regex rect("<rect ");
  EXPECT_EQ(std::distance(std::sregex_iterator(bar.begin(), bar.end(), rect),
                          std::sregex_iterator()),
            32);
}

TEST(ShapePicture, LambertShadingLightsFacesTurnedToTheLightMore) {
  const ShapeView view{0.0, 0.0};  // looking along +y; the light comes from about −y
  // One collider triangle facing the camera (normal −y), one seen nearly edge-on (normal +x).
  const LevelShape shape{{part(PartKind::collider, {{0, 0, 0, 1, 0, 0, 0, 0, 1}}),
                          part(PartKind::collider, {{2, 0, 0, 2, 1, 0, 2, 0, 1}})}};
  ShapePicture picture(view);
  picture.include(shape);
  const std::vector<Fill> fills = polygon_fills(picture.svg(shape, "lit"));
  ASSERT_EQ(fills.size(), 2u);
  const int facing = std::max(fills[0].green, fills[1].green);
  const int edge_on = std::min(fills[0].green, fills[1].green);
  EXPECT_GT(facing, edge_on + 40);
}

TEST(ShapePicture, DisplacementColoursRunFromVioletToYellowAndClamp) {
  EXPECT_EQ(displacement_colour(0.0).red, 68);
  EXPECT_EQ(displacement_colour(1.0).green, 231);
  EXPECT_EQ(displacement_colour(2.0).blue, displacement_colour(1.0).blue);
  EXPECT_EQ(displacement_colour(-1.0).blue, displacement_colour(0.0).blue);
  // Lighter along the scale (a grey print keeps the order).
  double lightness = -1;
  for (double f = 0; f <= 1.0; f += 0.125) {
    const Colour c = displacement_colour(f);
    const double l = 0.3 * c.red + 0.59 * c.green + 0.11 * c.blue;
    EXPECT_GT(l, lightness) << f;
    lightness = l;
  }
}

TEST(ShapePicture, EveryVertexOfTheFrameLandsInsideThePicture) {
  LevelShape shape{{part(PartKind::shell, {{0, 0, 1, 1, 0, 1, 0, 1, 1}}),
                    part(PartKind::collider, {{0, 0, 0, 0, 1, 0, 1, 0, 0}})}};
  for (PartMesh& p : shape.parts) p.positions *= 1e-3;  // millimetre-sized: scaled up to fit
  ShapePicture picture;
  picture.include(shape);
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
