#include "engine/elastic/deformation_gradient.hpp"

#include <fmt/format.h>

#include <Eigen/Geometry>

#include "engine/core/error.hpp"
#include "engine/elastic/element_loop.hpp"

namespace psq {

MembraneRest membrane_rest(const TrianglePositions& rest) {
  // D holds the rest edges in an orthonormal frame whose first axis is edge 1.
  const Eigen::Vector3d e1 = rest.col(1) - rest.col(0);
  const Eigen::Vector3d e2 = rest.col(2) - rest.col(0);
  const double l1 = e1.norm();
  const double twice_area = e1.cross(e2).norm();
  Eigen::Matrix2d d;
  d << l1, e1.dot(e2) / l1, 0.0, twice_area / l1;
  return {d.inverse(), 0.5 * twice_area};
}

DeformationGradient deformation_gradient(const TrianglePositions& x, const MembraneRest& rest) {
  DeformationGradient edges;
  edges << x.col(1) - x.col(0), x.col(2) - x.col(0);
  return edges * rest.rest_frame_inverse;
}

DeformationGradientVector vec_outer(const Eigen::Vector3d& a, const Eigen::Vector2d& b) {
  DeformationGradientVector v;
  v << b[0] * a, b[1] * a;
  return v;
}

Eigen::Matrix<double, 6, 9> deformation_gradient_jacobian(const MembraneRest& rest) {
  const Eigen::Vector2d beta1 = rest.rest_frame_inverse.row(0).transpose();
  const Eigen::Vector2d beta2 = rest.rest_frame_inverse.row(1).transpose();
  const Eigen::Vector2d beta[3] = {-beta1 - beta2, beta1, beta2};
  Eigen::Matrix<double, 6, 9> a = Eigen::Matrix<double, 6, 9>::Zero();
  for (int i = 0; i < 3; ++i)
    for (int k = 0; k < 2; ++k) a.block<3, 3>(3 * k, 3 * i).diagonal().setConstant(beta[i][k]);
  return a;
}

TriangleVector pull_back_stress(const DeformationGradient& stress, const MembraneRest& rest,
                                double weight) {
  const DeformationGradientVector stress_vec = stress.reshaped();
  return weight * deformation_gradient_jacobian(rest).transpose() * stress_vec;
}

TriangleMatrix pull_back_stress_derivative(const DeformationGradientMatrix& stress_derivative,
                                           const MembraneRest& rest, double weight) {
  const Eigen::Matrix<double, 6, 9> a = deformation_gradient_jacobian(rest);
  return weight * a.transpose() * stress_derivative * a;
}

TriangleElements::TriangleElements(const TriMesh& rest, int vertex_offset, const char* term) {
  const int n = rest.triangle_count();
  stencils_.reserve(3 * static_cast<std::size_t>(n));
  rest_.reserve(n);
  for (int t = 0; t < n; ++t) {
    TrianglePositions corners;
    for (int a = 0; a < 3; ++a) {
      corners.col(a) = rest.vertices.row(rest.triangles(t, a)).transpose();
      stencils_.push_back(vertex_offset + rest.triangles(t, a));
    }
    rest_.push_back(membrane_rest(corners));
    if (!(rest_.back().area > 0))
      throw InputError(fmt::format("{}: rest triangle {} (vertices {}, {}, {}) has zero area", term,
                                   t, rest.triangles(t, 0), rest.triangles(t, 1),
                                   rest.triangles(t, 2)));
  }
}

TrianglePositions TriangleElements::positions(const Eigen::VectorXd& x, std::size_t t) const {
  return element_positions<3>(x, stencils_, t);
}

}  // namespace psq
