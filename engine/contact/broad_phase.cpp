#include "engine/contact/broad_phase.hpp"

#include <fmt/format.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>
#include <tbb/parallel_sort.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <optional>
#include <stdexcept>

#include "engine/contact/edge_edge_distance.hpp"
#include "engine/contact/point_triangle_distance.hpp"
#include "engine/core/error.hpp"

namespace psq {
namespace {

using Box = Eigen::AlignedBox3d;
using Vector3 = Eigen::Vector3d;

/// Spreads the low 21 bits of v so that bit k lands on bit 3k (one axis of a Morton code).
std::uint64_t spread_bits(std::uint64_t v) {
  v &= 0x1fffffULL;
  v = (v | v << 32) & 0x1f00000000ffffULL;
  v = (v | v << 16) & 0x1f0000ff0000ffULL;
  v = (v | v << 8) & 0x100f00f00f00f00fULL;
  v = (v | v << 4) & 0x10c30c30c30c30c3ULL;
  v = (v | v << 2) & 0x1249249249249249ULL;
  return v;
}

/// Morton code of a point of `bounds`, 21 bits per axis. The cells are cubes (the largest
/// extent on every axis): stretching a thin axis to the full range would let it dominate the
/// order, and a flat sheet's neighbours would end up far apart along the curve.
std::uint64_t morton_code(const Vector3& p, const Box& bounds) {
  constexpr double kCells = double(1 << 21);
  const double extent = std::max(bounds.sizes().maxCoeff(), 1e-300);
  std::uint64_t code = 0;
  for (int axis = 0; axis < 3; ++axis) {
    const double t = (p[axis] - bounds.min()[axis]) / extent;
    const auto cell = static_cast<std::uint64_t>(std::clamp(t * kCells, 0.0, kCells - 1));
    code |= spread_bits(cell) << axis;
  }
  return code;
}

/// Whether closed boxes a and b come within `reach` of each other along every axis.
inline bool within_reach(const Box& a, const Box& b, double reach) {
  for (int axis = 0; axis < 3; ++axis)
    if (a.min()[axis] > b.max()[axis] + reach || b.min()[axis] > a.max()[axis] + reach)
      return false;
  return true;
}

/// A bounding volume hierarchy over boxes. Primitives are sorted along a Morton curve of
/// their centres and grouped in leaves of kLeafSize consecutive ones; the tree over the m
/// leaves splits each range of leaves in halves. Any binary tree over m leaves has 2m − 1
/// nodes, and with halving splits a subtree's place in the depth-first node array is known
/// before its boxes are, so subtrees are built in parallel into one preallocated array.
class BoxTree {
 public:
  static constexpr int kLeafSize = 4;

  /// Primitives [first, first + count) of the sorted arrays; a leaf if count ≤ kLeafSize
  /// (only the last leaf may hold fewer than kLeafSize, so an inner node holds more).
  /// An inner node's children are at index + 1 and at `right`.
  struct Node {
    Box box;
    int first = 0;
    int count = 0;
    int right = 0;
  };

  explicit BoxTree(const std::vector<Box>& boxes) {
    const int n = static_cast<int>(boxes.size());
    if (n == 0) return;
    sort_along_morton_curve(boxes);
    const int leaves = (n + kLeafSize - 1) / kLeafSize;
    nodes_.resize(2 * leaves - 1);
    build(0, 0, leaves);
  }

  [[nodiscard]] bool empty() const { return nodes_.empty(); }
  [[nodiscard]] const Node& node(int index) const { return nodes_[index]; }
  [[nodiscard]] static bool is_leaf(const Node& node) { return node.count <= kLeafSize; }
  /// Box and primitive id at position k of the Morton order.
  [[nodiscard]] const Box& sorted_box(int k) const { return sorted_boxes_[k]; }
  [[nodiscard]] int sorted_id(int k) const { return sorted_ids_[k]; }

 private:
  static constexpr int kParallelLeaves = 1024;

