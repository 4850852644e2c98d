#include "engine/hierarchy/shell_prolongation.hpp"

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <random>

#include "engine/core/error.hpp"
#include "engine/hierarchy/triangle_frame.hpp"
#include "engine/mesh/generators.hpp"
#include "support/finite_difference.hpp"

namespace psq {
namespace {

/// Targets scattered over a coarse sphere: random triangles, random barycentric coordinates,
/// random offsets off the surface (a stand-in for finer rest vertices).
struct ScatteredTargets {
  TriMesh coarse;
  std::vector<SurfaceLocation> locations;
  Positions rest;
};

ScatteredTargets scattered_targets(int count, unsigned seed) {
  ScatteredTargets s;
  s.coarse = make_sphere({.radius = 0.5, .edge_length = 0.25});
  std::mt19937 rng(seed);
  std::uniform_int_distribution<int> triangle(0, s.coarse.triangle_count() - 1);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  s.rest.resize(count, 3);
  for (int i = 0; i < count; ++i) {
    SurfaceLocation location;
    location.triangle = triangle(rng);
    Eigen::Vector3d b(unit(rng), unit(rng), unit(rng));
    location.barycentric = b / b.sum();
    Eigen::Vector3d anchor = Eigen::Vector3d::Zero();
    for (int k = 0; k < 3; ++k) {
      anchor += b[k] / b.sum() * s.coarse.vertices.row(s.coarse.triangles(location.triangle, k))
                                     .transpose();
    }
    s.rest.row(i) = anchor + 0.05 * Eigen::Vector3d::Random();
    s.locations.push_back(location);
  }
  return s;
}

TEST(ShellProlongation, RecoversTargetRestPositionsFromCoarseRest) {
  const ScatteredTargets s = scattered_targets(200, 1);
  const ShellProlongation p(s.coarse, s.locations, s.rest);
  EXPECT_EQ(p.target_count(), 200);
  EXPECT_EQ(p.coarse_vertex_count(), s.coarse.vertex_count());
  EXPECT_LT((p.apply(s.coarse.vertices) - s.rest).cwiseAbs().maxCoeff(), 1e-14);
}

TEST(ShellProlongation, LinearPartIsTheBarycentricAnchor) {
  const ScatteredTargets s = scattered_targets(50, 2);
  const ShellProlongation p(s.coarse, s.locations, s.rest);
  const Positions x = s.coarse.vertices + 0.1 * Positions::Random(s.coarse.vertex_count(), 3);
  Positions anchors(50, 3);
  flat(anchors) = p.linear_part() * flat(x);
  for (int i = 0; i < 50; ++i) {
    Eigen::Vector3d expected = Eigen::Vector3d::Zero();
    for (int k = 0; k < 3; ++k) {
      expected += s.locations[i].barycentric[k] *
                  x.row(s.coarse.triangles(s.locations[i].triangle, k)).transpose();
    }
    EXPECT_LT((anchors.row(i).transpose() - expected).norm(), 1e-14);
  }
  EXPECT_LT((p.apply(x) - anchors - p.offsets(x)).cwiseAbs().maxCoeff(), 1e-14);
}

TEST(ShellProlongation, CommutesWithRigidMotions) {
  const ScatteredTargets s = scattered_targets(200, 3);
  const ShellProlongation p(s.coarse, s.locations, s.rest);
  // A deformed (not rest) configuration, then a random rotation and translation of it.
  const Positions x = s.coarse.vertices + 0.05 * Positions::Random(s.coarse.vertex_count(), 3);
  const Eigen::Matrix3d rotation =
      Eigen::Quaterniond(Eigen::Vector4d::Random().normalized()).toRotationMatrix();
  const Eigen::RowVector3d translation(0.3, -1.2, 2.0);
  const Positions moved = (x * rotation.transpose()).rowwise() + translation;
  const Positions expected = (p.apply(x) * rotation.transpose()).rowwise() + translation;
  EXPECT_LT((p.apply(moved) - expected).cwiseAbs().maxCoeff(), 1e-13);
}

TEST(ShellProlongation, JacobianTransposeMatchesFiniteDifferences) {
  const ScatteredTargets s = scattered_targets(120, 4);
  const ShellProlongation p(s.coarse, s.locations, s.rest);
  const Positions x = s.coarse.vertices + 0.05 * Positions::Random(s.coarse.vertex_count(), 3);
  const Eigen::VectorXd g = Eigen::VectorXd::Random(3 * p.target_count());
  const auto objective = [&](const Eigen::VectorXd& y) {
    return g.dot(flat(p.apply(as_positions(y))));
  };
  const Eigen::VectorXd x_flat = flat(x);
  const Eigen::VectorXd expected = test::fd_gradient(objective, x_flat, 1e-6);
  EXPECT_LT(test::relative_error(p.apply_jacobian_transpose(x, g), expected), 1e-7);
}

TEST(ShellProlongation, StaysFiniteOnACollapsedTriangle) {
  const ScatteredTargets s = scattered_targets(60, 5);
  const ShellProlongation p(s.coarse, s.locations, s.rest);
  Positions x = s.coarse.vertices;
  // Collapse the triangle of target 0 onto a line, then onto a point.
  const auto tri = s.coarse.triangles.row(s.locations[0].triangle);
  x.row(tri(2)) = 0.5 * (x.row(tri(0)) + x.row(tri(1)));
  const Eigen::VectorXd g = Eigen::VectorXd::Ones(3 * p.target_count());
  EXPECT_TRUE(p.apply(x).allFinite());
  EXPECT_TRUE(p.apply_jacobian_transpose(x, g).allFinite());
  x.row(tri(1)) = x.row(tri(0));
  x.row(tri(2)) = x.row(tri(0));
  EXPECT_TRUE(p.apply(x).allFinite());
  EXPECT_TRUE(p.apply_jacobian_transpose(x, g).allFinite());
}

TEST(ShellProlongation, RejectsInvalidLocations) {
  ScatteredTargets s = scattered_targets(10, 6);
  s.locations[3].triangle = s.coarse.triangle_count();
  EXPECT_THROW(ShellProlongation(s.coarse, s.locations, s.rest), InputError);
  s = scattered_targets(10, 6);
  s.locations[2].barycentric = Eigen::Vector3d(0.7, 0.7, -0.4);
  EXPECT_THROW(ShellProlongation(s.coarse, s.locations, s.rest), InputError);
  s = scattered_targets(10, 6);
  EXPECT_THROW(ShellProlongation(s.coarse, s.locations, s.rest.topRows(9)), InputError);
}

TEST(TriangleFrame, RotationIsThePolarFactorOfTheDeformationGradient) {
  RestTriangleFrame rest;
  ASSERT_TRUE(rest_triangle_frame({0, 0, 0}, {1, 0.2, 0}, {0.3, 0.9, 0.1}, rest));
  const Eigen::Vector3d x0(0.1, 0.2, 0.3), x1(1.4, 0.1, 0.5), x2(0.2, 1.1, -0.2);
  const DeformedTriangleFrame frame = deformed_triangle_frame(x0, x1, x2, rest.b_inverse);
  Matrix32d f;
  f << x1 - x0, x2 - x0;
  f = f * rest.b_inverse;
  // Independent check: R = F (FᵀF)^{-1/2} via a general eigen-solver.
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eigen(f.transpose() * f);
  const Matrix32d expected = f * eigen.operatorInverseSqrt();
  EXPECT_LT((frame.rotation - expected).norm(), 1e-13);
  EXPECT_LT((frame.rotation.col(0).cross(frame.rotation.col(1)) - frame.normal).norm(), 1e-13);
  EXPECT_LT((frame.normal - (x1 - x0).cross(x2 - x0).normalized()).norm(), 1e-14);
}

}  // namespace
}  // namespace psq
