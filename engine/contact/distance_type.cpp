#include "engine/contact/distance_type.hpp"

#include <Eigen/Geometry>
#include <array>
#include <limits>
#include <utility>

#include "engine/contact/point_edge_distance.hpp"

namespace psq {
namespace {

/// True when sin²θ between a and b, whose cross product is `a_cross_b`, is below
/// kCollinearSineSquared, and when either is zero (from ‖a × b‖² = ‖a‖²‖b‖² sin²θ, no
/// division). The callers need the cross product themselves.
bool is_collinear(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                  const Eigen::Vector3d& a_cross_b) {
  return !(a_cross_b.squaredNorm() > kCollinearSineSquared * a.squaredNorm() * b.squaredNorm());
}

/// The nearest of several point–edge pairs: the index of the pair and its case, and its
/// squared distance in `distance` when given. Ties keep the first, so the choice is
/// deterministic.
template <std::size_t Count>
std::pair<std::size_t, PointEdgeCase> nearest_point_edge(
    const std::array<std::array<const Eigen::Vector3d*, 3>, Count>& pairs, double* distance) {
  std::size_t best = 0;
  double best_distance = std::numeric_limits<double>::infinity();
  std::array<PointEdgeCase, Count> cases;
  std::array<double, Count> distances;
  for (std::size_t i = 0; i < Count; ++i) {
    const auto& [p, e0, e1] = pairs[i];
    cases[i] = point_edge_case(*p, *e0, *e1);
    distances[i] = point_edge_distance(*p, *e0, *e1, cases[i]);
    if (distances[i] < best_distance) {
      best = i;
      best_distance = distances[i];
    }
  }
  // With no distance below infinity (NaN coordinates) the first pair's own value is given, NaN
  // included, so that a non-finite state reaches the barrier.
  if (distance != nullptr) *distance = distances[best];
  return {best, cases[best]};
}

/// Whether p projects onto the inner side of the edge (ti, tj) of a triangle with normal n
/// (boundary included).
bool projects_inside_edge(const Eigen::Vector3d& n, const Eigen::Vector3d& p,
                          const Eigen::Vector3d& ti, const Eigen::Vector3d& tj) {
  return n.dot((tj - ti).cross(p - ti)) >= 0;
}

}  // namespace

PointEdgeCase point_edge_case(const Eigen::Vector3d& p, const Eigen::Vector3d& e0,
                              const Eigen::Vector3d& e1) {
  const Eigen::Vector3d e = e1 - e0;
  const double e_sq = e.squaredNorm();
  const double along = (p - e0).dot(e);  // α ‖e‖², compared without dividing
  if (e_sq == 0 || along <= 0) return PointEdgeCase::Vertex0;
  if (along >= e_sq) return PointEdgeCase::Vertex1;
  return PointEdgeCase::Line;
}

PointTriangleCase point_triangle_case(const Eigen::Vector3d& p, const Eigen::Vector3d& t0,
                                      const Eigen::Vector3d& t1, const Eigen::Vector3d& t2,
                                      double* boundary_distance) {
  const Eigen::Vector3d a = t1 - t0, b = t2 - t0;
  const Eigen::Vector3d n = a.cross(b);
  if (!is_collinear(a, b, n) && projects_inside_edge(n, p, t0, t1) &&
      projects_inside_edge(n, p, t1, t2) && projects_inside_edge(n, p, t2, t0))
    return PointTriangleCase::Face;

  // Outside the face region the distance, a convex function on the triangle, is smallest on
  // its boundary: at the nearest of the three edges.
  const auto [edge, edge_case] =
      nearest_point_edge<3>({{{&p, &t0, &t1}, {&p, &t1, &t2}, {&p, &t2, &t0}}}, boundary_distance);
  // Per edge: the case when the closest point is its first endpoint, its second endpoint, or
  // inside it (indexed by PointEdgeCase).
  constexpr std::array<std::array<PointTriangleCase, 3>, 3> kCases{{
      {PointTriangleCase::Vertex0, PointTriangleCase::Vertex1, PointTriangleCase::Edge01},
      {PointTriangleCase::Vertex1, PointTriangleCase::Vertex2, PointTriangleCase::Edge12},
      {PointTriangleCase::Vertex2, PointTriangleCase::Vertex0, PointTriangleCase::Edge20},
  }};
  return kCases[edge][static_cast<int>(edge_case)];
}

EdgeEdgeCase edge_edge_case(const Eigen::Vector3d& ea0, const Eigen::Vector3d& ea1,
                            const Eigen::Vector3d& eb0, const Eigen::Vector3d& eb1,
                            double* boundary_distance) {
  const Eigen::Vector3d u = ea1 - ea0;
  const Eigen::Vector3d v = eb1 - eb0;
  const Eigen::Vector3d n = u.cross(v);
  if (!is_collinear(u, v, n)) {
    // Unconstrained minimiser (s, t) of ‖ea0 + s u − eb0 − t v‖², scaled by ‖n‖² > 0.
    const Eigen::Vector3d w0 = ea0 - eb0;
    const double n_sq = n.squaredNorm();
    const double s = n.dot(v.cross(w0));
    const double t = n.dot(u.cross(w0));
    if (s > 0 && s < n_sq && t > 0 && t < n_sq) return EdgeEdgeCase::LineLine;
  }

  // Otherwise the minimum over [0, 1]² lies on the square's boundary: an endpoint of one edge
  // against the other edge.
  const auto [pair, edge_case] = nearest_point_edge<4>(
      {{{&ea0, &eb0, &eb1}, {&ea1, &eb0, &eb1}, {&eb0, &ea0, &ea1}, {&eb1, &ea0, &ea1}}},
      boundary_distance);
  // Per candidate: the case when the closest point is the edge's first endpoint, its second
  // endpoint, or inside it (indexed by PointEdgeCase).
  constexpr std::array<std::array<EdgeEdgeCase, 3>, 4> kCases{{
      {EdgeEdgeCase::A0B0, EdgeEdgeCase::A0B1, EdgeEdgeCase::A0EdgeB},
      {EdgeEdgeCase::A1B0, EdgeEdgeCase::A1B1, EdgeEdgeCase::A1EdgeB},
      {EdgeEdgeCase::A0B0, EdgeEdgeCase::A1B0, EdgeEdgeCase::B0EdgeA},
      {EdgeEdgeCase::A0B1, EdgeEdgeCase::A1B1, EdgeEdgeCase::B1EdgeA},
  }};
  return kCases[pair][static_cast<int>(edge_case)];
}

}  // namespace psq
