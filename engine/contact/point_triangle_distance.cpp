#include "engine/contact/point_triangle_distance.hpp"

#include <Eigen/Geometry>

#include "engine/contact/point_edge_distance.hpp"

namespace psq {

ClosestPair point_plane_closest_pair(const Eigen::Vector3d& p, const Eigen::Vector3d& t0,
                                     const Eigen::Vector3d& t1, const Eigen::Vector3d& t2) {
  const Eigen::Vector3d e1 = t1 - t0;
  const Eigen::Vector3d e2 = t2 - t0;
  const Eigen::Vector3d r = p - t0;
  const Eigen::Vector3d n = e1.cross(e2);
  const double n_sq = n.squaredNorm();
  const double beta1 = n.dot(r.cross(e2)) / n_sq;
  const double beta2 = n.dot(e1.cross(r)) / n_sq;
  // Σ wᵢ xᵢ = p + (β₁ + β₂ − 1) t0 − β₁ t1 − β₂ t2 = q.
  return {Eigen::Vector4d(1, beta1 + beta2 - 1, -beta1, -beta2), n, n * (n.dot(r) / n_sq)};
}

double point_plane_distance(const Eigen::Vector3d& p, const Eigen::Vector3d& t0,
                            const Eigen::Vector3d& t1, const Eigen::Vector3d& t2) {
  return point_plane_closest_pair(p, t0, t1, t2).q.squaredNorm();
}

StencilDerivatives<12> point_plane_distance_derivatives(const Eigen::Vector3d& p,
                                                        const Eigen::Vector3d& t0,
                                                        const Eigen::Vector3d& t1,
                                                        const Eigen::Vector3d& t2) {
  const ClosestPair pair = point_plane_closest_pair(p, t0, t1, t2);
  Eigen::Matrix<double, 4, 2> dw_dbeta;
  dw_dbeta << 0, 0, 1, 1, -1, 0, 0, -1;
  return closest_pair_distance_derivatives<4, 2>(stack_stencil(p, t0, t1, t2), pair.weights,
                                                 dw_dbeta, pair.q);
}

double point_triangle_distance(const Eigen::Vector3d& p, const Eigen::Vector3d& t0,
                               const Eigen::Vector3d& t1, const Eigen::Vector3d& t2) {
  double boundary_distance = 0.0;
  const PointTriangleCase c = point_triangle_case(p, t0, t1, t2, &boundary_distance);
  return c == PointTriangleCase::Face ? point_plane_distance(p, t0, t1, t2) : boundary_distance;
}

StencilDerivatives<12> point_triangle_distance_derivatives(const Eigen::Vector3d& p,
                                                           const Eigen::Vector3d& t0,
                                                           const Eigen::Vector3d& t1,
                                                           const Eigen::Vector3d& t2) {
  const PointTriangleCase c = point_triangle_case(p, t0, t1, t2);
  if (c == PointTriangleCase::Face) return point_plane_distance_derivatives(p, t0, t1, t2);
  return point_feature_distance_derivatives(point_feature(c), stack_stencil(p, t0, t1, t2));
}

}  // namespace psq
