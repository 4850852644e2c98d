#include "engine/contact/intersection_check.hpp"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Intersections_3/Segment_3_Triangle_3.h>
#include <CGAL/Intersections_3/Triangle_3_Triangle_3.h>
#include <fmt/format.h>
#include <tbb/parallel_for.h>

#include <algorithm>

#include "engine/contact/broad_phase.hpp"
#include "engine/core/error.hpp"

namespace psq {
namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = Kernel::Point_3;
using Segment = Kernel::Segment_3;
using Triangle = Kernel::Triangle_3;

/// The mesh as CGAL points, with the exact tests of one triangle pair.
class ExactMesh {
 public:
  ExactMesh(const Positions& positions, const Triangles& triangles) : triangles_(triangles) {
    points_.reserve(positions.rows());
    for (int v = 0; v < positions.rows(); ++v)
      points_.emplace_back(positions(v, 0), positions(v, 1), positions(v, 2));
  }

  [[nodiscard]] bool degenerate(int t) const {
    return CGAL::collinear(corner(t, 0), corner(t, 1), corner(t, 2));
  }

  /// Whether non-degenerate triangles s and t meet beyond their shared vertices.
  [[nodiscard]] bool intersect(int s, int t) const {
    std::array<int, 3> shared_in_s{}, shared_in_t{};  // corner slots of the shared vertices
    int shared = 0;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j)
        if (triangles_(s, i) == triangles_(t, j)) {
          shared_in_s[shared] = i;
          shared_in_t[shared] = j;
          ++shared;
        }
    switch (shared) {
      case 0:
        return CGAL::do_intersect(triangle(s), triangle(t));
      case 1:
        return CGAL::do_intersect(opposite_edge(s, shared_in_s[0]), triangle(t)) ||
               CGAL::do_intersect(opposite_edge(t, shared_in_t[0]), triangle(s));
      case 2:
        return folded_onto_each_other(s, t, shared_in_s[0], shared_in_s[1], shared_in_t[0],
                                      shared_in_t[1]);
      default:
        return true;
    }
  }

 private:
  [[nodiscard]] const Point& corner(int t, int k) const { return points_[triangles_(t, k)]; }
  [[nodiscard]] Triangle triangle(int t) const {
    return {corner(t, 0), corner(t, 1), corner(t, 2)};
  }
  [[nodiscard]] Segment opposite_edge(int t, int k) const {
    return {corner(t, (k + 1) % 3), corner(t, (k + 2) % 3)};
  }

  /// Triangles sharing the edge at slots (i0, i1) of s and (j0, j1) of t: coplanar, with the
  /// third corners strictly on the same side of the shared edge.
  [[nodiscard]] bool folded_onto_each_other(int s, int t, int i0, int i1, int j0, int j1) const {
    const Point& u = corner(s, i0);
    const Point& v = corner(s, i1);
    const Point& a = corner(s, 3 - i0 - i1);
    const Point& b = corner(t, 3 - j0 - j1);
    return CGAL::coplanar(u, v, a, b) && CGAL::coplanar_orientation(u, v, a, b) == CGAL::POSITIVE;
  }

  const Triangles& triangles_;
  std::vector<Point> points_;
};

}  // namespace

IntersectionReport find_intersections(const Positions& positions, const Triangles& triangles) {
  const ExactMesh mesh(positions, triangles);
  IntersectionReport report;
  report.triangle_count = static_cast<int>(triangles.rows());

  std::vector<char> degenerate(triangles.rows());
  tbb::parallel_for(0, report.triangle_count, [&](int t) { degenerate[t] = mesh.degenerate(t); });
  for (int t = 0; t < report.triangle_count; ++t)
    if (degenerate[t]) report.degenerate_triangles.push_back(t);

  const std::vector<std::array<int, 2>> candidates =
      overlapping_triangle_boxes(positions, triangles);
  std::vector<char> hit(candidates.size());
  tbb::parallel_for(std::size_t{0}, candidates.size(), [&](std::size_t k) {
    const auto [s, t] = candidates[k];
    hit[k] = !degenerate[s] && !degenerate[t] && mesh.intersect(s, t);
  });
  for (std::size_t k = 0; k < candidates.size(); ++k)
    if (hit[k]) report.intersecting_pairs.push_back(candidates[k]);
  return report;
}

std::string describe_triangle(int triangle, const std::vector<TrianglePart>& parts) {
  for (const TrianglePart& part : parts)
    if (triangle >= part.first_triangle && triangle < part.first_triangle + part.triangle_count)
      return fmt::format("{} triangle {}", part.name, triangle - part.first_triangle);
  return fmt::format("triangle {}", triangle);
}

std::string list_intersections(const IntersectionReport& report,
                               const std::vector<TrianglePart>& parts, std::size_t max_listed) {
  std::string out;
  const std::size_t pairs = report.intersecting_pairs.size();
  if (pairs > 0)
    out += fmt::format("{} intersecting triangle pair{}:\n", pairs, pairs == 1 ? "" : "s");
  for (std::size_t k = 0; k < std::min(pairs, max_listed); ++k) {
    const auto [s, t] = report.intersecting_pairs[k];
    out += fmt::format("  {} and {}\n", describe_triangle(s, parts), describe_triangle(t, parts));
  }
  if (pairs > max_listed) out += fmt::format("  ... and {} more\n", pairs - max_listed);
  for (int t : report.degenerate_triangles)
    out += fmt::format("{} is degenerate (collinear corners)\n", describe_triangle(t, parts));
  return out;
}

void require_intersection_free(const TriMesh& mesh, const std::string& what,
                               const std::vector<TrianglePart>& parts) {
  const IntersectionReport report = find_intersections(mesh.vertices, mesh.triangles);
  if (report.clean()) return;
  throw InputError(fmt::format(
      "{}: the state is not free of intersections (exact check of {} triangles):\n{}"
      "Move the shells and colliders apart or fix the meshes; contact can only keep apart what "
      "starts apart.",
      what, report.triangle_count, list_intersections(report, parts)));
}

}  // namespace psq
