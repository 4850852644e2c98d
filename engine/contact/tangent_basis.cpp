#include "engine/contact/tangent_basis.hpp"

#include <Eigen/Geometry>
#include <array>

namespace psq {
namespace {

// The point–point and point–edge sub-cases of the boundary cases, in stencil slots. They
// restate the tables of point_triangle_distance.cpp and edge_edge_distance.cpp, which are
// private to those files.

/// Indexed by PointTriangleCase (Vertex0 … Edge20); slots (p, t0, t1, t2) = (0, 1, 2, 3).
constexpr std::array<PointFeature, 6> kPointTriangleSubCases{{{0, 1, {1, 0}},
                                                              {0, 1, {2, 0}},
                                                              {0, 1, {3, 0}},
                                                              {0, 2, {1, 2}},
                                                              {0, 2, {2, 3}},
                                                              {0, 2, {3, 1}}}};
static_assert(static_cast<int>(PointTriangleCase::Face) == kPointTriangleSubCases.size());

/// Indexed by EdgeEdgeCase (A0B0 … B1EdgeA); slots (ea0, ea1, eb0, eb1) = (0, 1, 2, 3).
constexpr std::array<PointFeature, 8> kEdgeEdgeSubCases{{{0, 1, {2, 0}},
                                                         {0, 1, {3, 0}},
                                                         {1, 1, {2, 0}},
                                                         {1, 1, {3, 0}},
                                                         {0, 2, {2, 3}},
                                                         {1, 2, {2, 3}},
                                                         {2, 2, {0, 1}},
                                                         {3, 2, {0, 1}}}};
static_assert(static_cast<int>(EdgeEdgeCase::LineLine) == kEdgeEdgeSubCases.size());

}  // namespace

TangentBasis tangent_basis(const Eigen::Vector3d& normal) {
  Eigen::Index least_aligned = 0;
  normal.cwiseAbs().minCoeff(&least_aligned);
  const Eigen::Vector3d first = normal.cross(Eigen::Vector3d::Unit(least_aligned)).normalized();
  TangentBasis basis;
  basis << first, normal.normalized().cross(first);
  return basis;
}

ContactFrame point_feature_frame(const PointFeature& sub_case, const StencilPositions& x) {
  const auto& [point, size, feature] = sub_case;
  ContactFrame frame;
  frame.weights.setZero();
  frame.weights[point] = 1;
  const Eigen::Vector3d p = x.col(point);
  if (size == 1) {
    frame.weights[feature[0]] = -1;
    frame.basis = tangent_basis(p - x.col(feature[0]));
    return frame;
  }
  const Eigen::Vector3d e0 = x.col(feature[0]);
  const Eigen::Vector3d e = x.col(feature[1]) - e0;
  const double alpha = (p - e0).dot(e) / e.squaredNorm();
  frame.weights[feature[0]] = alpha - 1;
  frame.weights[feature[1]] = -alpha;
  frame.basis = tangent_basis(p - e0 - alpha * e);
  return frame;
}

ContactFrame point_triangle_frame(const StencilPositions& x, PointTriangleCase sub_case) {
  if (sub_case != PointTriangleCase::Face)
    return point_feature_frame(kPointTriangleSubCases[static_cast<int>(sub_case)], x);
  const Eigen::Vector3d e1 = x.col(2) - x.col(1);
  const Eigen::Vector3d e2 = x.col(3) - x.col(1);
  const Eigen::Vector3d r = x.col(0) - x.col(1);
  const Eigen::Vector3d n = e1.cross(e2);
  const double n_sq = n.squaredNorm();
  const double beta1 = n.dot(r.cross(e2)) / n_sq;
  const double beta2 = n.dot(e1.cross(r)) / n_sq;
  return {tangent_basis(n), Eigen::Vector4d(1, beta1 + beta2 - 1, -beta1, -beta2)};
}

ContactFrame point_triangle_frame(const StencilPositions& x) {
  return point_triangle_frame(x, point_triangle_case(x.col(0), x.col(1), x.col(2), x.col(3)));
}

ContactFrame edge_edge_frame(const StencilPositions& x, EdgeEdgeCase sub_case) {
  if (sub_case != EdgeEdgeCase::LineLine)
    return point_feature_frame(kEdgeEdgeSubCases[static_cast<int>(sub_case)], x);
  const Eigen::Vector3d u = x.col(1) - x.col(0);
  const Eigen::Vector3d v = x.col(3) - x.col(2);
  const Eigen::Vector3d w0 = x.col(0) - x.col(2);
  const Eigen::Vector3d n = u.cross(v);
  const double n_sq = n.squaredNorm();
  const double s = n.dot(v.cross(w0)) / n_sq;
  const double t = n.dot(u.cross(w0)) / n_sq;
  return {tangent_basis(n), Eigen::Vector4d(1 - s, s, t - 1, -t)};
}

ContactFrame edge_edge_frame(const StencilPositions& x) {
  return edge_edge_frame(x, edge_edge_case(x.col(0), x.col(1), x.col(2), x.col(3)));
}

}  // namespace psq
