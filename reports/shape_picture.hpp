#pragma once
// Pictures of a shell's shape as inline SVG: an orthographic view (z up), triangles sorted
// back to front (painter's algorithm) and flat-shaded, front faces blue and back faces orange
// so the two sides of a shell are told apart.

#include <Eigen/Geometry>
#include <string>

#include "reports/report_model.hpp"

namespace psq::reports {

/// Where the camera looks from: `azimuth` turns it about the z axis (0: looking along +y),
/// `elevation` raises it above the xy plane. Degrees; |elevation| < 90.
struct ShapeView {
  double azimuth_degrees = 35.0;
  double elevation_degrees = 25.0;
};

/// Draws shapes in one shared frame, so that pictures of the levels of one job have one scale.
class ShapePicture {
 public:
  explicit ShapePicture(ShapeView view = {});

  /// Widens the frame to contain these points.
  void include(const Positions& points);

  /// Screen coordinates of a point: (p·r, p·u) with r, u the camera's right and up axes.
  Eigen::Vector2d project(const Eigen::Vector3d& point) const;
  /// Distance toward the camera, p·v: larger is nearer.
  double depth(const Eigen::Vector3d& point) const { return point.dot(toward_camera_); }

  /// An <svg> element (no namespace attribute: it is meant to be inlined in HTML) `width`
  /// pixels wide showing `shape` in the current frame, with `caption` as its <title>.
  /// Triangle indices must be valid.
  std::string svg(const LevelShape& shape, const std::string& caption, int width = 320) const;

 private:
  Eigen::Vector3d right_, up_, toward_camera_;
  Eigen::AlignedBox2d frame_;
};

}  // namespace psq::reports
