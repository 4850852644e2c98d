#include "reports/shape_picture.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <numeric>

#include "reports/html_text.hpp"

namespace psq::reports {
namespace {

/// Meshes with more triangles are drawn without edge lines (they would hide the shading).
constexpr Eigen::Index kMaxOutlinedTriangles = 3000;

struct Colour {
  double red, green, blue;
};
constexpr Colour kFrontFace{70, 130, 190};
constexpr Colour kBackFace{215, 140, 60};

std::string hex(const Colour& colour, double intensity) {
  const auto channel = [intensity](double value) {
    return static_cast<int>(std::clamp(std::lround(value * intensity), 0L, 255L));
  };
  return fmt::format("#{:02x}{:02x}{:02x}", channel(colour.red), channel(colour.green),
                     channel(colour.blue));
}

}  // namespace

ShapePicture::ShapePicture(ShapeView view) {
  const double azimuth = view.azimuth_degrees * M_PI / 180.0;
  const double elevation = view.elevation_degrees * M_PI / 180.0;
  toward_camera_ = Eigen::Vector3d(std::cos(elevation) * std::sin(azimuth),
                                   -std::cos(elevation) * std::cos(azimuth), std::sin(elevation));
  right_ = Eigen::Vector3d::UnitZ().cross(toward_camera_).normalized();
  up_ = toward_camera_.cross(right_);
}

void ShapePicture::include(const Positions& points) {
  for (Eigen::Index i = 0; i < points.rows(); ++i)
    frame_.extend(project(points.row(i).transpose()));
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

  const Positions& x = shape.positions;
  const Triangles& triangles = shape.triangles;
  std::vector<double> depths(triangles.rows());
  for (Eigen::Index t = 0; t < triangles.rows(); ++t)
    depths[t] = depth(x.row(triangles(t, 0)) + x.row(triangles(t, 1)) + x.row(triangles(t, 2)));
  std::vector<Eigen::Index> order(triangles.rows());
  std::iota(order.begin(), order.end(), Eigen::Index{0});
  std::sort(order.begin(), order.end(), [&](auto a, auto b) { return depths[a] < depths[b]; });

  const Eigen::Vector3d light = (toward_camera_ + 0.4 * right_ + 0.6 * up_).normalized();
  const bool outlined = triangles.rows() <= kMaxOutlinedTriangles;
  std::string svg = fmt::format(
      "<svg class=\"shape\" role=\"img\" width=\"{0}\" height=\"{1}\" viewBox=\"0 0 {0} {1}\">"
      "<title>{2}</title><rect width=\"{0}\" height=\"{1}\" fill=\"#ffffff\"/>",
      width, height, escape_html(caption));
  svg += outlined ? "<g stroke=\"#1b2733\" stroke-width=\"0.4\" stroke-opacity=\"0.45\" "
                    "stroke-linejoin=\"round\">"
                  : "<g shape-rendering=\"crispEdges\">";
  for (const Eigen::Index t : order) {
    const Eigen::Vector3d a = x.row(triangles(t, 0)), b = x.row(triangles(t, 1)),
                          c = x.row(triangles(t, 2));
    const Eigen::Vector3d normal = (b - a).cross(c - a);
    const double length = normal.norm();
    const double facing = length > 0 ? normal.dot(toward_camera_) / length : 1.0;
    const double lit = length > 0 ? std::abs(normal.dot(light)) / length : 0.0;
    const std::string fill = hex(facing >= 0 ? kFrontFace : kBackFace, 0.35 + 0.65 * lit);
    const Eigen::Vector2d p = to_screen(a), q = to_screen(b), r = to_screen(c);
    svg += fmt::format(
        "<polygon points=\"{:.1f},{:.1f} {:.1f},{:.1f} {:.1f},{:.1f}\" "
        "fill=\"{}\"/>",
        p.x(), p.y(), q.x(), q.y(), r.x(), r.y(), fill);
  }
  return svg + "</g></svg>";
}

}  // namespace psq::reports
