#include "engine/scene/rigid_motion.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace psq {
namespace {

RigidMotion rotation(double start, double end, const Eigen::Vector3d& point,
                     const Eigen::Vector3d& axis, double degrees) {
  RigidMotion m;
  m.start_time = start;
  m.end_time = end;
  m.axis_point = point;
  m.axis_direction = axis;
  m.angle_degrees = degrees;
  return m;
}

RigidMotion translation(double start, double end, const Eigen::Vector3d& offset) {
  RigidMotion m;
  m.start_time = start;
  m.end_time = end;
  m.translation = offset;
  return m;
}

void expect_near(const Eigen::Vector3d& actual, const Eigen::Vector3d& expected) {
  EXPECT_LT((actual - expected).norm(), 1e-12)
      << actual.transpose() << " vs " << expected.transpose();
}

TEST(ApplyMotions, NoMotionKeepsTheRestPosition) {
  expect_near(apply_motions({}, {1, 2, 3}, 5.0), {1, 2, 3});
}

TEST(ApplyMotions, RotatesAboutAnOffsetAxisLinearlyInTime) {
  // 90° about the z axis through (1, 0, 0); the point (2, 0, 0) is 1 from the axis.
  const std::vector motions{rotation(0, 1, {1, 0, 0}, {0, 0, 1}, 90)};
  const double h = std::sqrt(0.5);
  expect_near(apply_motions(motions, {2, 0, 0}, -1.0), {2, 0, 0});  // before start
  expect_near(apply_motions(motions, {2, 0, 0}, 0.0), {2, 0, 0});
  expect_near(apply_motions(motions, {2, 0, 0}, 0.5), {1 + h, h, 0});  // 45°
  expect_near(apply_motions(motions, {2, 0, 0}, 1.0), {1, 1, 0});
  expect_near(apply_motions(motions, {2, 0, 0}, 3.0), {1, 1, 0});  // held after the end
}

TEST(ApplyMotions, AxisLengthDoesNotMatter) {
  const std::vector unit{rotation(0, 1, {0, 0, 0}, {1, 0, 0}, 60)};
  const std::vector longer{rotation(0, 1, {0, 0, 0}, {7, 0, 0}, 60)};
  expect_near(apply_motions(longer, {0, 1, 0}, 1.0), apply_motions(unit, {0, 1, 0}, 1.0));
  // Rotation by 60° about +x takes y to (0, cos 60°, sin 60°).
  expect_near(apply_motions(unit, {0, 1, 0}, 1.0), {0, 0.5, std::sqrt(3.0) / 2});
}

TEST(ApplyMotions, OneMotionRotatesThenTranslates) {
  RigidMotion m = rotation(0, 2, {0, 0, 0}, {0, 0, 1}, 180);
  m.translation = {1, 0, 0};
  // At t = 1 (s = 1/2): rotate (1, 0, 0) by 90° to (0, 1, 0), then add (0.5, 0, 0).
  expect_near(apply_motions({m}, {1, 0, 0}, 1.0), {0.5, 1, 0});
  // At the end: rotated by 180° to (-1, 0, 0), then shifted by (1, 0, 0).
  expect_near(apply_motions({m}, {1, 0, 0}, 2.0), {0, 0, 0});
}

TEST(ApplyMotions, SequentialMotionsComposeInOrder) {
  // First a quarter turn about +x during [0, 1], then a lift by 1 along z during [1, 2].
  const std::vector motions{rotation(0, 1, {0, 0, 0}, {1, 0, 0}, 90), translation(1, 2, {0, 0, 1})};
  expect_near(apply_motions(motions, {0, 1, 0}, 0.5), {0, std::sqrt(0.5), std::sqrt(0.5)});
  expect_near(apply_motions(motions, {0, 1, 0}, 1.0), {0, 0, 1});
  expect_near(apply_motions(motions, {0, 1, 0}, 1.5), {0, 0, 1.5});
  expect_near(apply_motions(motions, {0, 1, 0}, 2.0), {0, 0, 2});
}

TEST(ApplyMotions, SimultaneousRotationsApplyTheFirstFirst) {
  // Both run during [0, 1]: R_x(90°)·R_z(90°)·(1, 0, 0) = R_x(90°)·(0, 1, 0) = (0, 0, 1);
  // the other order would give R_z(90°)·R_x(90°)·(1, 0, 0) = (0, 1, 0).
  const std::vector motions{rotation(0, 1, {0, 0, 0}, {0, 0, 1}, 90),
                            rotation(0, 1, {0, 0, 0}, {1, 0, 0}, 90)};
  expect_near(apply_motions(motions, {1, 0, 0}, 1.0), {0, 0, 1});
  // Halfway: R_x(45°)·R_z(45°)·(1, 0, 0) = R_x(45°)·(h, h, 0) = (h, h², h²), h = √½.
  const double h = std::sqrt(0.5);
  expect_near(apply_motions(motions, {1, 0, 0}, 0.5), {h, 0.5, 0.5});
}

TEST(ApplyMotions, ZeroLengthMotionIsAJumpAtItsTime) {
  const std::vector motions{translation(1, 1, {0, 0, 2})};
  expect_near(apply_motions(motions, {0, 0, 0}, 0.999), {0, 0, 0});
  expect_near(apply_motions(motions, {0, 0, 0}, 1.0), {0, 0, 2});
}

}  // namespace
}  // namespace psq
