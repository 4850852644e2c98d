#include "engine/contact/edge_edge_distance.hpp"

#include <Eigen/Geometry>

#include "engine/contact/point_edge_distance.hpp"

namespace psq {

ClosestPair line_line_closest_pair(const Eigen::Vector3d& ea0, const Eigen::Vector3d& ea1,
                                   const Eigen::Vector3d& eb0, const Eigen::Vector3d& eb1) {
  const Eigen::Vector3d u = ea1 - ea0;
  const Eigen::Vector3d v = eb1 - eb0;
  const Eigen::Vector3d w0 = ea0 - eb0;
  const Eigen::Vector3d n = u.cross(v);
  const double n_sq = n.squaredNorm();
  const double s = n.dot(v.cross(w0)) / n_sq;
  const double t = n.dot(u.cross(w0)) / n_sq;
  // q = n (n·w₀)/‖n‖² in exact arithmetic. For nearly parallel edges the rounding error of n
  // is large relative to n, and w₀ has large components along the edges that it would
  // multiply; the vector between the (approximate) closest points has none, so projecting it
  // instead keeps q accurate.
  const Eigen::Vector3d between = w0 + s * u - t * v;
  // Σ wᵢ xᵢ = (1 − s) ea0 + s ea1 + (t − 1) eb0 − t eb1 = q.
  return {Eigen::Vector4d(1 - s, s, t - 1, -t), n, n * (n.dot(between) / n_sq)};
}

double line_line_distance(const Eigen::Vector3d& ea0, const Eigen::Vector3d& ea1,
                          const Eigen::Vector3d& eb0, const Eigen::Vector3d& eb1) {
  return line_line_closest_pair(ea0, ea1, eb0, eb1).q.squaredNorm();
}

StencilDerivatives<12> line_line_distance_derivatives(const Eigen::Vector3d& ea0,
                                                      const Eigen::Vector3d& ea1,
                                                      const Eigen::Vector3d& eb0,
                                                      const Eigen::Vector3d& eb1) {
  const ClosestPair pair = line_line_closest_pair(ea0, ea1, eb0, eb1);
  Eigen::Matrix<double, 4, 2> dw_dst;
  dw_dst << -1, 0, 1, 0, 0, 1, 0, -1;
  return closest_pair_distance_derivatives<4, 2>(stack_stencil(ea0, ea1, eb0, eb1), pair.weights,
                                                 dw_dst, pair.q);
}

double edge_edge_distance(const Eigen::Vector3d& ea0, const Eigen::Vector3d& ea1,
                          const Eigen::Vector3d& eb0, const Eigen::Vector3d& eb1) {
  double boundary_distance = 0.0;
  const EdgeEdgeCase c = edge_edge_case(ea0, ea1, eb0, eb1, &boundary_distance);
  return c == EdgeEdgeCase::LineLine ? line_line_distance(ea0, ea1, eb0, eb1) : boundary_distance;
}

StencilDerivatives<12> edge_edge_distance_derivatives(const Eigen::Vector3d& ea0,
                                                      const Eigen::Vector3d& ea1,
                                                      const Eigen::Vector3d& eb0,
                                                      const Eigen::Vector3d& eb1) {
  const EdgeEdgeCase c = edge_edge_case(ea0, ea1, eb0, eb1);
  if (c == EdgeEdgeCase::LineLine) return line_line_distance_derivatives(ea0, ea1, eb0, eb1);
  return point_feature_distance_derivatives(point_feature(c), stack_stencil(ea0, ea1, eb0, eb1));
}

}  // namespace psq
