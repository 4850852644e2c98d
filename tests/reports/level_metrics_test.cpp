// The numbers a report derives: bounding-box diagonal, error to the finest level, level time,
// final residual.

#include "reports/level_metrics.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace psq::reports {
namespace {

TEST(LevelMetrics, BoundingBoxDiagonalOfABox) {
  Positions points(3, 3);
  points << 0, 0, 0, 3, -1, 0, 1, 1, 12;  // x ∈ [0,3], y ∈ [−1,1], z ∈ [0,12]
  EXPECT_DOUBLE_EQ(bounding_box_diagonal(points), std::sqrt(9.0 + 4.0 + 144.0));
  EXPECT_EQ(bounding_box_diagonal(Positions(0, 3)), 0.0);
}

TEST(LevelMetrics, RelativeErrorIsTheLargestVertexDistanceOverTheDiagonal) {
  Positions finest(3, 3), prolonged(3, 3);
  finest << 0, 0, 0, 4, 0, 0, 0, 3, 0;  // diagonal 5
  prolonged = finest;
  prolonged.row(1) += Eigen::RowVector3d(0, 0, 0.5);
  prolonged.row(2) += Eigen::RowVector3d(0.3, 0.4, 0);  // distance 0.5 too, the largest is 0.5
  prolonged.row(0) += Eigen::RowVector3d(0.1, 0, 0);
  EXPECT_DOUBLE_EQ(relative_error_to_finest(prolonged, finest), 0.5 / 5.0);
  EXPECT_EQ(relative_error_to_finest(finest, finest), 0.0);
}

TEST(LevelMetrics, RelativeErrorRefusesMismatchedOrDegenerateShapes) {
  Positions finest(2, 3), other(3, 3);
  finest << 0, 0, 0, 1, 0, 0;
  other.setZero();
  EXPECT_THROW(relative_error_to_finest(other, finest), std::invalid_argument);
  Positions point = Positions::Zero(2, 3);
  EXPECT_THROW(relative_error_to_finest(point, point), std::invalid_argument);
}

TEST(LevelMetrics, LevelSecondsPreferWallThenTotalThenTheSumOfPhases) {
  EXPECT_EQ(level_seconds({{"wall", 2.0}, {"total", 3.0}, {"solve", 1.0}}), 2.0);
  EXPECT_EQ(level_seconds({{"total", 3.0}, {"solve", 1.0}}), 3.0);
  EXPECT_DOUBLE_EQ(*level_seconds({{"assembly", 0.25}, {"solve", 1.5}}), 1.75);
  EXPECT_FALSE(level_seconds({}).has_value());
}

TEST(LevelMetrics, FinalResidualIsTheLastFiniteValue) {
  EXPECT_EQ(final_residual({1.0, 0.1, 1e-5}), 1e-5);
  EXPECT_EQ(final_residual({1.0, 1e-3, NAN, INFINITY}), 1e-3);
  EXPECT_FALSE(final_residual({NAN}).has_value());
  EXPECT_FALSE(final_residual({}).has_value());
}

}  // namespace
}  // namespace psq::reports
