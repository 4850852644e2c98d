#include "engine/hierarchy/triangle_quality.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include "engine/mesh/triangle_shape.hpp"

namespace psq {

namespace {

double corner_angle(const Eigen::Vector3d& at, const Eigen::Vector3d& p, const Eigen::Vector3d& q) {
  const Eigen::Vector3d u = p - at, v = q - at;
  return std::atan2(u.cross(v).norm(), u.dot(v));
}

}  // namespace

double minimum_angle(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
  if ((b - a).cross(c - a).norm() == 0) return 0.0;
  return std::min({corner_angle(a, b, c), corner_angle(b, c, a), corner_angle(c, a, b)});
}

double aspect_ratio(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
  const double quality = triangle_shape_quality(a, b, c);
  if (!(quality > 0)) return std::numeric_limits<double>::infinity();  // degenerate, or one point
  return std::sqrt(3.0) / (2 * quality);
}

MeshQuality mesh_quality(const TriMesh& mesh) {
  MeshQuality quality{std::numeric_limits<double>::infinity(), 0.0};
  for (int t = 0; t < mesh.triangle_count(); ++t) {
    const Eigen::Vector3d a = mesh.vertices.row(mesh.triangles(t, 0));
    const Eigen::Vector3d b = mesh.vertices.row(mesh.triangles(t, 1));
    const Eigen::Vector3d c = mesh.vertices.row(mesh.triangles(t, 2));
    quality.min_angle_degrees =
        std::min(quality.min_angle_degrees, minimum_angle(a, b, c) * 180 / std::numbers::pi);
    quality.max_aspect_ratio = std::max(quality.max_aspect_ratio, aspect_ratio(a, b, c));
  }
  return quality;
}

Positions vertex_normals(const TriMesh& mesh) {
  Positions normals = Positions::Zero(mesh.vertex_count(), 3);
  for (int t = 0; t < mesh.triangle_count(); ++t) {
    const auto tri = mesh.triangles.row(t);
    const Eigen::Vector3d a = mesh.vertices.row(tri(0));
    // |cross| = 2·area, so summing the raw cross products weights by area.
    const Eigen::Vector3d n = (Eigen::Vector3d(mesh.vertices.row(tri(1))) - a)
                                  .cross(Eigen::Vector3d(mesh.vertices.row(tri(2))) - a);
    for (int k = 0; k < 3; ++k) normals.row(tri(k)) += n.transpose();
  }
  normals.rowwise().normalize();
  return normals;
}

}  // namespace psq
