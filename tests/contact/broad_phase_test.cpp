// Broad phase against brute force: every pair of elements tested with its own box
// arithmetic, and the early-outs against distances computed here by a different method.

#include "engine/contact/broad_phase.hpp"

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <limits>
#include <random>
#include <set>

#include "engine/core/error.hpp"
#include "engine/mesh/generators.hpp"
#include "engine/mesh/topology.hpp"

namespace psq {
namespace {

using Vector3 = Eigen::Vector3d;
using Edges = std::vector<std::array<int, 2>>;

/// A contact surface as the simulator builds it: meshes concatenated, one body per mesh.
struct Surface {
  Positions x;
  Triangles triangles;
  Edges edges;
  std::vector<int> body;
};

void append(Surface& s, const TriMesh& mesh, int body) {
  const int offset = static_cast<int>(s.x.rows());
  s.x.conservativeResize(offset + mesh.vertex_count(), 3);
  s.x.bottomRows(mesh.vertex_count()) = mesh.vertices;
  const int first_triangle = static_cast<int>(s.triangles.rows());
  s.triangles.conservativeResize(first_triangle + mesh.triangle_count(), 3);
  s.triangles.bottomRows(mesh.triangle_count()) = mesh.triangles.array() + offset;
  for (const auto& e : MeshTopology::build(mesh).edges)
    s.edges.push_back({e[0] + offset, e[1] + offset});
  s.body.insert(s.body.end(), mesh.vertex_count(), body);
}

/// Disconnected random triangles in the unit cube (each its own three vertices), two bodies.
Surface triangle_soup(int count, double size, std::mt19937& rng) {
  std::uniform_real_distribution<double> unit(0.0, 1.0), corner(-size, size);
  Surface s;
  for (int t = 0; t < count; ++t) {
    TriMesh tri;
    tri.vertices.resize(3, 3);
    const Vector3 centre(unit(rng), unit(rng), unit(rng));
    for (int k = 0; k < 3; ++k)
      tri.vertices.row(k) = (centre + Vector3(corner(rng), corner(rng), corner(rng))).transpose();
    tri.triangles.resize(1, 3);
    tri.triangles << 0, 1, 2;
    append(s, tri, t % 2);
  }
  return s;
}

/// Two crumpled sheets (random heights and in-plane jitter), the second 2 cm above the first.
Surface perturbed_sheets(std::mt19937& rng) {
  std::uniform_real_distribution<double> jitter(-0.004, 0.004), height(-0.015, 0.015);
  Surface s;
  for (int body = 0; body < 2; ++body) {
    SheetGenerator spec;
    spec.width = 0.3;
    spec.height = 0.2;
    spec.edge_length = 0.02;
    spec.structured = body == 0;
    TriMesh sheet = make_sheet(spec);
    for (int v = 0; v < sheet.vertex_count(); ++v)
      sheet.vertices.row(v) +=
          Eigen::RowVector3d(jitter(rng), jitter(rng), height(rng) + 0.02 * body);
    append(s, sheet, body);
  }
  return s;
}

Positions randomly_moved(const Positions& x, double by, std::mt19937& rng) {
  std::uniform_real_distribution<double> move(-by, by);
  Positions moved = x;
  for (int k = 0; k < moved.size(); ++k) moved.data()[k] += move(rng);
  return moved;
}

/// Per-axis bounds of the given vertices over the given states.
struct Bounds {
  Vector3 lo = Vector3::Constant(std::numeric_limits<double>::infinity());
  Vector3 hi = -lo;
  Bounds(const std::vector<const Positions*>& states, std::initializer_list<int> vertices) {
    for (const Positions* x : states)
      for (int v : vertices)
        for (int a = 0; a < 3; ++a) {
          lo[a] = std::min(lo[a], (*x)(v, a));
          hi[a] = std::max(hi[a], (*x)(v, a));
        }
  }
  /// The largest separation along an axis: a lower bound on the distance of what they bound.
  double gap_to(const Bounds& other) const {
    return std::max({0.0, (lo - other.hi).maxCoeff(), (other.lo - hi).maxCoeff()});
  }
  /// Whether the boxes are at most `gap` apart along every axis.
  bool within(const Bounds& other, double gap) const {
    for (int a = 0; a < 3; ++a)
      if (lo[a] > other.hi[a] + gap || other.lo[a] > hi[a] + gap) return false;
    return true;
  }
};

bool allowed(const BodyPairRule& rule, int a, int b) { return !rule || rule(a, b); }

/// All pairs by brute force: box test over `states` (one state: distance, two: swept).
ContactCandidates brute_force(const Surface& s, const std::vector<const Positions*>& states,
                              double reach, const BodyPairRule& rule) {
  ContactCandidates out;
  for (int v = 0; v < s.x.rows(); ++v)
    for (int t = 0; t < s.triangles.rows(); ++t) {
      const int a = s.triangles(t, 0), b = s.triangles(t, 1), c = s.triangles(t, 2);
      if (v == a || v == b || v == c || !allowed(rule, s.body[v], s.body[a])) continue;
      if (Bounds(states, {v}).within(Bounds(states, {a, b, c}), reach))
        out.point_triangle.push_back({v, t});
    }
  for (int e = 0; e < static_cast<int>(s.edges.size()); ++e)
    for (int f = e + 1; f < static_cast<int>(s.edges.size()); ++f) {
      const auto [a, b] = s.edges[e];
      const auto [c, d] = s.edges[f];
      if (a == c || a == d || b == c || b == d || !allowed(rule, s.body[a], s.body[c])) continue;
      if (Bounds(states, {a, b}).within(Bounds(states, {c, d}), reach))
        out.edge_edge.push_back({e, f});
    }
  return out;
}

BroadPhase broad_phase_of(const Surface& s, const BodyPairRule& rule = {}) {
  return BroadPhase(s.triangles, s.edges, s.body, rule);
}

void expect_same(const ContactCandidates& found, const ContactCandidates& expected) {
  EXPECT_EQ(found.point_triangle, expected.point_triangle);
  EXPECT_EQ(found.edge_edge, expected.edge_edge);
}

/// Closest distance from p to segment ab, by clamped projection.
double point_segment_distance(const Vector3& p, const Vector3& a, const Vector3& b) {
  const Vector3 ab = b - a;
  const double t =
      ab.squaredNorm() > 0 ? std::clamp((p - a).dot(ab) / ab.squaredNorm(), 0.0, 1.0) : 0.0;
  return (p - (a + t * ab)).norm();
}

/// Point–triangle distance: to the plane if the projection falls inside (barycentric
/// coordinates from areas), to the nearest edge otherwise.
double reference_point_triangle(const Vector3& p, const Vector3& a, const Vector3& b,
                                const Vector3& c) {
  const Vector3 n = (b - a).cross(c - a);
  const Vector3 q = p - n.dot(p - a) / n.squaredNorm() * n;
  const bool inside = (b - a).cross(q - a).dot(n) >= 0 && (c - b).cross(q - b).dot(n) >= 0 &&
                      (a - c).cross(q - c).dot(n) >= 0;
  if (inside) return (p - q).norm();
  return std::min({point_segment_distance(p, a, b), point_segment_distance(p, b, c),
                   point_segment_distance(p, c, a)});
}

/// Segment–segment distance: s ↦ dist(p(s), segment q) is convex, so a golden-section search
/// on s converges to the minimum.
double reference_segment_segment(const Vector3& p0, const Vector3& p1, const Vector3& q0,
                                 const Vector3& q1) {
  const auto at = [&](double s) { return point_segment_distance(p0 + s * (p1 - p0), q0, q1); };
  double lo = 0, hi = 1;
  const double ratio = (std::sqrt(5.0) - 1) / 2;
  for (int k = 0; k < 60; ++k) {
    const double m1 = hi - ratio * (hi - lo), m2 = lo + ratio * (hi - lo);
    if (at(m1) < at(m2))
      hi = m2;
    else
      lo = m1;
  }
  return std::min({at(0.5 * (lo + hi)), at(0.0), at(1.0)});
}

Vector3 row(const Positions& x, int v) { return x.row(v).transpose(); }

/// The smallest distance over every pair the broad phase may report (brute force).
double closest_pair_distance(const Surface& s, const Positions& x, const BodyPairRule& rule = {}) {
  double closest = std::numeric_limits<double>::infinity();
  const ContactCandidates all = brute_force(s, {&x}, std::numeric_limits<double>::infinity(), rule);
  for (const auto& [v, t] : all.point_triangle) {
    const int a = s.triangles(t, 0), b = s.triangles(t, 1), c = s.triangles(t, 2);
    if (Bounds({&x}, {v}).gap_to(Bounds({&x}, {a, b, c})) >= closest) continue;
    closest =
        std::min(closest, reference_point_triangle(row(x, v), row(x, a), row(x, b), row(x, c)));
  }
  for (const auto& [e, f] : all.edge_edge) {
    const auto [a, b] = s.edges[e];
    const auto [c, d] = s.edges[f];
    if (Bounds({&x}, {a, b}).gap_to(Bounds({&x}, {c, d})) >= closest) continue;
    closest =
        std::min(closest, reference_segment_segment(row(x, a), row(x, b), row(x, c), row(x, d)));
  }
  return closest;
}

TEST(BroadPhase, DistanceCandidatesMatchBruteForceOnTriangleSoups) {
  std::mt19937 rng(7);
  for (int trial = 0; trial < 3; ++trial) {
    const Surface s = triangle_soup(300, 0.06, rng);
    const BroadPhase broad = broad_phase_of(s);
    for (double reach : {0.0, 0.01, 0.05}) {
      SCOPED_TRACE(::testing::Message() << "trial " << trial << ", reach " << reach);
      const ContactCandidates found = broad.distance_candidates(s.x, reach);
      EXPECT_FALSE(found.empty());
      expect_same(found, brute_force(s, {&s.x}, reach, {}));
    }
  }
}

TEST(BroadPhase, SweptCandidatesMatchBruteForceOnTriangleSoups) {
  std::mt19937 rng(11);
  for (int trial = 0; trial < 3; ++trial) {
    const Surface s = triangle_soup(300, 0.06, rng);
    const Positions x1 = randomly_moved(s.x, 0.05, rng);
    const BroadPhase broad = broad_phase_of(s);
    for (double reach : {0.0, 0.01, 0.05}) {
      SCOPED_TRACE(::testing::Message() << "trial " << trial << ", reach " << reach);
      expect_same(broad.swept_candidates(s.x, x1, reach), brute_force(s, {&s.x, &x1}, reach, {}));
    }
  }
}

TEST(BroadPhase, BothQueriesMatchBruteForceOnPerturbedSheets) {
  std::mt19937 rng(3);
  const Surface s = perturbed_sheets(rng);
  const Positions x1 = randomly_moved(s.x, 0.01, rng);
  const BroadPhase broad = broad_phase_of(s);
  for (double reach : {0.0, 0.002, 0.02}) {
    SCOPED_TRACE(::testing::Message() << "reach " << reach);
    expect_same(broad.distance_candidates(s.x, reach), brute_force(s, {&s.x}, reach, {}));
    expect_same(broad.swept_candidates(s.x, x1, reach), brute_force(s, {&s.x, &x1}, reach, {}));
  }
}

TEST(BroadPhase, BodyPairRuleFiltersPairs) {
  std::mt19937 rng(5);
  const Surface s = perturbed_sheets(rng);
  // Body 1 touches body 0 but not itself (a rigid collider, say).
  const BodyPairRule no_self_contact_for_1 = [](int a, int b) { return !(a == 1 && b == 1); };
  const BroadPhase broad = broad_phase_of(s, no_self_contact_for_1);
  const ContactCandidates found = broad.distance_candidates(s.x, 0.02);
  expect_same(found, brute_force(s, {&s.x}, 0.02, no_self_contact_for_1));
  for (const auto& [v, t] : found.point_triangle)
    EXPECT_FALSE(s.body[v] == 1 && s.body[s.triangles(t, 0)] == 1);
  // Pairs between the sheets and within sheet 0 remain: the rule removed only what it says.
  const auto body_of_triangle = [&](int t) { return s.body[s.triangles(t, 0)]; };
  EXPECT_TRUE(
      std::any_of(found.point_triangle.begin(), found.point_triangle.end(),
                  [&](const auto& c) { return s.body[c.vertex] != body_of_triangle(c.triangle); }));
  EXPECT_TRUE(std::any_of(
      found.point_triangle.begin(), found.point_triangle.end(),
      [&](const auto& c) { return s.body[c.vertex] == 0 && body_of_triangle(c.triangle) == 0; }));
}

TEST(BroadPhase, BodiesThatTouchOnlyEachOtherGiveOnlyTheirCrossPairsInEveryQuery) {
  std::mt19937 rng(29);
  const Surface s = perturbed_sheets(rng);
  const Positions x1 = randomly_moved(s.x, 0.01, rng);
  // Two colliders, say: each body is searched only against the other.
  const BodyPairRule only_across = [](int a, int b) { return a != b; };
  const BroadPhase broad = broad_phase_of(s, only_across);
  for (double reach : {0.002, 0.02}) {
    SCOPED_TRACE(::testing::Message() << "reach " << reach);
    const ContactCandidates found = broad.distance_candidates(s.x, reach);
    EXPECT_FALSE(found.empty());
    expect_same(found, brute_force(s, {&s.x}, reach, only_across));
    expect_same(broad.swept_candidates(s.x, x1, reach),
                brute_force(s, {&s.x, &x1}, reach, only_across));
  }
  const double closest = closest_pair_distance(s, s.x, only_across);
  ASSERT_GT(closest, 0.0);
  ASSERT_LT(closest, 1.0);
  EXPECT_NEAR(broad.clearance(s.x, 0.0, 10 * closest), closest, 1e-9 * closest);
  EXPECT_FALSE(broad.any_within_reach_during(s.x, s.x, 0.99 * closest));
  EXPECT_TRUE(broad.any_within_reach_during(s.x, s.x, 1.01 * closest));
}

TEST(BroadPhase, NoPairSharesAVertexAndListsAreStrictlySorted) {
  std::mt19937 rng(13);
  const Surface s = perturbed_sheets(rng);
  const ContactCandidates found = broad_phase_of(s).distance_candidates(s.x, 0.03);
  ASSERT_FALSE(found.point_triangle.empty());
  ASSERT_FALSE(found.edge_edge.empty());
  for (const auto& [v, t] : found.point_triangle)
    EXPECT_TRUE(v != s.triangles(t, 0) && v != s.triangles(t, 1) && v != s.triangles(t, 2))
        << v << " " << t;
  for (const auto& [e, f] : found.edge_edge) {
    EXPECT_LT(e, f);
    const std::set<int> corners{s.edges[e][0], s.edges[e][1], s.edges[f][0], s.edges[f][1]};
    EXPECT_EQ(corners.size(), 4u) << e << " " << f;
  }
  EXPECT_TRUE(std::adjacent_find(found.point_triangle.begin(), found.point_triangle.end(),
                                 std::greater_equal<>()) == found.point_triangle.end());
  EXPECT_TRUE(std::adjacent_find(found.edge_edge.begin(), found.edge_edge.end(),
                                 std::greater_equal<>()) == found.edge_edge.end());
}

TEST(BroadPhase, OutputDoesNotDependOnTheThreadCount) {
  std::mt19937 rng(17);
  const Surface s = perturbed_sheets(rng);
  const Positions x1 = randomly_moved(s.x, 0.01, rng);
  const BroadPhase broad = broad_phase_of(s);
  const ContactCandidates parallel = broad.swept_candidates(s.x, x1, 0.01);
  const tbb::global_control one_thread(tbb::global_control::max_allowed_parallelism, 1);
  expect_same(broad.swept_candidates(s.x, x1, 0.01), parallel);
}

TEST(BroadPhase, EarlyOutAgreesWithTheClosestPairDistance) {
  std::mt19937 rng(19);
  std::vector<Surface> surfaces{triangle_soup(100, 0.01, rng), triangle_soup(100, 0.01, rng),
                                perturbed_sheets(rng)};
  for (const Surface& s : surfaces) {
    const double closest = closest_pair_distance(s, s.x);
    ASSERT_GT(closest, 0.0);
    const BroadPhase broad = broad_phase_of(s);
    // "Any pair within r": a clearance with floor r below its cap is at most r.
    EXPECT_GT(broad.clearance(s.x, 0.99 * closest, 2 * closest), 0.99 * closest) << closest;
    EXPECT_LE(broad.clearance(s.x, 1.01 * closest, 2 * closest), 1.01 * closest) << closest;
    // A motion that does not move anything is the state itself.
    EXPECT_FALSE(broad.any_within_reach_during(s.x, s.x, 0.99 * closest)) << closest;
    EXPECT_TRUE(broad.any_within_reach_during(s.x, s.x, 1.01 * closest)) << closest;
  }
}

TEST(BroadPhase, ClearanceIsTheClosestPairDistanceUpToItsCap) {
  std::mt19937 rng(23);
  std::vector<Surface> surfaces{triangle_soup(100, 0.01, rng), perturbed_sheets(rng)};
  for (const Surface& s : surfaces) {
    const double closest = closest_pair_distance(s, s.x);
    ASSERT_GT(closest, 0.0);
    const BroadPhase broad = broad_phase_of(s);
    EXPECT_NEAR(broad.clearance(s.x, 0.0, 10 * closest), closest, 1e-9 * closest);
    EXPECT_NEAR(broad.clearance(s.x, 0.99 * closest, 1.01 * closest), closest, 1e-9 * closest);
    EXPECT_EQ(broad.clearance(s.x, 0.0, 0.99 * closest), 0.99 * closest);
    // A pair within the floor ends the search: the answer only says that one is that near.
    EXPECT_LE(broad.clearance(s.x, 2 * closest, 10 * closest), 2 * closest);
  }
}

TEST(BroadPhase, FlatSheetNeighboursHaveBoxesInReachButNoDistance) {
  SheetGenerator spec;
  spec.edge_length = 0.05;
  spec.structured = true;
  Surface s;
  append(s, make_sheet(spec), 0);
  const BroadPhase broad = broad_phase_of(s);
  // Across a square's diagonal, a corner lies in the box of the triangle opposite it.
  EXPECT_FALSE(broad.distance_candidates(s.x, 0.005).empty());
  EXPECT_GT(broad.clearance(s.x, 0.005, 0.01), 0.005);
  // A vertex lies 0.05/√2 from the diagonal of its square that avoids it.
  const double across = 0.05 / std::sqrt(2.0);
  EXPECT_GT(broad.clearance(s.x, 0.99 * across, 2 * across), 0.99 * across);
  EXPECT_LE(broad.clearance(s.x, 1.01 * across, 2 * across), 1.01 * across);
}

TEST(BroadPhase, RigidMotionFarFromContactNeedsNoCcd) {
  SheetGenerator spec;
  spec.edge_length = 0.05;  // no two elements of a sheet closer than 0.05/√2 ≈ 0.035
  spec.structured = true;
  Surface s;
  append(s, make_sheet(spec), 0);
  TriMesh upper = make_sheet(spec);
  upper.vertices.col(2).array() += 0.1;
  append(s, upper, 1);
  Positions moved = s.x;
  moved.col(0).array() += 10.0;
  const BroadPhase broad = broad_phase_of(s);
  EXPECT_FALSE(broad.swept_candidates(s.x, moved, 0.01).empty());
  EXPECT_FALSE(broad.any_within_reach_during(s.x, moved, 0.01));
  // Lowering the upper sheet through the lower one passes every pair across.
  Positions lowered = s.x;
  lowered.bottomRows(upper.vertex_count()).col(2).array() -= 0.2;
  EXPECT_TRUE(broad.any_within_reach_during(s.x, lowered, 0.01));
  // Lowering it to 2.5 cm above: the bound 0.1 − 0.075 is within a reach of 0.03, not 0.02.
  lowered.bottomRows(upper.vertex_count()).col(2).array() += 0.125;
  EXPECT_TRUE(broad.any_within_reach_during(s.x, lowered, 0.03));
  EXPECT_FALSE(broad.any_within_reach_during(s.x, lowered, 0.02));
}

TEST(BroadPhase, SweptEarlyOutNeverHidesAPairThatComesWithinReach) {
  std::mt19937 rng(23);
  int ruled_out = 0, kept = 0;
  for (int trial = 0; trial < 6; ++trial) {
    const Surface s = triangle_soup(60, 0.02, rng);
    const Positions x1 = randomly_moved(s.x, 0.03, rng);
    double closest_on_the_way = std::numeric_limits<double>::infinity();
    for (int k = 0; k <= 20; ++k) {
      const Positions xt = s.x + (k / 20.0) * (x1 - s.x);
      closest_on_the_way = std::min(closest_on_the_way, closest_pair_distance(s, xt));
    }
    const BroadPhase broad = broad_phase_of(s);
    for (double reach : {0.001, 0.01, 0.03}) {
      if (broad.any_within_reach_during(s.x, x1, reach)) {
        ++kept;
      } else {
        ++ruled_out;
        EXPECT_GT(closest_on_the_way, reach) << "trial " << trial;
      }
    }
  }
  // Both answers occurred, so both branches were tested.
  EXPECT_GT(ruled_out, 0);
  EXPECT_GT(kept, 0);
}

TEST(BroadPhase, OverlappingTriangleBoxesMatchBruteForceNeighboursIncluded) {
  std::mt19937 rng(29);
  const Surface s = perturbed_sheets(rng);
  std::vector<std::array<int, 2>> expected;
  for (int t = 0; t < s.triangles.rows(); ++t)
    for (int u = t + 1; u < s.triangles.rows(); ++u) {
      const auto tri = s.triangles.row(t);
      const auto other = s.triangles.row(u);
      if (Bounds({&s.x}, {tri[0], tri[1], tri[2]})
              .within(Bounds({&s.x}, {other[0], other[1], other[2]}), 0.0))
        expected.push_back({t, u});
    }
  EXPECT_EQ(overlapping_triangle_boxes(s.x, s.triangles), expected);
}

TEST(BroadPhase, NonFinitePositionIsANumericalError) {
  std::mt19937 rng(31);
  Surface s = triangle_soup(10, 0.05, rng);
  const BroadPhase broad = broad_phase_of(s);
  Positions bad = s.x;
  bad(4, 1) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW((void)broad.distance_candidates(bad, 0.01), NumericalError);
  EXPECT_THROW((void)broad.swept_candidates(s.x, bad, 0.01), NumericalError);
  EXPECT_THROW((void)broad.clearance(bad, 0.01, 0.1), NumericalError);
  EXPECT_THROW((void)overlapping_triangle_boxes(bad, s.triangles), NumericalError);
}

TEST(BroadPhase, ConnectivityOutOfRangeIsRejected) {
  Triangles triangles(1, 3);
  triangles << 0, 1, 3;
  EXPECT_THROW(BroadPhase(triangles, {{0, 1}}, {0, 0, 0}), std::invalid_argument);
  triangles << 0, 1, 2;
  EXPECT_THROW(BroadPhase(triangles, {{0, 1}}, {0, 0, -1}), std::invalid_argument);
  const BroadPhase broad(triangles, {{0, 1}}, {0, 0, 0});
  EXPECT_THROW((void)broad.distance_candidates(Positions::Zero(4, 3), 0.1), std::invalid_argument);
}

}  // namespace
}  // namespace psq
