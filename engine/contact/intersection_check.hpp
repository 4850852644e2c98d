#pragma once
// Exact intersection check of a triangle mesh (all shells and colliders concatenated): the
// independent judge of the promise that every accepted state is free of intersections.
// Predicates are exact (CGAL, filtered), so the verdict does not depend on round-off; a
// touching pair counts as intersecting.

#include <array>
#include <cstddef>
#include <string>
#include <vector>

#include "engine/mesh/tri_mesh.hpp"

namespace psq {

struct IntersectionReport {
  int triangle_count = 0;
  std::vector<std::array<int, 2>> intersecting_pairs;  ///< (i, j), i < j, sorted
  std::vector<int> degenerate_triangles;               ///< collinear corners, sorted

  /// No intersecting pair and no degenerate triangle (which could not be checked).
  [[nodiscard]] bool clean() const {
    return intersecting_pairs.empty() && degenerate_triangles.empty();
  }
};

/// Every pair of triangles with a common point, judged with exact predicates, except pairs
/// that meet only where their shared corners say they must:
/// - no shared vertex: any common point counts (touching included);
/// - one shared vertex v: they intersect iff the edge opposite v in either triangle meets
///   the other triangle (T₁ ∩ T₂ is convex and contains v, so it holds more than v exactly
///   when a segment from v leaves one triangle through its opposite edge inside the other);
/// - a shared edge: they intersect iff they are coplanar with the third corners on the same
///   side of the edge (folded flat onto each other); distinct planes meet only on the edge;
/// - three shared vertices: a duplicated triangle, always intersecting.
/// Degenerate triangles are reported separately and left out of the pairs. Candidate pairs
/// come from overlapping_triangle_boxes; the exact tests run in parallel.
IntersectionReport find_intersections(const Positions& positions, const Triangles& triangles);

/// A named run of consecutive triangles of a concatenated mesh, such as "shell 'cloth'".
struct TrianglePart {
  std::string name;
  int first_triangle = 0;
  int triangle_count = 0;
};

/// "shell 'cloth' triangle 12" (index local to its part), or "triangle 12" without parts.
std::string describe_triangle(int triangle, const std::vector<TrianglePart>& parts);

/// One line per intersecting pair (at most `max_listed`, then "... and N more") and the
/// degenerate triangles, each line ending in '\n'. Empty for a clean report.
std::string list_intersections(const IntersectionReport& report,
                               const std::vector<TrianglePart>& parts, std::size_t max_listed = 20);

/// Throws InputError "<what>: the state is not free of intersections: <listing>" unless the
/// mesh passes find_intersections; for refusing to start a simulation from such a state.
void require_intersection_free(const TriMesh& mesh, const std::string& what,
                               const std::vector<TrianglePart>& parts = {});

}  // namespace psq