  void sort_along_morton_curve(const std::vector<Box>& boxes) {
    const int n = static_cast<int>(boxes.size());
    Box centres;
    for (const Box& b : boxes) centres.extend(b.center());
    std::vector<std::pair<std::uint64_t, int>> keys(n);
    tbb::parallel_for(0, n, [&](int i) { keys[i] = {morton_code(boxes[i].center(), centres), i}; });
    tbb::parallel_sort(keys.begin(), keys.end());
    sorted_boxes_.resize(n);
    sorted_ids_.resize(n);
    tbb::parallel_for(0, n, [&](int k) {
      sorted_ids_[k] = keys[k].second;
      sorted_boxes_[k] = boxes[keys[k].second];
    });
  }

  /// Fills the subtree over `leaf_count` leaves from `first_leaf` rooted at nodes_[index].
  void build(int index, int first_leaf, int leaf_count) {
    Node& node = nodes_[index];
    const int primitives = static_cast<int>(sorted_ids_.size());
    node.first = first_leaf * kLeafSize;
    node.count = std::min(primitives, (first_leaf + leaf_count) * kLeafSize) - node.first;
    if (leaf_count == 1) {
      node.box.setEmpty();
      for (int k = node.first; k < node.first + node.count; ++k) node.box.extend(sorted_boxes_[k]);
      return;
    }
    const int left_leaves = leaf_count / 2;
    node.right = index + 2 * left_leaves;
    const auto build_left = [&] { build(index + 1, first_leaf, left_leaves); };
    const auto build_right = [&] {
      build(node.right, first_leaf + left_leaves, leaf_count - left_leaves);
    };
    if (leaf_count > kParallelLeaves) {
      tbb::parallel_invoke(build_left, build_right);
    } else {
      build_left();
      build_right();
    }
    node.box = nodes_[index + 1].box.merged(nodes_[node.right].box);
  }

  std::vector<Box> sorted_boxes_;
  std::vector<int> sorted_ids_;
  std::vector<Node> nodes_;
};

/// Finds the pairs of primitives, one from each of two trees or two distinct ones of one
/// tree, whose boxes come within `reach`: a simultaneous descent of both trees that refines
/// each pair of overlapping nodes by splitting the larger one, so that the shared top of the
/// trees is visited once rather than once per primitive. Large subtree pairs are searched in
/// parallel; visit(i, j) is called concurrently, and returning false stops the search.
template <class Visit>
class OverlapSearch {
 public:
  OverlapSearch(const BoxTree& a, const BoxTree& b, double reach, const Visit& visit)
      : a_(a), b_(b), reach_(reach), visit_(visit) {}

  /// Pairs (i of a, j of b). Returns false if visit stopped the search.
  bool between() {
    if (!a_.empty() && !b_.empty()) cross(0, 0);
    return !stopped_.load();
  }

  /// Pairs of distinct primitives of a (constructed with b = a), each once in either order.
  bool within() {
    if (!a_.empty()) self(0);
    return !stopped_.load();
  }

 private:
  static constexpr int kParallelPrimitives = 4096;

  template <class... Tasks>
  static void run(int primitives, const Tasks&... tasks) {
    if (primitives > kParallelPrimitives) {
      tbb::parallel_invoke(tasks...);
    } else {
      (tasks(), ...);
    }
  }

  [[nodiscard]] bool stopped() const { return stopped_.load(std::memory_order_relaxed); }

  void test(int k, int l) {
    if (within_reach(a_.sorted_box(k), b_.sorted_box(l), reach_) &&
        !visit_(a_.sorted_id(k), b_.sorted_id(l)))
      stopped_.store(true, std::memory_order_relaxed);
  }

  void self(int index) {
    if (stopped()) return;
    const BoxTree::Node& node = a_.node(index);
    if (BoxTree::is_leaf(node)) {
      for (int k = node.first; k < node.first + node.count; ++k)
        for (int l = k + 1; l < node.first + node.count; ++l) test(k, l);
      return;
    }
    const int left = index + 1, right = node.right;
    run(
        node.count, [&] { self(left); }, [&] { self(right); }, [&] { cross(left, right); });
  }

