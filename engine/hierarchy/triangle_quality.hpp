#pragma once
// Shape measures of triangles, used as decimation guarantees and reported per level.

#include <Eigen/Core>

#include "engine/mesh/tri_mesh.hpp"

namespace psq {

/// The smallest interior angle of triangle (a, b, c), in radians; 0 when degenerate.
double minimum_angle(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c);

/// Longest edge over shortest altitude, scaled so that an equilateral triangle has 1:
/// ℓ_max² √3 / (4 A) = (√3/2) / triangle_shape_quality. A smallest angle θ bounds it by
/// √3 cot θ. +∞ when degenerate.
double aspect_ratio(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c);

/// Worst shape over a mesh.
struct MeshQuality {
  double min_angle_degrees = 0;
  double max_aspect_ratio = 0;
};
MeshQuality mesh_quality(const TriMesh& mesh);

/// Area-weighted unit vertex normals of a mesh.
Positions vertex_normals(const TriMesh& mesh);

}  // namespace psq
