#pragma once
// Broad phase of contact: which point–triangle and edge–edge pairs of a contact surface are
// close enough (now, or somewhere along a linear motion) to need a distance or CCD query.
// The surface is every shell and collider concatenated into one vertex array; a per-vertex
// body id lets the caller decide which bodies may touch which (self-contact included).
//
// Candidates come from bounding volume hierarchies over each body's vertices, edges and
// triangles, rebuilt for each query (building is a parallel sort, cheaper than the search),
// searched pairwise (both trees descended together) for each pair of bodies that may touch:
// one tree over the whole surface would descend into every pair of a finely meshed collider's
// own neighbouring elements, which can never touch, and a query whose reach is a few edge
// lengths would spend its time there. Measured against a uniform spatial hash (cell = mean edge
// length, one thread, 80k-triangle sheet): equal on a uniform mesh, 8× faster once a coarse
// collider (40× longer edges) lies under the sheet, since a hash must store each large
// triangle in every cell it covers; swept boxes vary in size the same way.

#include <array>
#include <compare>
#include <cstddef>
#include <functional>
#include <vector>

#include "engine/mesh/tri_mesh.hpp"

namespace psq {

/// A vertex and a triangle that does not contain it.
struct PointTriangleCandidate {
  int vertex;
  int triangle;
  friend auto operator<=>(const PointTriangleCandidate&, const PointTriangleCandidate&) = default;
};

/// Two edges (indices into the edge list) without a common vertex, edge0 < edge1.
struct EdgeEdgeCandidate {
  int edge0;
  int edge1;
  friend auto operator<=>(const EdgeEdgeCandidate&, const EdgeEdgeCandidate&) = default;
};

/// Candidate pairs, each list sorted and free of duplicates.
struct ContactCandidates {
  std::vector<PointTriangleCandidate> point_triangle;
  std::vector<EdgeEdgeCandidate> edge_edge;

  [[nodiscard]] bool empty() const { return point_triangle.empty() && edge_edge.empty(); }
  [[nodiscard]] std::size_t size() const { return point_triangle.size() + edge_edge.size(); }
};

/// Whether two bodies can touch; `a == b` asks about self-contact. Symmetric.
using BodyPairRule = std::function<bool(int body_a, int body_b)>;

/// Candidate search over a fixed contact surface (connectivity and bodies); positions are
/// given to each query. Pairs sharing a vertex and pairs of bodies the rule keeps apart are
/// never reported. Queries run in parallel (TBB) and their output does not depend on the
/// thread count. Every query throws NumericalError for a non-finite position.
///
/// `reach` is the distance below which a pair interacts: d̂ for the barrier, plus the
/// thickness offset when there is one. Boxes are compared with closed inequalities, so a
/// pair exactly `reach` apart is a candidate.
class BroadPhase {
 public:
  /// `triangles` and `edges` index a vertex array of `vertex_body.size()` vertices; body ids
  /// are 0..B−1. An empty `may_touch` lets every pair of bodies touch, itself included.
  /// Throws std::invalid_argument for a vertex index out of range or a negative body id.
  BroadPhase(Triangles triangles, std::vector<std::array<int, 2>> edges,
             std::vector<int> vertex_body, const BodyPairRule& may_touch = {});

  [[nodiscard]] const Triangles& triangles() const { return triangles_; }
  [[nodiscard]] const std::vector<std::array<int, 2>>& edges() const { return edges_; }

  /// Pairs whose axis-aligned bounding boxes, one inflated by `reach`, overlap at x:
  /// a superset of the pairs with distance ≤ reach.
  [[nodiscard]] ContactCandidates distance_candidates(const Positions& x, double reach) const;

  /// Pairs whose boxes covering the linear motion x0 → x1, one inflated by `reach`, overlap:
  /// a superset of the pairs that come within `reach` at some t ∈ [0, 1].
  [[nodiscard]] ContactCandidates swept_candidates(const Positions& x0, const Positions& x1,
                                                   double reach) const;

  /// How far apart the surface is at x: the smallest contact distance (point_triangle_distance,
  /// edge_edge_distance, so that neighbouring elements of a flat sheet, whose boxes touch, do
  /// not count) of a pair whose boxes come within `cap`, or `cap` when there is none (a NaN
  /// distance counts as 0). Stops at the first pair found within `floor` ≤ cap and returns its
  /// distance, so a result ≤ floor says only that some pair is that near: with floor = reach
  /// < cap, a result above reach means no barrier term is active at x. Costs a
  /// distance_candidates(x, cap) search with a distance per candidate.
  [[nodiscard]] double clearance(const Positions& x, double floor, double cap) const;

  /// Whether any pair may come within `reach` during the linear motion x0 → x1. A pair is
  /// ruled out by the bound d(t) ≥ max(d(0), d(1)) − max_{i,j} ‖u_i − u_j‖ (u the
  /// displacements x1 − x0, i over one element's vertices, j over the other's). False means
  /// that no pair comes within `reach` on the way, so a CCD that stops pairs at a gap below
  /// `reach` has nothing to find in this step. Stops at the first pair found.
  [[nodiscard]] bool any_within_reach_during(const Positions& x0, const Positions& x1,
                                             double reach) const;

 private:
  /// A body's vertices, edges and triangles (indices into the surface's arrays); an edge or
  /// triangle belongs to the body of its first vertex.
  struct BodyElements {
    std::vector<int> vertices, edges, triangles;
  };
  struct ElementBoxes;
  struct Trees;
  [[nodiscard]] ContactCandidates candidates(const ElementBoxes& boxes, double reach) const;
  /// visit(v, t) for the vertex–triangle box pairs within `reach` of each ordered pair of bodies
  /// that may touch, each body's trees searched only against those it may touch (a collider's
  /// own dense pairs are never visited); false when visit stopped the search.
  template <class Visit>
  bool search_point_triangle(const Trees& trees, double reach, const Visit& visit) const;
  /// The same for edge–edge box pairs, each unordered pair of bodies once.
  template <class Visit>
  bool search_edge_edge(const Trees& trees, double reach, const Visit& visit) const;
  template <class Near>
  [[nodiscard]] bool any_pair(const ElementBoxes& boxes, double reach, const Near& near) const;
  [[nodiscard]] bool is_point_triangle_pair(int v, int t) const;
  [[nodiscard]] bool is_edge_edge_pair(int e, int f) const;
  [[nodiscard]] bool bodies_may_touch(int vertex_a, int vertex_b) const;
  void check_vertex_count(const Positions& x) const;

  Triangles triangles_;
  std::vector<std::array<int, 2>> edges_;
  std::vector<int> vertex_body_;
  int body_count_ = 0;
  std::vector<char> body_pair_allowed_;  ///< body_count_² flags
  std::vector<BodyElements> bodies_;
};

/// Every pair of triangles (i < j) whose closed bounding boxes overlap, neighbours included,
/// sorted: the broad phase of the exact intersection check.
std::vector<std::array<int, 2>> overlapping_triangle_boxes(const Positions& x,
                                                           const Triangles& triangles);

}  // namespace psq
