// Additive CCD and its distance routines, checked against exact references (CGAL's exact
// kernel), motions whose answers follow by hand, and the shared CCD benchmark set.

#include "engine/contact/additive_ccd.hpp"

#include <CGAL/Exact_predicates_exact_constructions_kernel.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>

#include "engine/contact/ccd_query_file.hpp"
#include "engine/contact/edge_edge_distance.hpp"
#include "engine/contact/point_triangle_distance.hpp"
#include "engine/core/error.hpp"
#include "support/random_geometry.hpp"
#include "support/test_paths.hpp"

namespace psq {
namespace {

using Eigen::Vector3d;
using Kernel = CGAL::Exact_predicates_exact_constructions_kernel;
using ExactPoint = Kernel::Point_3;

ExactPoint exact(const Vector3d& x) { return {x.x(), x.y(), x.z()}; }

/// Exact squared distance of a primitive pair, with the positions taken exactly as given.
Kernel::FT exact_squared_distance(CcdQueryKind kind, const std::array<ExactPoint, 4>& x) {
  if (kind == CcdQueryKind::vertex_face)
    return CGAL::squared_distance(x[0], Kernel::Triangle_3(x[1], x[2], x[3]));
  return CGAL::squared_distance(Kernel::Segment_3(x[0], x[1]), Kernel::Segment_3(x[2], x[3]));
}

/// Exact squared distance at time t along the straight paths start → end (t as given).
Kernel::FT exact_squared_distance_at(CcdQueryKind kind, const PairPositions& start,
                                     const PairPositions& end, double t) {
  std::array<ExactPoint, 4> x;
  for (int i = 0; i < 4; ++i) {
    const ExactPoint a = exact(start[i]), b = exact(end[i]);
    x[i] = a + Kernel::FT(t) * (b - a);
  }
  return exact_squared_distance(kind, x);
}

double reference_distance(CcdQueryKind kind, const PairPositions& x) {
  return std::sqrt(CGAL::to_double(
      exact_squared_distance(kind, {exact(x[0]), exact(x[1]), exact(x[2]), exact(x[3])})));
}

double point_triangle(const PairPositions& x) {
  return std::sqrt(point_triangle_distance(x[0], x[1], x[2], x[3]));
}
double segment_segment(const PairPositions& x) {
  return std::sqrt(edge_edge_distance(x[0], x[1], x[2], x[3]));
}

// ---- distances -------------------------------------------------------------------------------

TEST(CcdDistance, PointTriangleMatchesExactDistanceOnRandomPairs) {
  std::mt19937 rng(7);
  for (int trial = 0; trial < 2000; ++trial) {
    PairPositions x;
    for (Vector3d& v : x) v = test::random_point(rng);
    if (trial % 4 == 0)  // all in one plane, the point often inside the triangle
      for (Vector3d& v : x) v.z() = 0;
    EXPECT_NEAR(point_triangle(x), reference_distance(CcdQueryKind::vertex_face, x), 1e-12)
        << trial;
  }
}

TEST(CcdDistance, PointTriangleRegionsByHand) {
  const Vector3d t0(0, 0, 0), t1(2, 0, 0), t2(0, 2, 0);
  EXPECT_DOUBLE_EQ(std::sqrt(point_triangle_distance({0.5, 0.5, 3}, t0, t1, t2)), 3.0);  // face
  EXPECT_DOUBLE_EQ(std::sqrt(point_triangle_distance({1, -4, 3}, t0, t1, t2)), 5.0);     // edge
  EXPECT_DOUBLE_EQ(std::sqrt(point_triangle_distance({-3, -4, 0}, t0, t1, t2)), 5.0);    // corner
  EXPECT_EQ(std::sqrt(point_triangle_distance({0.5, 0.5, 0}, t0, t1, t2)), 0.0);         // inside
  // A degenerate (collinear) triangle is its longest edge.
  EXPECT_DOUBLE_EQ(std::sqrt(point_triangle_distance({1, 3, 4}, t0, {1, 0, 0}, t1)), 5.0);
}

TEST(CcdDistance, SegmentSegmentMatchesExactDistanceOnRandomPairs) {
  std::mt19937 rng(11);
  for (int trial = 0; trial < 2000; ++trial) {
    PairPositions x;
    for (Vector3d& v : x) v = test::random_point(rng);
    if (trial % 4 == 1) x[3] = x[2] + 0.7 * (x[1] - x[0]);  // exactly parallel directions
    EXPECT_NEAR(segment_segment(x), reference_distance(CcdQueryKind::edge_edge, x), 1e-12) << trial;
  }
}

TEST(CcdDistance, NearlyParallelAndDegenerateSegments) {
  // Edge b crosses over edge a at a tiny angle, 1e-3 above it: the minimum is inside both.
  // The line–line formula loses digits as the edges turn parallel (5e-11 relative at 1e-8);
  // the CCD tolerates that: its steps keep a 10% margin of the distance (rescaling s = 0.9).
  for (const double angle : {1e-4, 1e-8, 1e-12, 1e-15}) {
    const PairPositions x = {Vector3d(-1, 0, 0), Vector3d(1, 0, 0), Vector3d(-1, -angle, 1e-3),
                             Vector3d(1, angle, 1e-3)};
    EXPECT_NEAR(segment_segment(x), reference_distance(CcdQueryKind::edge_edge, x), 1e-13) << angle;
  }
  // Overlapping parallel edges 0.25 apart, and a zero-length edge.
  EXPECT_DOUBLE_EQ(std::sqrt(edge_edge_distance({0, 0, 0}, {2, 0, 0}, {1, 0.25, 0}, {3, 0.25, 0})),
                   0.25);
  EXPECT_DOUBLE_EQ(std::sqrt(edge_edge_distance({0, 0, 0}, {2, 0, 0}, {1, 3, 4}, {1, 3, 4})), 5.0);
  EXPECT_DOUBLE_EQ(std::sqrt(edge_edge_distance({0, 0, 0}, {0, 0, 0}, {3, 4, 0}, {3, 4, 0})), 5.0);
}

// ---- hand-made motions -----------------------------------------------------------------------

/// The triangle (0,0,0), (1,0,0), (0,1,0), at rest, and a point moving from `from` to `to`.
struct PointMotion {
  PairPositions start, end;
  PointMotion(const Vector3d& from, const Vector3d& to) {
    start = {from, Vector3d(0, 0, 0), Vector3d(1, 0, 0), Vector3d(0, 1, 0)};
    end = start;
    end[0] = to;
  }
  /// The point's true distance to the triangle at time t, independent of the CCD's routines.
  [[nodiscard]] double distance_at(double t) const {
    return reference_distance(CcdQueryKind::vertex_face,
                              {start[0] + t * (end[0] - start[0]), start[1], start[2], start[3]});
  }
};

// Falling straight through the triangle, the point touches it at t = 0.5. After removing the
// mean displacement, l_p = 3/4·2 + 1/4·2 = 2 is exactly the closing speed, so ACCD advances
// to 0.9·0.5 = 0.45 (gap 0.1 = r·d₀, kept) and then rejects the step to 0.495 (gap 0.01).
TEST(AdditiveCcd, PointFallingThroughTriangleStopsJustBeforeContact) {
  const PointMotion motion({0.25, 0.25, 1}, {0.25, 0.25, -1});
  const CcdResult result = point_triangle_ccd(motion.start, motion.end);
  EXPECT_TRUE(result.collision);
  EXPECT_LT(result.toi, 0.5);
  EXPECT_GE(result.toi, 0.9 * 0.5 * (1 - 1e-9));
  EXPECT_GT(motion.distance_at(result.toi), 0.1 * motion.distance_at(0) * (1 - 1e-9));
}

TEST(AdditiveCcd, PointMovingAwayOrParallelDoesNotCollide) {
  for (const Vector3d& to : {Vector3d(0.25, 0.25, 2), Vector3d(5, 0.25, 1), Vector3d(-3, 2, 1)}) {
    const PointMotion motion({0.25, 0.25, 1}, to);
    const CcdResult result = point_triangle_ccd(motion.start, motion.end);
    EXPECT_FALSE(result.collision) << to.transpose();
    EXPECT_EQ(result.toi, 1.0) << to.transpose();
  }
}

TEST(AdditiveCcd, RigidMotionOrRestNeedsNoIteration) {
  const PointMotion motion({0.25, 0.25, 1}, {0.25, 0.25, 1});
  PairPositions shifted = motion.start;
  for (Vector3d& v : shifted) v += Vector3d(3, -2, 7);
  for (const PairPositions& end : {motion.start, shifted}) {
    const CcdResult result = point_triangle_ccd(motion.start, end);
    EXPECT_FALSE(result.collision);
    EXPECT_EQ(result.toi, 1.0);
    EXPECT_EQ(result.iterations, 0);
  }
}

TEST(AdditiveCcd, CrossingEdgesStopJustBeforeContact) {
  // Edge a sweeps down through edge b, touching it at t = 0.5; l_p = 1 + 1 = 2 again.
  const PairPositions start = {Vector3d(-1, 0, 1), Vector3d(1, 0, 1), Vector3d(0, -1, 0),
                               Vector3d(0, 1, 0)};
  PairPositions end = start;
  end[0].z() = end[1].z() = -1;
  const CcdResult result = edge_edge_ccd(start, end);
  EXPECT_TRUE(result.collision);
  EXPECT_LT(result.toi, 0.5);
  EXPECT_GE(result.toi, 0.9 * 0.5 * (1 - 1e-9));
  EXPECT_GT(
      CGAL::to_double(exact_squared_distance_at(CcdQueryKind::edge_edge, start, end, result.toi)),
      0.0);
}

TEST(AdditiveCcd, ParallelEdgesCollideOrSlideByAsTheyShould) {
  const PairPositions start = {Vector3d(0, 0, 1), Vector3d(1, 0, 1), Vector3d(0.5, 0, 0),
                               Vector3d(1.5, 0, 0)};
  PairPositions down = start, along = start;
  down[0].z() = down[1].z() = -1;
  along[0].x() += 4;
  along[1].x() += 4;
  const CcdResult falling = edge_edge_ccd(start, down);
  EXPECT_TRUE(falling.collision);
  EXPECT_LT(falling.toi, 0.5);
  EXPECT_GT(falling.toi, 0.4);
  EXPECT_FALSE(edge_edge_ccd(start, along).collision);
}

TEST(AdditiveCcd, RatioBoundDecidesNearMisses) {
  // The point passes 0.05 beside the triangle's edge y = 0: no contact, but the distance falls
  // to 5% of d₀. r = 0.1 reports it, with the gap at t* still ≥ r·d₀; r = 0.01 lets it pass.
  const PointMotion motion({0.25, -0.05, 1}, {0.25, -0.05, -1});
  const double d0 = motion.distance_at(0);
  AdditiveCcdSettings settings;
  const CcdResult strict = point_triangle_ccd(motion.start, motion.end, settings);
  EXPECT_TRUE(strict.collision);
  EXPECT_GT(strict.toi, 0.0);
  EXPECT_GE(motion.distance_at(strict.toi), 0.1 * d0 * (1 - 1e-9));
  settings.ratio_bound = 0.01;
  const CcdResult loose = point_triangle_ccd(motion.start, motion.end, settings);
  EXPECT_FALSE(loose.collision);
  EXPECT_EQ(loose.toi, 1.0);
}

TEST(AdditiveCcd, LargeRatioBoundKeepsMostOfTheGap) {
  // With r = 0.5 the advance is min(s, 1 − r) = 0.5 of the safe time: one step to t = 0.25
  // (distance 0.5 = r·d₀), then the step to 0.375 (distance 0.25) is refused.
  const PointMotion motion({0.25, 0.25, 1}, {0.25, 0.25, -1});
  AdditiveCcdSettings settings;
  settings.ratio_bound = 0.5;
  const CcdResult result = point_triangle_ccd(motion.start, motion.end, settings);
  EXPECT_TRUE(result.collision);
  EXPECT_NEAR(result.toi, 0.25, 1e-9);
  EXPECT_GE(motion.distance_at(result.toi), 0.5 * (1 - 1e-9));
}

// With r = 0.999 each advance may close only 0.1 % of the gap; a pair moving apart still
// passes the full step in a few advances, since the gap's excess over r·d₀ bounds the step.
TEST(AdditiveCcd, ASeparatingPairPassesQuicklyEvenWithARatioBoundNearOne) {
  const PointMotion motion({0.25, 0.25, 1e-6}, {0.25, 0.25, 1.0});
  AdditiveCcdSettings settings;
  settings.ratio_bound = 0.999;
  const CcdResult result = point_triangle_ccd(motion.start, motion.end, settings);
  EXPECT_FALSE(result.collision);
  EXPECT_EQ(result.toi, 1.0);
  EXPECT_LE(result.iterations, 40);
  // Head-on, the same bound still keeps 99.9 % of the gap.
  const PointMotion falling({0.25, 0.25, 1}, {0.25, 0.25, -1});
  const CcdResult stopped = point_triangle_ccd(falling.start, falling.end, settings);
  EXPECT_TRUE(stopped.collision);
  EXPECT_GE(falling.distance_at(stopped.toi), 0.999 * (1 - 1e-9));
}

TEST(AdditiveCcd, MinimumDistanceCountsAsContact) {
  // With ξ = 0.5 the falling point reaches the contact distance at t = 0.25.
  const PointMotion motion({0.25, 0.25, 1}, {0.25, 0.25, -1});
  AdditiveCcdSettings settings;
  settings.min_distance = 0.5;
  const CcdResult result = point_triangle_ccd(motion.start, motion.end, settings);
  EXPECT_TRUE(result.collision);
  EXPECT_LT(result.toi, 0.25);
  EXPECT_GE(result.toi, 0.9 * 0.25 * (1 - 1e-9));
  EXPECT_GT(motion.distance_at(result.toi), 0.5);

  settings.min_distance = 2;  // already closer than ξ at t = 0
  const CcdResult inside = point_triangle_ccd(motion.start, motion.end, settings);
  EXPECT_TRUE(inside.collision);
  EXPECT_EQ(inside.toi, 0.0);
  EXPECT_EQ(inside.iterations, 0);
}

TEST(AdditiveCcd, StopsAtTmax) {
  const PointMotion motion({0.25, 0.25, 1}, {0.25, 0.25, -1});
  AdditiveCcdSettings settings;
  settings.t_max = 0.4;  // contact at 0.5 lies beyond
  const CcdResult result = point_triangle_ccd(motion.start, motion.end, settings);
  EXPECT_FALSE(result.collision);
  EXPECT_EQ(result.toi, 0.4);
}

/// A random pair and a random straight motion of it, fast enough that many pairs collide.
std::pair<PairPositions, PairPositions> random_motion(std::mt19937& rng) {
  PairPositions start, end;
  for (int i = 0; i < 4; ++i) {
    start[i] = test::random_point(rng);
    end[i] = start[i] + 2.0 * test::random_point(rng);
  }
  return {start, end};
}

TEST(AdditiveCcd, StoppingAfterABoundKeepsEveryEarlierTimeOfImpact) {
  // Random pairs, many of them close and fast: with stop_after = τ a query that would have
  // reported a time of impact below τ reports the same one, and any other ends at or after τ
  // without a collision.
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> bound(0.01, 1.0);
  int earlier = 0;
  for (int trial = 0; trial < 2000; ++trial) {
    const auto [start, end] = random_motion(rng);
    const bool edge_edge = trial % 2 == 1;
    const auto query = [&](const AdditiveCcdSettings& settings) {
      return edge_edge ? edge_edge_ccd(start, end, settings) : point_triangle_ccd(start, end, settings);
    };
    const CcdResult full = query({});
    AdditiveCcdSettings stopping;
    stopping.stop_after = bound(rng);
    const CcdResult stopped = query(stopping);
    if (full.toi < stopping.stop_after) {
      ++earlier;
      EXPECT_EQ(stopped.collision, full.collision) << trial;
      EXPECT_EQ(stopped.toi, full.toi) << trial;
    } else {
      EXPECT_FALSE(stopped.collision) << trial;
      EXPECT_GE(stopped.toi, stopping.stop_after) << trial;
      EXPECT_LE(stopped.iterations, full.iterations) << trial;
    }
  }
  EXPECT_GT(earlier, 100);  // both branches were exercised
}

TEST(AdditiveCcd, NoCollisionIsReportedWithinTheFirstAdvance) {
  // ccd_first_advance is a lower bound of every query's time of impact, and a query whose step
  // ends there finds the pair apart.
  std::mt19937 rng(11);
  int limiting = 0;
  for (int trial = 0; trial < 2000; ++trial) {
    const auto [start, end] = random_motion(rng);
    const bool edge_edge = trial % 2 == 1;
    const double first = ccd_first_advance(start, end, edge_edge);
    AdditiveCcdSettings settings;
    const CcdResult full =
        edge_edge ? edge_edge_ccd(start, end, settings) : point_triangle_ccd(start, end, settings);
    EXPECT_GE(full.toi, std::min(first, 1.0)) << trial;
    if (first >= 1.0) continue;
    ++limiting;
    settings.t_max = first;
    const CcdResult within =
        edge_edge ? edge_edge_ccd(start, end, settings) : point_triangle_ccd(start, end, settings);
    EXPECT_FALSE(within.collision) << trial;
    EXPECT_EQ(within.iterations, 1) << trial;
  }
  EXPECT_GT(limiting, 100);
  // Touching: nothing is covered.
  const PairPositions touching{Vector3d(0, 0, 0), Vector3d(0, 0, 0), Vector3d(1, 0, 0),
                               Vector3d(0, 1, 0)};
  EXPECT_EQ(ccd_first_advance(touching, touching, false), 0.0);
}

TEST(AdditiveCcd, IterationCapReportsACollisionAtTheTimeReached) {
  // A fast slide 1 above the triangle's plane needs many small advances.
  const PointMotion motion({0.25, 0.25, 1}, {100, 0.25, 1});
  ASSERT_FALSE(point_triangle_ccd(motion.start, motion.end).collision);
  AdditiveCcdSettings settings;
  settings.max_iterations = 5;
  const CcdResult capped = point_triangle_ccd(motion.start, motion.end, settings);
  EXPECT_TRUE(capped.collision);
  EXPECT_EQ(capped.iterations, 5);
  EXPECT_GT(capped.toi, 0.0);
  EXPECT_LT(capped.toi, 1.0);
}

TEST(AdditiveCcd, NonFinitePositionsAreNumericalErrors) {
  const PointMotion motion({0.25, 0.25, 1}, {0.25, 0.25, -1});
  PairPositions end = motion.end;
  end[2].y() = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(point_triangle_ccd(motion.start, end), NumericalError);
  end[2].y() = std::numeric_limits<double>::infinity();
  EXPECT_THROW(edge_edge_ccd(motion.start, end), NumericalError);
}

TEST(AdditiveCcd, SettingsOutsideTheirRangeAreInputErrors) {
  auto message = [](void (*spoil)(AdditiveCcdSettings&)) -> std::string {
    AdditiveCcdSettings settings;
    spoil(settings);
    try {
      validate_ccd_settings(settings);
    } catch (const InputError& e) {
      return e.what();
    }
    return "accepted";
  };
  EXPECT_NO_THROW(validate_ccd_settings({}));
  EXPECT_NE(message([](AdditiveCcdSettings& s) { s.rescaling = 1; }).find("rescaling"),
            std::string::npos);
  EXPECT_NE(message([](AdditiveCcdSettings& s) { s.ratio_bound = 0; }).find("ratio_bound"),
            std::string::npos);
  EXPECT_NE(message([](AdditiveCcdSettings& s) { s.min_distance = -1; }).find("min_distance"),
            std::string::npos);
  EXPECT_NE(message([](AdditiveCcdSettings& s) { s.max_iterations = 0; }).find("max_iterations"),
            std::string::npos);
  EXPECT_NE(message([](AdditiveCcdSettings& s) { s.t_max = 0; }).find("t_max"), std::string::npos);
}

// ---- the shared benchmark set ----------------------------------------------------------------

std::vector<std::filesystem::path> benchmark_files() {
  std::vector<std::filesystem::path> files;
  for (const auto& entry :
       std::filesystem::recursive_directory_iterator(test::shared_dir() / "data" / "ccd-queries"))
    if (entry.path().extension() == ".csv") files.push_back(entry.path());
  std::sort(files.begin(), files.end());
  return files;
}

// Measured with the default settings (s = 0.9, r = 0.1): 285 false positives among 1562
// queries with truth 0 (18.2%), at most 61 of 105 (58%) in one file. They are near misses:
// 230 of them remain even with r = 1e-9 (the set's degenerate cases pass within a billionth of
// d₀, many at rounding level, which a floating-point CCD cannot tell from contact); the other
// 55 come closer than r·d₀, which ACCD reports by design. The bounds leave a little room.
constexpr double kMaxFalsePositiveShareInAFile = 0.65;
constexpr double kMaxFalsePositiveShareOverall = 0.20;

TEST(AdditiveCcdBenchmarkSet, NoFalseNegativesAndSafeTimesOfImpactOnEveryFile) {
  const std::vector<std::filesystem::path> files = benchmark_files();
  ASSERT_EQ(files.size(), 16u) << "the shared CCD query set is incomplete";
  long queries = 0, negatives = 0, false_positives = 0;
  for (const auto& file : files) {
    SCOPED_TRACE(file.string());
    const CcdQueryKind kind = ccd_query_kind(file);
    const std::vector<CcdQuery> file_queries = read_ccd_queries(file);
    long file_negatives = 0, file_false_positives = 0, file_false_negatives = 0;
    for (const CcdQuery& query : file_queries) {
      const CcdResult result = run_ccd_query(query, kind, {});
      if (query.truth && !result.collision) {
        ++file_false_negatives;
        ADD_FAILURE() << "missed the contact of the query at line " << query.line;
      }
      if (!query.truth) {
        ++file_negatives;
        file_false_positives += result.collision;
      }
      if (!result.collision) {
        EXPECT_EQ(result.toi, 1.0) << "line " << query.line;
      } else if (result.toi > 0) {
        // Independent check of the safe time: the exact distance there is positive.
        EXPECT_GT(exact_squared_distance_at(kind, query.start, query.end, result.toi), 0)
            << "line " << query.line << ", t* = " << result.toi;
      }
    }
    EXPECT_EQ(file_false_negatives, 0);
    EXPECT_LE(file_false_positives, kMaxFalsePositiveShareInAFile * double(file_negatives));
    const CcdTally tally = tally_ccd_queries(file_queries, kind, {});
    EXPECT_EQ(tally.queries, long(file_queries.size()));
    EXPECT_EQ(tally.queries - tally.touching, file_negatives);
    EXPECT_EQ(tally.false_negatives, file_false_negatives);
    EXPECT_EQ(tally.false_positives, file_false_positives);
    queries += long(file_queries.size());
    negatives += file_negatives;
    false_positives += file_false_positives;
  }
  EXPECT_EQ(queries, 14592 / 8);
  EXPECT_LT(false_positives, kMaxFalsePositiveShareOverall * double(negatives))
      << false_positives << " false positives among " << negatives << " negatives";
}

}  // namespace
}  // namespace psq