  void cross(int ia, int ib) {
    if (stopped()) return;
    const BoxTree::Node& na = a_.node(ia);
    const BoxTree::Node& nb = b_.node(ib);
    if (!within_reach(na.box, nb.box, reach_)) return;
    const bool a_leaf = BoxTree::is_leaf(na), b_leaf = BoxTree::is_leaf(nb);
    if (a_leaf && b_leaf) {
      for (int k = na.first; k < na.first + na.count; ++k)
        for (int l = nb.first; l < nb.first + nb.count; ++l) test(k, l);
      return;
    }
    const int primitives = na.count + nb.count;
    if (b_leaf || (!a_leaf && na.count >= nb.count)) {
      run(
          primitives, [&] { cross(ia + 1, ib); }, [&] { cross(na.right, ib); });
    } else {
      run(
          primitives, [&] { cross(ia, ib + 1); }, [&] { cross(ia, nb.right); });
    }
  }

  const BoxTree& a_;
  const BoxTree& b_;
  double reach_;
  const Visit& visit_;
  std::atomic<bool> stopped_{false};
};

/// Every thread's pairs of `found` in one sorted list.
template <class Pair>
std::vector<Pair> gathered_sorted(tbb::enumerable_thread_specific<std::vector<Pair>>& found) {
  std::size_t total = 0;
  for (const auto& part : found) total += part.size();
  std::vector<Pair> out;
  out.reserve(total);
  for (const auto& part : found) out.insert(out.end(), part.begin(), part.end());
  tbb::parallel_sort(out.begin(), out.end());
  return out;
}

void check_finite(const Positions& x, const char* name) {
  if (x.allFinite()) return;
  for (int v = 0; v < x.rows(); ++v)
    if (!x.row(v).allFinite())
      throw NumericalError(
          fmt::format("contact broad phase: vertex {} of {} is not finite ({}, {}, {})", v, name,
                      x(v, 0), x(v, 1), x(v, 2)));
}

Vector3 position(const Positions& x, int v) { return x.row(v).transpose(); }

/// The largest relative displacement between a vertex of one element and one of the other:
/// a bound on how much their distance can shrink along a linear motion.
template <std::size_t A, std::size_t B>
double relative_motion(const Positions& u, const std::array<int, A>& first,
                       const std::array<int, B>& second) {
  double largest = 0;
  for (int i : first)
    for (int j : second) largest = std::max(largest, (u.row(i) - u.row(j)).norm());
  return largest;
}

bool shares_vertex(const std::array<int, 2>& e, const std::array<int, 2>& f) {
  return e[0] == f[0] || e[0] == f[1] || e[1] == f[0] || e[1] == f[1];
}

}  // namespace

/// Boxes of every vertex (a point, or the segment it sweeps), edge and triangle.
struct BroadPhase::ElementBoxes {
  std::vector<Box> vertex, edge, triangle;

  ElementBoxes(std::vector<Box> vertex_boxes, const BroadPhase& surface)
      : vertex(std::move(vertex_boxes)),
        edge(surface.edges_.size()),
        triangle(surface.triangles_.rows()) {
    tbb::parallel_for(0, static_cast<int>(edge.size()), [&](int e) {
      edge[e] = vertex[surface.edges_[e][0]].merged(vertex[surface.edges_[e][1]]);
    });
    tbb::parallel_for(0, static_cast<int>(triangle.size()), [&](int t) {
      triangle[t] = vertex[surface.triangles_(t, 0)]
                        .merged(vertex[surface.triangles_(t, 1)])
                        .merged(vertex[surface.triangles_(t, 2)]);
    });
  }

  static ElementBoxes at(const Positions& x, const BroadPhase& surface) {
    std::vector<Box> boxes(x.rows());
    tbb::parallel_for(0, static_cast<int>(x.rows()),
                      [&](int v) { boxes[v] = Box(position(x, v), position(x, v)); });
    return {std::move(boxes), surface};
  }

