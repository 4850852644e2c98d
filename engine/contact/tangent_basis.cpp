#include "engine/contact/tangent_basis.hpp"

#include <Eigen/Geometry>

#include "engine/contact/edge_edge_distance.hpp"
#include "engine/contact/point_triangle_distance.hpp"

namespace psq {
namespace {

/// The frame of an interior case (point–plane, line–line): the plane orthogonal to the
/// features' common normal.
ContactFrame closest_pair_frame(const ClosestPair& pair) {
  return {tangent_basis(pair.normal), pair.weights};
}

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
  const LineFoot foot = line_foot(p, x.col(feature[0]), x.col(feature[1]));
  frame.weights[feature[0]] = foot.alpha - 1;
  frame.weights[feature[1]] = -foot.alpha;
  frame.basis = tangent_basis(foot.q);
  return frame;
}

ContactFrame point_triangle_frame(const StencilPositions& x, PointTriangleCase sub_case) {
  if (sub_case != PointTriangleCase::Face) return point_feature_frame(point_feature(sub_case), x);
  return closest_pair_frame(point_plane_closest_pair(x.col(0), x.col(1), x.col(2), x.col(3)));
}

ContactFrame point_triangle_frame(const StencilPositions& x) {
  return point_triangle_frame(x, point_triangle_case(x.col(0), x.col(1), x.col(2), x.col(3)));
}

ContactFrame edge_edge_frame(const StencilPositions& x, EdgeEdgeCase sub_case) {
  if (sub_case != EdgeEdgeCase::LineLine) return point_feature_frame(point_feature(sub_case), x);
  return closest_pair_frame(line_line_closest_pair(x.col(0), x.col(1), x.col(2), x.col(3)));
}

ContactFrame edge_edge_frame(const StencilPositions& x) {
  return edge_edge_frame(x, edge_edge_case(x.col(0), x.col(1), x.col(2), x.col(3)));
}

}  // namespace psq
