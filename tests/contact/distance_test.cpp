#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <random>

#include "engine/contact/distance_type.hpp"
#include "engine/contact/edge_edge_distance.hpp"
#include "engine/contact/point_edge_distance.hpp"
#include "engine/contact/point_triangle_distance.hpp"
#include "support/derivative_check.hpp"
#include "support/random_geometry.hpp"

namespace psq {
namespace {

using Eigen::Vector3d;
using Eigen::VectorXd;

using Stencil = std::array<Vector3d, 4>;

VectorXd flatten(const Stencil& x) {
  VectorXd v(12);
  for (int i = 0; i < 4; ++i) v.segment<3>(3 * i) = x[i];
  return v;
}

Stencil unflatten(const VectorXd& v) {
  return {v.segment<3>(0), v.segment<3>(3), v.segment<3>(6), v.segment<3>(9)};
}

// ---- the functions under test, on flat 12-vectors -------------------------------------------

double pt_distance(const Stencil& x) { return point_triangle_distance(x[0], x[1], x[2], x[3]); }
StencilDerivatives<12> pt_derivatives(const Stencil& x) {
  return point_triangle_distance_derivatives(x[0], x[1], x[2], x[3]);
}
PointTriangleCase pt_case(const Stencil& x) { return point_triangle_case(x[0], x[1], x[2], x[3]); }

double ee_distance(const Stencil& x) { return edge_edge_distance(x[0], x[1], x[2], x[3]); }
StencilDerivatives<12> ee_derivatives(const Stencil& x) {
  return edge_edge_distance_derivatives(x[0], x[1], x[2], x[3]);
}
EdgeEdgeCase ee_case(const Stencil& x) { return edge_edge_case(x[0], x[1], x[2], x[3]); }

/// Central differences of the value against the gradient and of the gradient against the
/// Hessian, for a stencil function of any size.
template <int Dofs>
void expect_derivatives_match_finite_differences(
    const std::function<StencilDerivatives<Dofs>(const VectorXd&)>& f, const VectorXd& x, double h,
    double tolerance) {
  const test::DerivativeErrors errors = test::derivative_errors(f, x, h);
  EXPECT_LT(errors.gradient, tolerance) << "gradient at " << x.transpose();
  EXPECT_LT(errors.hessian, tolerance) << "Hessian at " << x.transpose();
  const StencilDerivatives<Dofs> at_x = f(x);
  EXPECT_LT((at_x.hessian - at_x.hessian.transpose()).norm(), 1e-12 * at_x.hessian.norm());
}

void expect_stencil_derivatives_match(
    const std::function<StencilDerivatives<12>(const Stencil&)>& f, const Stencil& x,
    double h = 1e-6, double tolerance = 1e-6) {
  expect_derivatives_match_finite_differences<12>(
      [&](const VectorXd& v) { return f(unflatten(v)); }, flatten(x), h, tolerance);
}

// ---- independent reference: brute-force search over the closest-point parameters ----------

/// Minimum of f over the unit square (or, with `simplex`, over a + b ≤ 1), by repeatedly
/// sampling a 21 × 21 grid around the best sample and halving the window. Points outside the
/// simplex are pulled back onto its hypotenuse, so the boundary is sampled too.
double brute_force_minimum(const std::function<double(double, double)>& f, bool simplex) {
  double best = std::numeric_limits<double>::infinity();
  double center_a = 0.5, center_b = 0.5, half_width = 0.5;
  for (int round = 0; round < 60; ++round) {
    double best_a = center_a, best_b = center_b;
    for (int i = 0; i <= 20; ++i) {
      for (int j = 0; j <= 20; ++j) {
        double a = std::clamp(center_a + half_width * (i / 10.0 - 1), 0.0, 1.0);
        double b = std::clamp(center_b + half_width * (j / 10.0 - 1), 0.0, 1.0);
        if (simplex && a + b > 1) {
          const double sum = a + b;
          a /= sum;
          b /= sum;
        }
        const double value = f(a, b);
        if (value < best) {
          best = value;
          best_a = a;
          best_b = b;
        }
      }
    }
    center_a = best_a;
    center_b = best_b;
    half_width /= 2;
  }
  return best;
}

double brute_force_point_triangle(const Stencil& x) {
  return brute_force_minimum(
      [&](double b1, double b2) {
        return (x[0] - (x[1] + b1 * (x[2] - x[1]) + b2 * (x[3] - x[1]))).squaredNorm();
      },
      true);
}

double brute_force_edge_edge(const Stencil& x) {
  return brute_force_minimum(
      [&](double s, double t) {
        return ((x[0] + s * (x[1] - x[0])) - (x[2] + t * (x[3] - x[2]))).squaredNorm();
      },
      false);
}

// ---- constructions whose closest features and distance are known --------------------------

struct Rng {
  std::mt19937 engine;
  explicit Rng(unsigned seed) : engine(seed) {}
  double uniform(double lo, double hi) { return std::uniform_real_distribution<>(lo, hi)(engine); }
  Vector3d point() { return test::random_point(engine); }
  Vector3d unit() {
    for (;;) {
      const Vector3d v = point();
      if (v.norm() > 0.1 && v.norm() < 1) return v.normalized();
    }
  }
  /// A unit vector perpendicular to the unit vector a.
  Vector3d unit_perpendicular(const Vector3d& a) {
    for (;;) {
      const Vector3d v = point();
      const Vector3d perpendicular = v - v.dot(a) * a;
      if (perpendicular.norm() > 0.1) return perpendicular.normalized();
    }
  }
};

double sine_squared(const Vector3d& a, const Vector3d& b) {
  return a.cross(b).squaredNorm() / (a.squaredNorm() * b.squaredNorm());
}

/// A triangle with every angle's sine above 0.25, so no region is a sliver.
std::array<Vector3d, 3> random_triangle(Rng& rng) {
  for (;;) {
    const std::array<Vector3d, 3> t{rng.point(), rng.point(), rng.point()};
    bool good = true;
    for (int i = 0; i < 3; ++i)
      good = good && sine_squared(t[(i + 1) % 3] - t[i], t[(i + 2) % 3] - t[i]) > 0.0625;
    if (good) return t;
  }
}

/// A stencil with its squared distance, known by construction.
struct KnownPair {
  Stencil x;
  double distance;  ///< squared
};

/// A random triangle and a point at distance δ from a foot point on the feature of case c,
/// along a direction in that feature's normal cone (so the foot is the closest point).
KnownPair point_triangle_with_case(PointTriangleCase c, Rng& rng) {
  const std::array<Vector3d, 3> t = random_triangle(rng);
  const Vector3d n = (t[1] - t[0]).cross(t[2] - t[0]).normalized();
  const double delta = rng.uniform(0.05, 0.5);
  const double tilt = rng.uniform(-1.2, 1.2);  // out of the plane, for edges and vertices
  Vector3d foot, direction;
  const int index = static_cast<int>(c);
  if (c == PointTriangleCase::Face) {
    const double b1 = rng.uniform(0.1, 0.8), b2 = rng.uniform(0.1, 0.9 - b1);
    foot = t[0] + b1 * (t[1] - t[0]) + b2 * (t[2] - t[0]);
    direction = rng.uniform(0, 1) < 0.5 ? n : Vector3d(-n);
  } else if (index < 3) {  // vertex i: against both of its edges
    const Vector3d& ti = t[index];
    const Vector3d a = (t[(index + 1) % 3] - ti).normalized();
    const Vector3d b = (t[(index + 2) % 3] - ti).normalized();
    foot = ti;
    direction = std::cos(tilt) * -(a + b).normalized() + std::sin(tilt) * n;
  } else {  // edge (ti, tj): outward in the plane, away from the opposite vertex
    const int i = index - 3, j = (i + 1) % 3, k = (i + 2) % 3;
    foot = t[i] + rng.uniform(0.2, 0.8) * (t[j] - t[i]);
    Vector3d outward = (t[j] - t[i]).cross(n).normalized();
    if (outward.dot(t[k] - t[i]) > 0) outward = -outward;
    direction = std::cos(tilt) * outward + std::sin(tilt) * n;
  }
  return {{foot + delta * direction, t[0], t[1], t[2]}, delta * delta};
}

/// Where the closest point of an edge lies: an endpoint or inside.
enum class Feature { End0, End1, Inside };

/// The edge–edge case named by the features of a and of b.
EdgeEdgeCase case_of(Feature a, Feature b) {
  using F = Feature;
  if (a == F::Inside && b == F::Inside) return EdgeEdgeCase::LineLine;
  if (a == F::Inside) return b == F::End0 ? EdgeEdgeCase::B0EdgeA : EdgeEdgeCase::B1EdgeA;
  if (b == F::Inside) return a == F::End0 ? EdgeEdgeCase::A0EdgeB : EdgeEdgeCase::A1EdgeB;
  if (a == F::End0) return b == F::End0 ? EdgeEdgeCase::A0B0 : EdgeEdgeCase::A0B1;
  return b == F::End0 ? EdgeEdgeCase::A1B0 : EdgeEdgeCase::A1B1;
}

/// Two edges with known closest features and squared distance.
struct KnownEdges {
  Stencil x;
  double distance;
  Feature a, b;
};

/// Edges whose closest points lie on the given features (End1 is not used: relabel gives it),
/// built from the optimality conditions of the convex ‖ea0 + s u − eb0 − t v‖²: the vector
/// between the closest points is δ m, perpendicular to an edge whose closest point is inside
/// it, and an edge whose closest point is its first endpoint leaves it away from the other
/// edge (u·m > 0 for a, v·m < 0 for b).
KnownEdges edges_with_features(Feature a, Feature b, Rng& rng) {
  const double delta = rng.uniform(0.05, 0.5);
  const double length_a = rng.uniform(0.5, 2), length_b = rng.uniform(0.5, 2);
  Vector3d u, v, m;
  for (;;) {
    m = rng.unit();
    const double tilt_a = rng.uniform(-1.2, 1.2), tilt_b = rng.uniform(-1.2, 1.2);
    u = a == Feature::Inside
            ? rng.unit_perpendicular(m)
            : Vector3d(std::cos(tilt_a) * m + std::sin(tilt_a) * rng.unit_perpendicular(m));
    v = b == Feature::Inside
            ? rng.unit_perpendicular(m)
            : Vector3d(-std::cos(tilt_b) * m + std::sin(tilt_b) * rng.unit_perpendicular(m));
    if (sine_squared(u, v) > 0.1) break;
  }
  const Vector3d closest_b = rng.point();
  const Vector3d closest_a = closest_b + delta * m;
  const double s = a == Feature::Inside ? rng.uniform(0.2, 0.8) : 0.0;
  const double t = b == Feature::Inside ? rng.uniform(0.2, 0.8) : 0.0;
  const Vector3d ea0 = closest_a - s * length_a * u, eb0 = closest_b - t * length_b * v;
  return {{ea0, ea0 + length_a * u, eb0, eb0 + length_b * v}, delta * delta, a, b};
}

/// The same pair with edge a reversed, edge b reversed and/or the edges swapped.
KnownEdges relabel(KnownEdges e, bool reverse_a, bool reverse_b, bool swap_edges) {
  const auto flip = [](Feature f) {
    return f == Feature::Inside ? f : (f == Feature::End0 ? Feature::End1 : Feature::End0);
  };
  if (reverse_a) {
    std::swap(e.x[0], e.x[1]);
    e.a = flip(e.a);
  }
  if (reverse_b) {
    std::swap(e.x[2], e.x[3]);
    e.b = flip(e.b);
  }
  if (swap_edges) {
    std::swap(e.x[0], e.x[2]);
    std::swap(e.x[1], e.x[3]);
    std::swap(e.a, e.b);
  }
  return e;
}

/// Every edge–edge case, from the three canonical constructions and their relabelings.
std::vector<KnownEdges> edges_for_every_case(Rng& rng) {
  std::vector<KnownEdges> all;
  const std::array<std::pair<Feature, Feature>, 3> canonical{{{Feature::End0, Feature::End0},
                                                              {Feature::End0, Feature::Inside},
                                                              {Feature::Inside, Feature::Inside}}};
  for (const auto& [a, b] : canonical)
    for (int flags = 0; flags < 8; ++flags)
      all.push_back(relabel(edges_with_features(a, b, rng), flags & 1, flags & 2, flags & 4));
  return all;
}

constexpr std::array<PointTriangleCase, 7> kAllPointTriangleCases{
    PointTriangleCase::Vertex0, PointTriangleCase::Vertex1, PointTriangleCase::Vertex2,
    PointTriangleCase::Edge01,  PointTriangleCase::Edge12,  PointTriangleCase::Edge20,
    PointTriangleCase::Face};

// ---- point–point and point–edge --------------------------------------------------------------

TEST(PointEdgeDistance, ClassifiesAndMeasuresEachFeature) {
  const Vector3d e0(0, 0, 0), e1(2, 0, 0);
  EXPECT_EQ(point_edge_case(Vector3d(-1, 1, 0), e0, e1), PointEdgeCase::Vertex0);
  EXPECT_EQ(point_edge_case(Vector3d(3, 0, 2), e0, e1), PointEdgeCase::Vertex1);
  EXPECT_EQ(point_edge_case(Vector3d(0.5, 1, 1), e0, e1), PointEdgeCase::Line);
  EXPECT_DOUBLE_EQ(point_edge_distance(Vector3d(-1, 1, 0), e0, e1), 2);
  EXPECT_DOUBLE_EQ(point_edge_distance(Vector3d(3, 0, 2), e0, e1), 5);
  EXPECT_DOUBLE_EQ(point_edge_distance(Vector3d(0.5, 1, 1), e0, e1), 2);
  // A zero-length edge is a point.
  EXPECT_EQ(point_edge_case(Vector3d(1, 1, 1), e0, e0), PointEdgeCase::Vertex0);
  EXPECT_DOUBLE_EQ(point_edge_distance(Vector3d(1, 1, 1), e0, e0), 3);
}

TEST(PointEdgeDistance, DerivativesMatchFiniteDifferencesInEveryCase) {
  const auto f = [](const VectorXd& v) {
    return point_edge_distance_derivatives(v.segment<3>(0), v.segment<3>(3), v.segment<3>(6));
  };
  const Vector3d e0(0.1, -0.2, 0.3), e1(1.3, 0.4, -0.2);
  Rng rng(7);
  const std::array<Vector3d, 3> points{e0 - 0.4 * (e1 - e0) + 0.1 * rng.unit(),
                                       e1 + 0.3 * (e1 - e0) + 0.1 * rng.unit(),
                                       e0 + 0.4 * (e1 - e0) + 0.5 * rng.unit()};
  const std::array<PointEdgeCase, 3> cases{PointEdgeCase::Vertex0, PointEdgeCase::Vertex1,
                                           PointEdgeCase::Line};
  for (int k = 0; k < 3; ++k) {
    ASSERT_EQ(point_edge_case(points[k], e0, e1), cases[k]);
    VectorXd x(9);
    x << points[k], e0, e1;
    expect_derivatives_match_finite_differences<9>(f, x, 1e-6, 1e-6);
  }
}

TEST(PointPointDistance, DerivativesMatchFiniteDifferences) {
  VectorXd x(6);
  x << 0.3, -0.1, 0.7, -0.5, 0.2, 0.4;
  expect_derivatives_match_finite_differences<6>(
      [](const VectorXd& v) {
        return point_point_distance_derivatives(v.segment<3>(0), v.segment<3>(3));
      },
      x, 1e-6, 1e-6);
}

// ---- point–triangle ---------------------------------------------------------------------------

TEST(PointTriangleDistance, ClassifiesAndMeasuresConstructedPairsOfEveryCase) {
  Rng rng(11);
  for (PointTriangleCase c : kAllPointTriangleCases) {
    for (int trial = 0; trial < 20; ++trial) {
      const KnownPair pair = point_triangle_with_case(c, rng);
      EXPECT_EQ(pt_case(pair.x), c) << "trial " << trial;
      EXPECT_NEAR(pt_distance(pair.x), pair.distance, 1e-13 * pair.distance + 1e-15);
      EXPECT_NEAR(pt_derivatives(pair.x).value, pair.distance, 1e-13 * pair.distance + 1e-15);
    }
  }
}

TEST(PointTriangleDistance, DerivativesMatchFiniteDifferencesInEveryCase) {
  Rng rng(12);
  for (PointTriangleCase c : kAllPointTriangleCases) {
    for (int trial = 0; trial < 3; ++trial) {
      const KnownPair pair = point_triangle_with_case(c, rng);
      ASSERT_EQ(pt_case(pair.x), c);
      expect_stencil_derivatives_match(pt_derivatives, pair.x);
    }
  }
}

TEST(PointTriangleDistance, UnusedVerticesHaveZeroDerivatives) {
  Rng rng(13);
  const KnownPair pair = point_triangle_with_case(PointTriangleCase::Edge12, rng);
  const StencilDerivatives<12> d = pt_derivatives(pair.x);
  EXPECT_EQ(d.gradient.segment<3>(3).norm(), 0);
  EXPECT_EQ(d.hessian.middleRows<3>(3).norm(), 0);
  EXPECT_EQ(d.hessian.middleCols<3>(3).norm(), 0);
}

TEST(PointTriangleDistance, EqualsBruteForceSearchOnRandomPairs) {
  Rng rng(14);
  for (int trial = 0; trial < 200; ++trial) {
    const Stencil x{1.5 * rng.point(), rng.point(), rng.point(), rng.point()};
    EXPECT_NEAR(pt_distance(x), brute_force_point_triangle(x), 1e-12) << "trial " << trial;
  }
}

TEST(PointTriangleDistance, IsInvariantUnderPermutationsOfTheTriangle) {
  Rng rng(15);
  for (int trial = 0; trial < 50; ++trial) {
    const Stencil x{1.5 * rng.point(), rng.point(), rng.point(), rng.point()};
    const StencilDerivatives<12> d = pt_derivatives(x);
    std::array<int, 3> order{1, 2, 3};
    while (std::next_permutation(order.begin(), order.end())) {
      const Stencil y{x[0], x[order[0]], x[order[1]], x[order[2]]};
      const StencilDerivatives<12> e = pt_derivatives(y);
      EXPECT_NEAR(e.value, d.value, 1e-14);
      EXPECT_NEAR(pt_distance(y), d.value, 1e-14);
      // The gradient moves with the vertices.
      EXPECT_LT((e.gradient.segment<3>(0) - d.gradient.segment<3>(0)).norm(), 1e-12);
      for (int k = 0; k < 3; ++k)
        EXPECT_LT((e.gradient.segment<3>(3 * (k + 1)) - d.gradient.segment<3>(3 * order[k])).norm(),
                  1e-12);
    }
  }
}

TEST(PointTriangleDistance, SliverTrianglesAreMeasuredThroughTheirEdges) {
  // A triangle collapsed onto a segment: no face case, the distance is to the segment.
  const Vector3d t0(0, 0, 0), t1(1, 0, 0), t2(2, 0, 0);
  const Vector3d p(0.5, 0.3, 0.4);
  EXPECT_NE(point_triangle_case(p, t0, t1, t2), PointTriangleCase::Face);
  EXPECT_DOUBLE_EQ(point_triangle_distance(p, t0, t1, t2), 0.25);
  // All three vertices coincide: a point.
  EXPECT_DOUBLE_EQ(point_triangle_distance(p, t0, t0, t0), p.squaredNorm());
}

// ---- edge–edge --------------------------------------------------------------------------------

TEST(EdgeEdgeDistance, ClassifiesAndMeasuresConstructedPairsOfEveryCase) {
  Rng rng(21);
  for (int trial = 0; trial < 10; ++trial) {
    for (const KnownEdges& e : edges_for_every_case(rng)) {
      EXPECT_EQ(ee_case(e.x), case_of(e.a, e.b)) << "trial " << trial;
      EXPECT_NEAR(ee_distance(e.x), e.distance, 1e-13 * e.distance + 1e-15);
      EXPECT_NEAR(ee_derivatives(e.x).value, e.distance, 1e-13 * e.distance + 1e-15);
    }
  }
}

TEST(EdgeEdgeDistance, DerivativesMatchFiniteDifferencesInEveryCase) {
  Rng rng(22);
  for (const KnownEdges& e : edges_for_every_case(rng)) {
    ASSERT_EQ(ee_case(e.x), case_of(e.a, e.b));
    expect_stencil_derivatives_match(ee_derivatives, e.x);
  }
}

TEST(EdgeEdgeDistance, EqualsBruteForceSearchOnRandomPairs) {
  Rng rng(23);
  for (int trial = 0; trial < 200; ++trial) {
    const Stencil x{rng.point(), rng.point(), rng.point(), rng.point()};
    EXPECT_NEAR(ee_distance(x), brute_force_edge_edge(x), 1e-12) << "trial " << trial;
  }
}

TEST(EdgeEdgeDistance, IsInvariantUnderSwappingAndReversingTheEdges) {
  Rng rng(24);
  for (int trial = 0; trial < 50; ++trial) {
    const Stencil x{rng.point(), rng.point(), rng.point(), rng.point()};
    const StencilDerivatives<12> d = ee_derivatives(x);
    const std::array<std::array<int, 4>, 4> orders{
        {{1, 0, 2, 3}, {0, 1, 3, 2}, {2, 3, 0, 1}, {3, 2, 1, 0}}};
    for (const auto& order : orders) {
      const Stencil y{x[order[0]], x[order[1]], x[order[2]], x[order[3]]};
      const StencilDerivatives<12> e = ee_derivatives(y);
      EXPECT_NEAR(e.value, d.value, 1e-14);
      for (int k = 0; k < 4; ++k)
        EXPECT_LT((e.gradient.segment<3>(3 * k) - d.gradient.segment<3>(3 * order[k])).norm(),
                  1e-12);
    }
  }
}

/// Edges through points δ apart along their common normal, at angle θ, in a generic (rotated)
/// frame: their distance is δ² for every θ, parallel included (then the edges overlap).
Stencil edges_at_angle(double theta, double delta) {
  const Eigen::Matrix3d rotation =
      Eigen::AngleAxisd(0.7, Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  const Vector3d u = rotation * Vector3d(1, 0, 0);
  const Vector3d v = rotation * Vector3d(std::cos(theta), std::sin(theta), 0);
  const Vector3d a_mid(0.2, -0.1, 0.3);
  const Vector3d b_mid = a_mid + delta * (rotation * Vector3d(0, 0, 1));
  return {a_mid - 0.5 * u, a_mid + 0.5 * u, b_mid - 0.7 * v, b_mid + 0.3 * v};
}

TEST(EdgeEdgeDistance, NearlyParallelAndParallelEdgesKeepTheirDistance) {
  const double delta = 0.01;
  for (double theta : {1e-2, 1e-4, 1e-6, 1e-8, 1e-10, 0.0}) {
    const Stencil x = edges_at_angle(theta, delta);
    EXPECT_NEAR(ee_distance(x), delta * delta, 1e-12 * delta * delta) << "θ = " << theta;
    const StencilDerivatives<12> d = ee_derivatives(x);
    EXPECT_NEAR(d.value, delta * delta, 1e-12 * delta * delta) << "θ = " << theta;
    EXPECT_TRUE(d.gradient.allFinite() && d.hessian.allFinite()) << "θ = " << theta;
  }
  // (Nearly) parallel edges fall back to an endpoint against the other edge: ea0 against b
  // and eb1 against a are equally near (a tie, broken by rounding).
  for (double theta : {1e-10, 0.0}) {
    const EdgeEdgeCase parallel = ee_case(edges_at_angle(theta, delta));
    EXPECT_TRUE(parallel == EdgeEdgeCase::A0EdgeB || parallel == EdgeEdgeCase::B1EdgeA)
        << "θ = " << theta;
  }
  EXPECT_EQ(ee_case(edges_at_angle(1e-2, delta)), EdgeEdgeCase::LineLine);
}

TEST(EdgeEdgeDistance, NearlyParallelLineLineDerivativesMatchFiniteDifferences) {
  const Stencil x = edges_at_angle(1e-2, 0.05);
  ASSERT_EQ(ee_case(x), EdgeEdgeCase::LineLine);
  expect_stencil_derivatives_match(ee_derivatives, x, 1e-7, 1e-5);
}

TEST(EdgeEdgeDistance, ParallelEdgesApartAlongTheirLineMeetAtEndpoints) {
  // Collinear-direction edges offset by (0.5, δ): the closest points are ea1 and eb0.
  const Vector3d ea0(0, 0, 0), ea1(1, 0, 0), eb0(1.5, 0.1, 0), eb1(2.5, 0.1, 0);
  EXPECT_EQ(edge_edge_case(ea0, ea1, eb0, eb1), EdgeEdgeCase::A1B0);
  EXPECT_DOUBLE_EQ(edge_edge_distance(ea0, ea1, eb0, eb1), 0.26);
  expect_stencil_derivatives_match(ee_derivatives, {ea0, ea1, eb0, eb1});
}

TEST(EdgeEdgeDistance, DegenerateEdgesAreMeasuredAsPoints) {
  const Vector3d p(0.3, 0.4, 0.5), ea0(0, 0, 0), ea1(1, 0, 0);
  EXPECT_DOUBLE_EQ(edge_edge_distance(ea0, ea1, p, p), 0.41);
  EXPECT_DOUBLE_EQ(edge_edge_distance(p, p, p, p), 0);
}

}  // namespace
}  // namespace psq
