#include "engine/contact/point_triangle_distance.hpp"

#include <Eigen/Geometry>

#include "engine/contact/point_edge_distance.hpp"

namespace psq {
namespace {

/// The foot of p on the triangle's plane, through the normal n = e₁ × e₂ rather than a
/// Gram-matrix solve, which keeps q accurate when p is close to the plane.
struct PlaneFoot {
  double beta1, beta2;  ///< barycentric coordinates of the foot for t1 and t2
  Eigen::Vector3d q;    ///< p − foot, along n
};

PlaneFoot plane_foot(const Eigen::Vector3d& p, const Eigen::Vector3d& t0, const Eigen::Vector3d& t1,
                     const Eigen::Vector3d& t2) {
  const Eigen::Vector3d e1 = t1 - t0;
  const Eigen::Vector3d e2 = t2 - t0;
  const Eigen::Vector3d r = p - t0;
  const Eigen::Vector3d n = e1.cross(e2);
  const double n_sq = n.squaredNorm();
  return {n.dot(r.cross(e2)) / n_sq, n.dot(e1.cross(r)) / n_sq, n * (n.dot(r) / n_sq)};
}

/// The point–point or point–edge sub-case of each boundary case, indexed by PointTriangleCase
/// (Vertex0 … Edge20), in stencil slots (p, t0, t1, t2) = (0, 1, 2, 3): three vertices, then
/// three edges.
constexpr std::array<PointFeature, 6> kBoundarySubCases{{{0, 1, {1, 0}},
                                                         {0, 1, {2, 0}},
                                                         {0, 1, {3, 0}},
                                                         {0, 2, {1, 2}},
                                                         {0, 2, {2, 3}},
                                                         {0, 2, {3, 1}}}};
static_assert(static_cast<int>(PointTriangleCase::Face) == kBoundarySubCases.size());

}  // namespace

double point_plane_distance(const Eigen::Vector3d& p, const Eigen::Vector3d& t0,
                            const Eigen::Vector3d& t1, const Eigen::Vector3d& t2) {
  return plane_foot(p, t0, t1, t2).q.squaredNorm();
}

StencilDerivatives<12> point_plane_distance_derivatives(const Eigen::Vector3d& p,
                                                        const Eigen::Vector3d& t0,
                                                        const Eigen::Vector3d& t1,
                                                        const Eigen::Vector3d& t2) {
  const PlaneFoot foot = plane_foot(p, t0, t1, t2);
  // q = p + (β₁ + β₂ − 1) t0 − β₁ t1 − β₂ t2.
  const Eigen::Vector4d w(1, foot.beta1 + foot.beta2 - 1, -foot.beta1, -foot.beta2);
  Eigen::Matrix<double, 4, 2> dw_dbeta;
  dw_dbeta << 0, 0, 1, 1, -1, 0, 0, -1;
  return closest_pair_distance_derivatives<4, 2>(stack_stencil(p, t0, t1, t2), w, dw_dbeta, foot.q);
}

double point_triangle_distance(const Eigen::Vector3d& p, const Eigen::Vector3d& t0,
                               const Eigen::Vector3d& t1, const Eigen::Vector3d& t2) {
  const PointTriangleCase c = point_triangle_case(p, t0, t1, t2);
  if (c == PointTriangleCase::Face) return point_plane_distance(p, t0, t1, t2);
  return point_feature_distance(kBoundarySubCases[static_cast<int>(c)], stack_stencil(p, t0, t1, t2));
}

StencilDerivatives<12> point_triangle_distance_derivatives(const Eigen::Vector3d& p,
                                                           const Eigen::Vector3d& t0,
                                                           const Eigen::Vector3d& t1,
                                                           const Eigen::Vector3d& t2) {
  const PointTriangleCase c = point_triangle_case(p, t0, t1, t2);
  if (c == PointTriangleCase::Face) return point_plane_distance_derivatives(p, t0, t1, t2);
  return point_feature_distance_derivatives(kBoundarySubCases[static_cast<int>(c)],
                                            stack_stencil(p, t0, t1, t2));
}

}  // namespace psq
