#include "reports/shape_picture.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <numeric>

#include "reports/html_text.hpp"

namespace psq::reports {
namespace {

/// Meshes with more triangles are drawn without edge lines (they would hide the shading).
constexpr Eigen::Index kMaxOutlinedTriangles = 3000;
constexpr Colour kColliderColour{170, 176, 184};
/// Lambert shading: a triangle lit edge-on still shows this much of its colour (enough that
/// the darkest shade of a colour is not mistaken for another colour of the scale).
constexpr double kAmbient = 0.45;

/// One triangle to draw: its corners, its fill and whether it belongs to a collider.
struct DrawnTriangle {
  std::array<Eigen::Vector3d, 3> corners;
  double depth = 0;
  std::string fill;
  bool collider = false;
};

/// Per vertex ‖x − X‖ of a part.
Eigen::VectorXd displacements(const PartMesh& part) {
  return (part.positions - part.rest_positions).rowwise().norm();
}

}  // namespace

std::string hex_colour(const Colour& colour, double intensity) {
  const auto channel = [intensity](double value) {
    return static_cast<int>(std::clamp(std::lround(value * intensity), 0L, 255L));
  };
  return fmt::format("#{:02x}{:02x}{:02x}", channel(colour.red), channel(colour.green),
                     channel(colour.blue));
}

Colour displacement_colour(double fraction) {
  // Stops of a viridis-like scale: ordered in lightness, readable in grey and by most
  // colour-blind readers.
  static constexpr std::array<Colour, 5> stops{
      {{68, 1, 84}, {59, 82, 139}, {33, 145, 140}, {94, 201, 98}, {253, 231, 37}}};
  const double at = std::clamp(fraction, 0.0, 1.0) * (stops.size() - 1);
  const std::size_t low = std::min(static_cast<std::size_t>(at), stops.size() - 2);
  const double t = at - low;
  const Colour& a = stops[low];
  const Colour& b = stops[low + 1];
  return {a.red + t * (b.red - a.red), a.green + t * (b.green - a.green),
          a.blue + t * (b.blue - a.blue)};
}

ShapePicture::ShapePicture(ShapeView view) {
  const double azimuth = view.azimuth_degrees * M_PI / 180.0;
  const double elevation = view.elevation_degrees * M_PI / 180.0;
  toward_camera_ = Eigen::Vector3d(std::cos(elevation) * std::sin(azimuth),
                                   -std::cos(elevation) * std::cos(azimuth), std::sin(elevation));
  right_ = Eigen::Vector3d::UnitZ().cross(toward_camera_).normalized();
  up_ = toward_camera_.cross(right_);
  // Above and to the left of the camera, so that faces turned towards it are not all equally lit.
  light_ = (toward_camera_ - 0.4 * right_ + 0.6 * up_).normalized();
}

void ShapePicture::include(const LevelShape& shape) {
  for (const PartMesh& part : shape.parts) {
    for (Eigen::Index i = 0; i < part.positions.rows(); ++i)
      frame_.extend(project(part.positions.row(i).transpose()));
    if (part.kind == PartKind::shell && part.positions.rows() > 0)
      largest_displacement_ = std::max(largest_displacement_, displacements(part).maxCoeff());
  }
}

Eigen::Vector2d ShapePicture::project(const Eigen::Vector3d& point) const {
  return {point.dot(right_), point.dot(up_)};
}

std::string ShapePicture::svg(const LevelShape& shape, const std::string& caption,
                              int width) const {
  // The frame fills the picture's width less a 4% margin; screen y grows downwards.
  const Eigen::Vector2d span = frame_.isEmpty()
                                   ? Eigen::Vector2d(1, 1)
                                   : frame_.sizes().cwiseMax(Eigen::Vector2d::Constant(1e-12));
  const int height =
      static_cast<int>(std::clamp(width * span.y() / span.x(), 0.3 * width, 1.2 * width));
  const double fit = 0.92 * std::min(width / span.x(), height / span.y());
  const Eigen::Vector2d centre = frame_.isEmpty() ? Eigen::Vector2d(0, 0) : frame_.center();
  const auto to_screen = [&](const Eigen::Vector3d& point) {
    const Eigen::Vector2d p = project(point) - centre;
    return Eigen::Vector2d(0.5 * width + fit * p.x(), 0.5 * height - fit * p.y());
  };

  std::vector<DrawnTriangle> triangles;
  Eigen::Index shell_triangles = 0;
  for (const PartMesh& part : shape.parts) {
    const bool collider = part.kind == PartKind::collider;
    const Eigen::VectorXd moved = displacements(part);
    if (!collider) shell_triangles += part.triangles.rows();
    for (Eigen::Index t = 0; t < part.triangles.rows(); ++t) {
      DrawnTriangle drawn;
      double displacement = 0;
      for (int k = 0; k < 3; ++k) {
        drawn.corners[k] = part.positions.row(part.triangles(t, k)).transpose();
        displacement += moved(part.triangles(t, k)) / 3;
      }
      drawn.depth = depth(drawn.corners[0] + drawn.corners[1] + drawn.corners[2]);
      const Eigen::Vector3d normal =
          (drawn.corners[1] - drawn.corners[0]).cross(drawn.corners[2] - drawn.corners[0]);
      const double length = normal.norm();
      // Shells are two-sided: either face turned to the light is lit.
      const double lambert = length > 0 ? std::abs(normal.dot(light_)) / length : 0.0;
      const Colour colour =
          collider ? kColliderColour
                   : displacement_colour(largest_displacement_ > 0
                                             ? displacement / largest_displacement_
                                             : 0.0);
      drawn.fill = hex_colour(colour, kAmbient + (1 - kAmbient) * lambert);
      drawn.collider = collider;
      triangles.push_back(std::move(drawn));
    }
  }
  std::sort(triangles.begin(), triangles.end(),
            [](const DrawnTriangle& a, const DrawnTriangle& b) { return a.depth < b.depth; });

  std::string svg = fmt::format(
      "<svg class=\"shape\" role=\"img\" width=\"{0}\" height=\"{1}\" viewBox=\"0 0 {0} {1}\">"
      "<title>{2}</title><rect width=\"{0}\" height=\"{1}\" fill=\"#ffffff\"/>",
      width, height, escape_html(caption));
  svg += shell_triangles <= kMaxOutlinedTriangles
             ? "<g stroke=\"#1b2733\" stroke-width=\"0.3\" stroke-opacity=\"0.35\" "
               "stroke-linejoin=\"round\">"
             : "<g>";
  for (const DrawnTriangle& triangle : triangles) {
    const Eigen::Vector2d p = to_screen(triangle.corners[0]), q = to_screen(triangle.corners[1]),
                          r = to_screen(triangle.corners[2]);
    svg += fmt::format(
        "<polygon points=\"{:.1f},{:.1f} {:.1f},{:.1f} {:.1f},{:.1f}\" fill=\"{}\"{}/>", p.x(),
        p.y(), q.x(), q.y(), r.x(), r.y(), triangle.fill,
        triangle.collider ? " fill-opacity=\"0.45\" stroke=\"none\" class=\"collider\"" : "");
  }
  return svg + "</g></svg>";
}

std::string ShapePicture::colour_bar(int width) const {
  constexpr int kSteps = 32;
  constexpr int kBarHeight = 14;
  const double step = (width - 20.0) / kSteps;
  std::string svg = fmt::format(
      "<svg class=\"colour-bar\" role=\"img\" width=\"{0}\" height=\"36\" viewBox=\"0 0 {0} 36\">"
      "<title>displacement from rest, 0 to {1:.4g} mm</title>",
      width, 1e3 * largest_displacement_);
  for (int s = 0; s < kSteps; ++s)
    svg += fmt::format("<rect x=\"{:.2f}\" y=\"2\" width=\"{:.2f}\" height=\"{}\" fill=\"{}\"/>",
                       10 + s * step, step + 0.5, kBarHeight,
                       hex_colour(displacement_colour((s + 0.5) / kSteps)));
  svg += fmt::format(
      "<g font-family=\"sans-serif\" font-size=\"11\" fill=\"#1b2733\">"
      "<text x=\"10\" y=\"30\">0</text>"
      "<text x=\"{0}\" y=\"30\" text-anchor=\"middle\">displacement (mm)</text>"
      "<text x=\"{1}\" y=\"30\" text-anchor=\"end\">{2:.4g}</text></g>",
      width / 2, width - 10, 1e3 * largest_displacement_);
  return svg + "</svg>";
}

}  // namespace psq::reports