  static ElementBoxes swept(const Positions& x0, const Positions& x1, const BroadPhase& surface) {
    std::vector<Box> boxes(x0.rows());
    tbb::parallel_for(0, static_cast<int>(x0.rows()), [&](int v) {
      boxes[v] =
          Box(position(x0, v).cwiseMin(position(x1, v)), position(x0, v).cwiseMax(position(x1, v)));
    });
    return {std::move(boxes), surface};
  }
};

BroadPhase::BroadPhase(Triangles triangles, std::vector<std::array<int, 2>> edges,
                       std::vector<int> vertex_body, const BodyPairRule& may_touch)
    : triangles_(std::move(triangles)),
      edges_(std::move(edges)),
      vertex_body_(std::move(vertex_body)) {
  const int n = static_cast<int>(vertex_body_.size());
  const auto check_index = [n](int v, const char* where) {
    if (v < 0 || v >= n)
      throw std::invalid_argument(
          fmt::format("BroadPhase: {} refers to vertex {} of {}", where, v, n));
  };
  for (int k = 0; k < triangles_.size(); ++k) check_index(triangles_.data()[k], "a triangle");
  for (const auto& e : edges_) {
    check_index(e[0], "an edge");
    check_index(e[1], "an edge");
  }
  for (int b : vertex_body_) {
    if (b < 0) throw std::invalid_argument(fmt::format("BroadPhase: negative body id {}", b));
    body_count_ = std::max(body_count_, b + 1);
  }
  bodies_.resize(body_count_);
  for (int v = 0; v < n; ++v) bodies_[vertex_body_[v]].vertices.push_back(v);
  for (int e = 0; e < static_cast<int>(edges_.size()); ++e)
    bodies_[vertex_body_[edges_[e][0]]].edges.push_back(e);
  for (int t = 0; t < triangles_.rows(); ++t)
    bodies_[vertex_body_[triangles_(t, 0)]].triangles.push_back(t);
  body_pair_allowed_.assign(std::size_t(body_count_) * body_count_, 1);
  if (!may_touch) return;
  for (int a = 0; a < body_count_; ++a)
    for (int b = 0; b < body_count_; ++b) body_pair_allowed_[a * body_count_ + b] = may_touch(a, b);
}

bool BroadPhase::bodies_may_touch(int vertex_a, int vertex_b) const {
  return body_pair_allowed_[vertex_body_[vertex_a] * body_count_ + vertex_body_[vertex_b]] != 0;
}

void BroadPhase::check_vertex_count(const Positions& x) const {
  if (x.rows() != static_cast<Eigen::Index>(vertex_body_.size()))
    throw std::invalid_argument(fmt::format("BroadPhase: {} positions for a surface of {} vertices",
                                            x.rows(), vertex_body_.size()));
}

bool BroadPhase::is_point_triangle_pair(int v, int t) const {
  const auto tri = triangles_.row(t);
  return tri[0] != v && tri[1] != v && tri[2] != v && bodies_may_touch(v, tri[0]);
}

bool BroadPhase::is_edge_edge_pair(int e, int f) const {
  return !shares_vertex(edges_[e], edges_[f]) && bodies_may_touch(edges_[e][0], edges_[f][0]);
}

/// The vertex, edge and triangle trees of each body for one query, built side by side.
struct BroadPhase::Trees {
  std::vector<BoxTree> vertex, edge, triangle;

