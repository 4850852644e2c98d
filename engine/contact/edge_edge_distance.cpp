#include "engine/contact/edge_edge_distance.hpp"

#include <Eigen/Geometry>
#include <array>

#include "engine/contact/point_edge_distance.hpp"

namespace psq {
namespace {

/// The closest points ea0 + s u and eb0 + t v of the two lines, through the common normal
/// n = u × v rather than a Gram-matrix solve.
struct LinePair {
  double s, t;
  Eigen::Vector3d q;  ///< (ea0 + s u) − (eb0 + t v), along n
};

LinePair line_pair(const Eigen::Vector3d& ea0, const Eigen::Vector3d& ea1,
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
  return {s, t, n * (n.dot(between) / n_sq)};
}

/// The point–point or point–edge sub-case of each boundary case, indexed by EdgeEdgeCase
/// (A0B0 … B1EdgeA), in stencil slots (ea0, ea1, eb0, eb1) = (0, 1, 2, 3): four endpoint
/// pairs, then four endpoint–edge pairs.
constexpr std::array<PointFeature, 8> kBoundarySubCases{{{0, 1, {2, 0}},
                                                         {0, 1, {3, 0}},
                                                         {1, 1, {2, 0}},
                                                         {1, 1, {3, 0}},
                                                         {0, 2, {2, 3}},
                                                         {1, 2, {2, 3}},
                                                         {2, 2, {0, 1}},
                                                         {3, 2, {0, 1}}}};
static_assert(static_cast<int>(EdgeEdgeCase::LineLine) == kBoundarySubCases.size());

}  // namespace

double line_line_distance(const Eigen::Vector3d& ea0, const Eigen::Vector3d& ea1,
                          const Eigen::Vector3d& eb0, const Eigen::Vector3d& eb1) {
  return line_pair(ea0, ea1, eb0, eb1).q.squaredNorm();
}

StencilDerivatives<12> line_line_distance_derivatives(const Eigen::Vector3d& ea0,
                                                      const Eigen::Vector3d& ea1,
                                                      const Eigen::Vector3d& eb0,
                                                      const Eigen::Vector3d& eb1) {
  const LinePair pair = line_pair(ea0, ea1, eb0, eb1);
  // q = (1 − s) ea0 + s ea1 + (t − 1) eb0 − t eb1.
  const Eigen::Vector4d w(1 - pair.s, pair.s, pair.t - 1, -pair.t);
  Eigen::Matrix<double, 4, 2> dw_dst;
  dw_dst << -1, 0, 1, 0, 0, 1, 0, -1;
  return closest_pair_distance_derivatives<4, 2>(stack_stencil(ea0, ea1, eb0, eb1), w, dw_dst, pair.q);
}

double edge_edge_distance(const Eigen::Vector3d& ea0, const Eigen::Vector3d& ea1,
                          const Eigen::Vector3d& eb0, const Eigen::Vector3d& eb1) {
  const EdgeEdgeCase c = edge_edge_case(ea0, ea1, eb0, eb1);
  if (c == EdgeEdgeCase::LineLine) return line_line_distance(ea0, ea1, eb0, eb1);
  return point_feature_distance(kBoundarySubCases[static_cast<int>(c)],
                                stack_stencil(ea0, ea1, eb0, eb1));
}

StencilDerivatives<12> edge_edge_distance_derivatives(const Eigen::Vector3d& ea0,
                                                      const Eigen::Vector3d& ea1,
                                                      const Eigen::Vector3d& eb0,
                                                      const Eigen::Vector3d& eb1) {
  const EdgeEdgeCase c = edge_edge_case(ea0, ea1, eb0, eb1);
  if (c == EdgeEdgeCase::LineLine) return line_line_distance_derivatives(ea0, ea1, eb0, eb1);
  return point_feature_distance_derivatives(kBoundarySubCases[static_cast<int>(c)],
                                            stack_stencil(ea0, ea1, eb0, eb1));
}

}  // namespace psq
