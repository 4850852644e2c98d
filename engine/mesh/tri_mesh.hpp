#pragma once
// Triangle mesh: vertex positions and oriented triangles. Positions are row-major so that
// the n×3 array is also the flat vector x = (x0, y0, z0, x1, ...) used by the solvers.

#include <Eigen/Core>

namespace psq {

using Positions = Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>;
using Triangles = Eigen::Matrix<int, Eigen::Dynamic, 3, Eigen::RowMajor>;

struct TriMesh {
  Positions vertices;
  Triangles triangles;

  [[nodiscard]] int vertex_count() const { return static_cast<int>(vertices.rows()); }
  [[nodiscard]] int triangle_count() const { return static_cast<int>(triangles.rows()); }
};

/// Flat 3n view of an n×3 row-major position array, and back.
inline Eigen::Map<Eigen::VectorXd> flat(Positions& p) { return {p.data(), p.size()}; }
inline Eigen::Map<const Eigen::VectorXd> flat(const Positions& p) { return {p.data(), p.size()}; }
inline Eigen::Map<const Positions> as_positions(const Eigen::VectorXd& x) {
  return {x.data(), x.size() / 3, 3};
}

/// Length of the bounding-box diagonal; the scale of a scene for relative tolerances.
double bounding_box_diagonal(const Positions& p);

}  // namespace psq