  Trees(const ElementBoxes& boxes, const std::vector<BodyElements>& bodies) {
    const auto subset = [](const std::vector<Box>& all, const std::vector<int>& ids) {
      std::vector<Box> part(ids.size());
      for (std::size_t k = 0; k < ids.size(); ++k) part[k] = all[ids[k]];
      return part;
    };
    const int body_count = static_cast<int>(bodies.size());
    std::vector<std::optional<BoxTree>> built(3 * std::size_t(body_count));
    tbb::parallel_for(0, 3 * body_count, [&](int task) {
      const BodyElements& body = bodies[task / 3];
      switch (task % 3) {
        case 0: built[task].emplace(subset(boxes.vertex, body.vertices)); break;
        case 1: built[task].emplace(subset(boxes.edge, body.edges)); break;
        default: built[task].emplace(subset(boxes.triangle, body.triangles)); break;
      }
    });
    for (int b = 0; b < body_count; ++b) {
      vertex.push_back(std::move(*built[3 * b]));
      edge.push_back(std::move(*built[3 * b + 1]));
      triangle.push_back(std::move(*built[3 * b + 2]));
    }
  }
};

template <class Visit>
bool BroadPhase::search_point_triangle(const Trees& trees, double reach,
                                       const Visit& visit) const {
  for (int a = 0; a < body_count_; ++a)
    for (int b = 0; b < body_count_; ++b) {
      if (!body_pair_allowed_[a * body_count_ + b]) continue;
      const std::vector<int>& vertices = bodies_[a].vertices;
      const std::vector<int>& triangles = bodies_[b].triangles;
      const auto in_surface = [&](int v, int t) { return visit(vertices[v], triangles[t]); };
      OverlapSearch search(trees.vertex[a], trees.triangle[b], reach, in_surface);
      if (!search.between()) return false;
    }
  return true;
}

template <class Visit>
bool BroadPhase::search_edge_edge(const Trees& trees, double reach, const Visit& visit) const {
  for (int a = 0; a < body_count_; ++a)
    for (int b = a; b < body_count_; ++b) {
      if (!body_pair_allowed_[a * body_count_ + b]) continue;
      const std::vector<int>& first = bodies_[a].edges;
      const std::vector<int>& second = bodies_[b].edges;
      const auto in_surface = [&](int e, int f) { return visit(first[e], second[f]); };
      OverlapSearch search(trees.edge[a], trees.edge[b], reach, in_surface);
      if (!(a == b ? search.within() : search.between())) return false;
    }
  return true;
}

ContactCandidates BroadPhase::candidates(const ElementBoxes& boxes, double reach) const {
  const Trees trees(boxes, bodies_);
  tbb::enumerable_thread_specific<std::vector<PointTriangleCandidate>> point_triangle;
  tbb::enumerable_thread_specific<std::vector<EdgeEdgeCandidate>> edge_edge;
  search_point_triangle(trees, reach, [&](int v, int t) {
    if (is_point_triangle_pair(v, t)) point_triangle.local().push_back({v, t});
    return true;
  });
  search_edge_edge(trees, reach, [&](int e, int f) {
    if (is_edge_edge_pair(e, f)) edge_edge.local().push_back({std::min(e, f), std::max(e, f)});
    return true;
  });
  return {gathered_sorted(point_triangle), gathered_sorted(edge_edge)};
}

/// `near` has point_triangle(v, t) and edge_edge(e, f), the exact tests of a box candidate.
template <class Near>
bool BroadPhase::any_pair(const ElementBoxes& boxes, double reach, const Near& near) const {
  const Trees trees(boxes, bodies_);
  return !search_point_triangle(trees, reach,
                                [&](int v, int t) {
                                  return !(is_point_triangle_pair(v, t) &&
                                           near.point_triangle(v, t));
                                }) ||
         !search_edge_edge(trees, reach, [&](int e, int f) {
           return !(is_edge_edge_pair(e, f) && near.edge_edge(e, f));
         });
}

ContactCandidates BroadPhase::distance_candidates(const Positions& x, double reach) const {
  check_vertex_count(x);
  check_finite(x, "x");
  return candidates(ElementBoxes::at(x, *this), reach);
}

ContactCandidates BroadPhase::swept_candidates(const Positions& x0, const Positions& x1,
                                               double reach) const {
  check_vertex_count(x0);
  check_vertex_count(x1);
  check_finite(x0, "x0");
  check_finite(x1, "x1");
  return candidates(ElementBoxes::swept(x0, x1, *this), reach);
}

namespace {

/// Unsigned distances of box candidates at one state (square roots of the squared contact
/// distances). A NaN distance counts as near in the tests below: an early-out must never hide
/// a pair.
struct DistanceAt {
  const Positions& x;
  const Triangles& triangles;
  const std::vector<std::array<int, 2>>& edges;

