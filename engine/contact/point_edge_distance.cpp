#include "engine/contact/point_edge_distance.hpp"

#include <array>

namespace psq {
namespace {

/// point_feature's table for PointTriangleCase (Vertex0 … Edge20): three vertices, then three
/// edges.
constexpr std::array<PointFeature, 6> kPointTriangleSubCases{{{0, 1, {1, 0}},
                                                              {0, 1, {2, 0}},
                                                              {0, 1, {3, 0}},
                                                              {0, 2, {1, 2}},
                                                              {0, 2, {2, 3}},
                                                              {0, 2, {3, 1}}}};
static_assert(static_cast<int>(PointTriangleCase::Face) == kPointTriangleSubCases.size());

/// point_feature's table for EdgeEdgeCase (A0B0 … B1EdgeA): four endpoint pairs, then four
/// endpoint–edge pairs.
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

LineFoot line_foot(const Eigen::Vector3d& p, const Eigen::Vector3d& e0, const Eigen::Vector3d& e1) {
  const Eigen::Vector3d e = e1 - e0;
  const Eigen::Vector3d r = p - e0;
  const double alpha = r.dot(e) / e.squaredNorm();
  return {alpha, r - alpha * e};
}

double point_point_distance(const Eigen::Vector3d& p, const Eigen::Vector3d& q) {
  return (p - q).squaredNorm();
}

StencilDerivatives<6> point_point_distance_derivatives(const Eigen::Vector3d& p,
                                                       const Eigen::Vector3d& q) {
  Eigen::Matrix<double, 3, 2> x;
  x << p, q;
  return closest_pair_distance_derivatives<2, 0>(x, Eigen::Vector2d(1, -1),
                                                 Eigen::Matrix<double, 2, 0>(), p - q);
}

double point_line_distance(const Eigen::Vector3d& p, const Eigen::Vector3d& e0,
                           const Eigen::Vector3d& e1) {
  return line_foot(p, e0, e1).q.squaredNorm();
}

StencilDerivatives<9> point_line_distance_derivatives(const Eigen::Vector3d& p,
                                                      const Eigen::Vector3d& e0,
                                                      const Eigen::Vector3d& e1) {
  const LineFoot foot = line_foot(p, e0, e1);
  Eigen::Matrix3d x;
  x << p, e0, e1;
  // q = p + (α − 1) e0 − α e1.
  const Eigen::Vector3d w(1, foot.alpha - 1, -foot.alpha);
  const Eigen::Vector3d dw_dalpha(0, 1, -1);
  return closest_pair_distance_derivatives<3, 1>(x, w, dw_dalpha, foot.q);
}

double point_edge_distance(const Eigen::Vector3d& p, const Eigen::Vector3d& e0,
                           const Eigen::Vector3d& e1) {
  return point_edge_distance(p, e0, e1, point_edge_case(p, e0, e1));
}

double point_edge_distance(const Eigen::Vector3d& p, const Eigen::Vector3d& e0,
                           const Eigen::Vector3d& e1, PointEdgeCase edge_case) {
  switch (edge_case) {
    case PointEdgeCase::Vertex0:
      return point_point_distance(p, e0);
    case PointEdgeCase::Vertex1:
      return point_point_distance(p, e1);
    case PointEdgeCase::Line:
      break;
  }
  return point_line_distance(p, e0, e1);
}

StencilDerivatives<9> point_edge_distance_derivatives(const Eigen::Vector3d& p,
                                                      const Eigen::Vector3d& e0,
                                                      const Eigen::Vector3d& e1) {
  switch (point_edge_case(p, e0, e1)) {
    case PointEdgeCase::Vertex0:
      return embed_in_stencil<3, 2>(point_point_distance_derivatives(p, e0), {0, 1});
    case PointEdgeCase::Vertex1:
      return embed_in_stencil<3, 2>(point_point_distance_derivatives(p, e1), {0, 2});
    case PointEdgeCase::Line:
      break;
  }
  return point_line_distance_derivatives(p, e0, e1);
}

const PointFeature& point_feature(PointTriangleCase boundary_case) {
  return kPointTriangleSubCases[static_cast<int>(boundary_case)];
}

const PointFeature& point_feature(EdgeEdgeCase boundary_case) {
  return kEdgeEdgeSubCases[static_cast<int>(boundary_case)];
}

double point_feature_distance(const PointFeature& sub_case, const StencilPositions& x) {
  const auto& [point, size, feature] = sub_case;
  if (size == 1) return point_point_distance(x.col(point), x.col(feature[0]));
  return point_line_distance(x.col(point), x.col(feature[0]), x.col(feature[1]));
}

StencilDerivatives<12> point_feature_distance_derivatives(const PointFeature& sub_case,
                                                          const StencilPositions& x) {
  const auto& [point, size, feature] = sub_case;
  if (size == 1)
    return embed_in_stencil<4, 2>(point_point_distance_derivatives(x.col(point), x.col(feature[0])),
                                  {point, feature[0]});
  return embed_in_stencil<4, 3>(
      point_line_distance_derivatives(x.col(point), x.col(feature[0]), x.col(feature[1])),
      {point, feature[0], feature[1]});
}

}  // namespace psq
