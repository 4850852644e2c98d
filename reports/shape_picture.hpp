#pragma once
// Pictures of a level's shape as inline SVG: an orthographic view (z up), triangles sorted back
// to front (painter's algorithm) and Lambert-shaded by the angle of their normal to a light near
// the camera. A shell's triangles are coloured by their displacement from rest on one colour
// scale (a colour bar explains it); colliders are grey and half transparent, so that a shell
// behind or under one stays visible.

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

/// An sRGB colour, channels 0–255.
struct Colour {
  double red, green, blue;
};

/// "#rrggbb" of `colour` scaled by `intensity` (channels rounded and clamped to 0–255).
std::string hex_colour(const Colour& colour, double intensity = 1.0);

/// The displacement colour scale (perceptually ordered, dark blue → teal → yellow) at
/// `fraction` ∈ [0, 1] (clamped).
Colour displacement_colour(double fraction);

/// Draws shapes in one shared frame and on one displacement scale, so that pictures of several
/// levels or jobs compare directly.
class ShapePicture {
 public:
  explicit ShapePicture(ShapeView view = {});

  /// Widens the frame to contain every part of `shape`, and the displacement scale to its
  /// shells' largest displacement.
  void include(const LevelShape& shape);

  /// Screen coordinates of a point: (p·r, p·u) with r, u the camera's right and up axes.
  Eigen::Vector2d project(const Eigen::Vector3d& point) const;
  /// Distance toward the camera, p·v: larger is nearer.
  double depth(const Eigen::Vector3d& point) const { return point.dot(toward_camera_); }
  /// The displacement (m) that takes the top colour of the scale.
  double largest_displacement() const { return largest_displacement_; }

  /// An <svg> element (no namespace attribute: it is meant to be inlined in HTML) `width`
  /// pixels wide showing `shape` in the current frame, with `caption` as its <title>.
  /// Triangle indices must be valid.
  std::string svg(const LevelShape& shape, const std::string& caption, int width = 320) const;

  /// An <svg> colour bar `width` pixels wide: the displacement scale from 0 to
  /// largest_displacement(), labelled in millimetres.
  std::string colour_bar(int width = 320) const;

 private:
  Eigen::Vector3d right_, up_, toward_camera_, light_;
  Eigen::AlignedBox2d frame_;
  double largest_displacement_ = 0.0;
};

}  // namespace psq::reports