  double point_triangle(int v, int t) const {
    return std::sqrt(point_triangle_distance(position(x, v), position(x, triangles(t, 0)),
                                             position(x, triangles(t, 1)),
                                             position(x, triangles(t, 2))));
  }
  double edge_edge(int e, int f) const {
    return std::sqrt(edge_edge_distance(position(x, edges[e][0]), position(x, edges[e][1]),
                                        position(x, edges[f][0]), position(x, edges[f][1])));
  }
};

/// The near test of a clearance query: keeps each thread's smallest candidate distance (a NaN
/// one as 0) and calls a pair near when it is within `floor`, which ends the search.
struct ClearanceAt {
  DistanceAt at;
  double floor;
  tbb::enumerable_thread_specific<double>& smallest;

  bool record(double distance) const {
    const double d = std::isnan(distance) ? 0.0 : distance;
    double& local = smallest.local();
    local = std::min(local, d);
    return d <= floor;
  }
  bool point_triangle(int v, int t) const { return record(at.point_triangle(v, t)); }
  bool edge_edge(int e, int f) const { return record(at.edge_edge(e, f)); }
};

struct NearDuring {
  DistanceAt start, end;
  const Positions& displacement;
  double reach;

  bool point_triangle(int v, int t) const {
    const std::array<int, 3> tri{start.triangles(t, 0), start.triangles(t, 1),
                                 start.triangles(t, 2)};
    const double distance = std::max(start.point_triangle(v, t), end.point_triangle(v, t));
    return !(distance - relative_motion(displacement, std::array{v}, tri) > reach);
  }
  bool edge_edge(int e, int f) const {
    const double distance = std::max(start.edge_edge(e, f), end.edge_edge(e, f));
    return !(distance - relative_motion(displacement, start.edges[e], start.edges[f]) > reach);
  }
};

}  // namespace

double BroadPhase::clearance(const Positions& x, double floor, double cap) const {
  check_vertex_count(x);
  check_finite(x, "x");
  tbb::enumerable_thread_specific<double> smallest(cap);
  // A pair within the floor, when one ends the search, is in `smallest` already.
  static_cast<void>(any_pair(ElementBoxes::at(x, *this), cap,
                             ClearanceAt{{x, triangles_, edges_}, floor, smallest}));
  return smallest.combine([](double a, double b) { return std::min(a, b); });
}

bool BroadPhase::any_within_reach_during(const Positions& x0, const Positions& x1,
                                         double reach) const {
  check_vertex_count(x0);
  check_vertex_count(x1);
  check_finite(x0, "x0");
  check_finite(x1, "x1");
  const Positions displacement = x1 - x0;
  const NearDuring near{{x0, triangles_, edges_}, {x1, triangles_, edges_}, displacement, reach};
  return any_pair(ElementBoxes::swept(x0, x1, *this), reach, near);
}

std::vector<std::array<int, 2>> overlapping_triangle_boxes(const Positions& x,
                                                           const Triangles& triangles) {
  check_finite(x, "the mesh");
  std::vector<Box> boxes(triangles.rows());
  tbb::parallel_for(0, static_cast<int>(triangles.rows()), [&](int t) {
    boxes[t].setEmpty();
    for (int k = 0; k < 3; ++k) boxes[t].extend(position(x, triangles(t, k)));
  });
  tbb::enumerable_thread_specific<std::vector<std::array<int, 2>>> found;
  const BoxTree tree(boxes);
  const auto keep = [&](int s, int t) {
    found.local().push_back({std::min(s, t), std::max(s, t)});
    return true;
  };
  OverlapSearch(tree, tree, 0.0, keep).within();
  return gathered_sorted(found);
}

}  // namespace psq
