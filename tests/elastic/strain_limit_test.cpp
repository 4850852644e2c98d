#include "engine/elastic/strain_limit.hpp"

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <cmath>
#include <limits>
#include <string>

#include "engine/core/error.hpp"
#include "support/finite_difference.hpp"

namespace psq {
namespace {

using Eigen::Vector2d;
using Eigen::Vector3d;
using Eigen::VectorXd;
using test::fd_gradient;
using test::fd_jacobian;
using test::relative_error;

constexpr double kInfinity = std::numeric_limits<double>::infinity();
const StrainLimitBand kBand{1.05, 1.0};
constexpr double kStiffness = 3.0;

/// A scalene rest triangle in the plane z = 0.
TrianglePositions rest_triangle() {
  TrianglePositions x;
  x << 0, 1.0, 0.3, 0, 0.1, 0.8, 0, 0, 0;
  return x;
}

/// The rest triangle deformed so that its deformation gradient has singular values σ₁, σ₂:
/// x = M X with M's in-plane columns Q [diag(σ); 0] W, Q and W rotations (the rest frame of
/// the membrane is an isometry of the plane, so F = M₂ R has the same singular values).
TrianglePositions stretched(double s1, double s2) {
  const Eigen::Matrix3d q = Eigen::AngleAxisd(0.7, Vector3d(1, -2, 0.5).normalized()).matrix();
  const Eigen::Matrix2d w = Eigen::Rotation2Dd(0.4).matrix();
  Eigen::Matrix<double, 3, 2> m2 = Eigen::Matrix<double, 3, 2>::Zero();
  m2(0, 0) = s1;
  m2(1, 1) = s2;
  m2 = q * m2 * w;
  const TrianglePositions rest = rest_triangle();
  return m2 * rest.topRows<2>() + Vector3d(0.2, -0.1, 0.4).replicate<1, 3>();
}

TEST(StrainLimitBarrier, IsZeroBelowTheBandInfiniteAtTheLimitAndConvexBetween) {
  for (double s : {0.5, 1.0}) {
    EXPECT_EQ(strain_limit_barrier(s, kBand), 0);
    EXPECT_EQ(strain_limit_barrier_first_derivative(s, kBand), 0);
    EXPECT_EQ(strain_limit_barrier_second_derivative(s, kBand), 0);
  }
  EXPECT_EQ(strain_limit_barrier(1.05, kBand), kInfinity);
  EXPECT_EQ(strain_limit_barrier(1.2, kBand), kInfinity);
  // At r = 1/e: g = (1 − 1/e)².
  EXPECT_NEAR(strain_limit_barrier(1.05 - 0.05 / M_E, kBand), std::pow(1 - 1 / M_E, 2), 1e-14);
  double previous = 0;
  for (int i = 1; i < 100; ++i) {
    const double s = 1.0 + 0.05 * i / 100;
    const double g = strain_limit_barrier(s, kBand);
    EXPECT_GT(g, previous);
    EXPECT_GT(strain_limit_barrier_first_derivative(s, kBand), 0);
    EXPECT_GT(strain_limit_barrier_second_derivative(s, kBand), 0);
    const double h = 1e-7;
    EXPECT_NEAR(strain_limit_barrier_first_derivative(s, kBand),
                (strain_limit_barrier(s + h, kBand) - strain_limit_barrier(s - h, kBand)) / (2 * h),
                1e-6 * (1 + strain_limit_barrier_first_derivative(s, kBand)));
    EXPECT_NEAR(strain_limit_barrier_second_derivative(s, kBand),
                (strain_limit_barrier_first_derivative(s + h, kBand) -
                 strain_limit_barrier_first_derivative(s - h, kBand)) /
                    (2 * h),
                1e-5 * (1 + strain_limit_barrier_second_derivative(s, kBand)));
    previous = g;
  }
}

TEST(StrainLimit, PrincipalStretchesAreTheConstructedSingularValues) {
  const MembraneRest rest = membrane_rest(rest_triangle());
  const Vector2d sigma = principal_stretches(deformation_gradient(stretched(1.04, 0.9), rest));
  EXPECT_NEAR(sigma[0], 1.04, 1e-14);
  EXPECT_NEAR(sigma[1], 0.9, 1e-14);
}

/// FD check of one triangle's energy, gradient and Hessian at stretches (σ₁, σ₂).
void expect_derivatives_match(double s1, double s2) {
  SCOPED_TRACE("sigma " + std::to_string(s1) + ", " + std::to_string(s2));
  const MembraneRest rest = membrane_rest(rest_triangle());
  const VectorXd x = stretched(s1, s2).reshaped();
  const auto value = [&](const VectorXd& y) {
    return strain_limit_triangle_energy(y.reshaped(3, 3), rest, kBand, kStiffness);
  };
  const auto gradient = [&](const VectorXd& y) -> VectorXd {
    return strain_limit_triangle_gradient(y.reshaped(3, 3), rest, kBand, kStiffness);
  };
  const double h = 1e-7;
  EXPECT_LT(relative_error(gradient(x), fd_gradient(value, x, h)), 1e-6);
  const TriangleMatrix hessian =
      strain_limit_triangle_hessian(x.reshaped(3, 3), rest, kBand, kStiffness, false);
  EXPECT_TRUE(hessian.allFinite());
  EXPECT_LT(relative_error(hessian, fd_jacobian(gradient, x, h)), 1e-5);
  // The exact Hessian is already PSD in the band: projecting leaves it (nearly) unchanged.
  const TriangleMatrix projected =
      strain_limit_triangle_hessian(x.reshaped(3, 3), rest, kBand, kStiffness, true);
  EXPECT_LT(relative_error(projected, hessian), 1e-12);
  EXPECT_GE(Eigen::SelfAdjointEigenSolver<TriangleMatrix>(projected).eigenvalues().minCoeff(),
            -1e-10 * projected.norm());
}

TEST(StrainLimit, DerivativesMatchFiniteDifferencesInTheBand) {
  expect_derivatives_match(1.04, 1.02);   // both stretches in the band
  expect_derivatives_match(1.045, 0.97);  // one in the band, one compressed
  expect_derivatives_match(1.049, 0.3);   // close to the limit, with a thin triangle
  expect_derivatives_match(1.03, 1.01);
}

TEST(StrainLimit, DerivativesStayFiniteAndCorrectAtRepeatedStretches) {
  expect_derivatives_match(1.03, 1.03);
  expect_derivatives_match(1.03 + 1e-9, 1.03);
  expect_derivatives_match(1.03 + 1e-5, 1.03);
}

TEST(StrainLimit, VanishesBelowTheBandAndIsInfiniteBeyondTheLimit) {
  const MembraneRest rest = membrane_rest(rest_triangle());
  EXPECT_EQ(strain_limit_triangle_energy(stretched(0.99, 0.8), rest, kBand, kStiffness), 0);
  EXPECT_TRUE(
      strain_limit_triangle_gradient(stretched(1.0, 0.8), rest, kBand, kStiffness).isZero());
  EXPECT_EQ(strain_limit_triangle_energy(stretched(1.06, 1.0), rest, kBand, kStiffness), kInfinity);
  EXPECT_THROW(strain_limit_triangle_gradient(stretched(1.06, 1.0), rest, kBand, kStiffness),
               NumericalError);
}

TEST(StrainLimit, FeasibleStepStopsJustShortOfTheLimit) {
  const MembraneRest rest = membrane_rest(rest_triangle());
  const TrianglePositions x = rest_triangle();
  // Stretching by 20% along x in one step: σ₁(α) = 1 + 0.2α reaches 1.05 at α = 1/4.
  TrianglePositions dx = TrianglePositions::Zero();
  dx.row(0) = 0.2 * x.row(0);
  const double alpha = strain_limit_feasible_step(x, dx, rest, kBand.limit);
  EXPECT_LT(alpha, 0.25);
  EXPECT_NEAR(alpha, 0.25, 1e-11);
  const double sigma = principal_stretches(deformation_gradient(x + alpha * dx, rest))[0];
  EXPECT_LT(sigma, kBand.limit);
  EXPECT_GT(sigma, kBand.limit - 1e-11);
  // A step that stays below the limit is not cut.
  EXPECT_EQ(strain_limit_feasible_step(x, 0.2 * dx, rest, kBand.limit), 1);
  // Linearized rotation by a quarter turn: the path shrinks the triangle midway, ends
  // unstretched, and by convexity never passes the limit in between.
  const Eigen::Matrix3d quarter = Eigen::AngleAxisd(M_PI / 2, Vector3d::UnitZ()).matrix();
  const TrianglePositions turn = quarter * x - x;
  EXPECT_EQ(strain_limit_feasible_step(x, turn, rest, kBand.limit), 1);
  for (int i = 0; i <= 20; ++i)
    EXPECT_LT(principal_stretches(deformation_gradient(x + 0.05 * i * turn, rest))[0], kBand.limit);
  EXPECT_THROW(strain_limit_feasible_step(stretched(1.06, 1), dx, rest, kBand.limit),
               NumericalError);
}

/// Two triangles sharing an edge: a unit square split along its diagonal.
TriMesh square() {
  TriMesh mesh;
  mesh.vertices.resize(4, 3);
  mesh.vertices << 0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0;
  mesh.triangles.resize(2, 3);
  mesh.triangles << 0, 1, 2, 0, 2, 3;
  return mesh;
}

TEST(StrainLimitEnergy, SumsItsTrianglesInsideALargerPositionVector) {
  const TriMesh mesh = square();
  const StrainLimitEnergy energy(mesh, kBand, kStiffness, 1);
  // Vertex 0 of the global vector is another shell's; stretch vertex 2 of the square (global
  // 3) along the diagonal and vertex 1 (global 2) along x.
  VectorXd x = VectorXd::Zero(15);
  x.segment<3>(0) = Vector3d(5, 5, 5);
  for (int v = 0; v < 4; ++v) x.segment<3>(3 * (v + 1)) = mesh.vertices.row(v).transpose();
  x.segment<3>(6) += Vector3d(0.03, 0, 0.01);
  x.segment<3>(9) += Vector3d(0.02, 0.025, 0);
  const auto value = [&](const VectorXd& y) { return energy.value(y); };
  const auto gradient = [&](const VectorXd& y) {
    VectorXd g = VectorXd::Zero(15);
    energy.add_gradient(y, g);
    return g;
  };
  EXPECT_GT(energy.value(x), 0);
  const VectorXd g = gradient(x);
  EXPECT_TRUE(g.head<3>().isZero());
  EXPECT_LT(relative_error(g, fd_gradient(value, x, 1e-7)), 1e-6);
  ElementMatrices blocks;
  energy.hessian(x, blocks);
  Eigen::MatrixXd hessian = Eigen::MatrixXd::Zero(15, 15);
  for (std::size_t e = 0; e < blocks.element_count(); ++e)
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < 3; ++b)
        hessian.block<3, 3>(3 * blocks.vertices[3 * e + a], 3 * blocks.vertices[3 * e + b]) +=
            blocks.block(e).block<3, 3>(3 * a, 3 * b);
  EXPECT_LT(relative_error(hessian, fd_jacobian(gradient, x, 1e-7)), 1e-5);
  // Stretching the whole square by 3% along x gives both triangles σ₁ = 1.03.
  VectorXd uniform = VectorXd::Zero(15);
  for (int v = 0; v < 4; ++v) {
    uniform.segment<3>(3 * (v + 1)) = mesh.vertices.row(v).transpose();
    uniform[3 * (v + 1)] *= 1.03;
  }
  EXPECT_NEAR(energy.min_slack(uniform), kBand.limit - 1.03, 1e-14);
}

TEST(StrainLimitEnergy, HessianHoldsOnlyTrianglesInsideTheBand) {
  const TriMesh mesh = square();
  const StrainLimitEnergy energy(mesh, kBand, kStiffness);
  VectorXd x = mesh.vertices.transpose().reshaped();
  ElementMatrices blocks;
  energy.hessian(x, blocks);
  EXPECT_EQ(blocks.element_count(), 0);  // at rest nothing is active
  x[3] += 0.03;                          // vertex 1 only belongs to the first triangle
  energy.hessian(x, blocks);
  ASSERT_EQ(blocks.element_count(), 1);
  EXPECT_EQ(blocks.vertices, (std::vector<int>{0, 1, 2}));
}

TEST(StrainLimitEnergy, MaxFeasibleStepIsTheTightestTriangle) {
  const TriMesh mesh = square();
  const StrainLimitEnergy energy(mesh, kBand, kStiffness);
  const VectorXd x = mesh.vertices.transpose().reshaped();
  // Pull vertex 1 right by 0.4 and vertex 3 up by 0.1: the first triangle reaches the limit
  // first, and the line search's first trial must stop short of it.
  VectorXd dx = VectorXd::Zero(12);
  dx[3] = 0.4;
  dx[10] = 0.1;
  const double alpha = energy.max_feasible_step(x, dx);
  EXPECT_GT(alpha, 0);
  EXPECT_LT(alpha, 1);
  const VectorXd trial = x + alpha * dx;
  EXPECT_LT(energy.value(trial), kInfinity);
  EXPECT_GT(energy.min_slack(trial), 0);
  EXPECT_LT(energy.min_slack(trial), 1e-10);
  EXPECT_EQ(energy.value(x + std::min(1.0, alpha + 1e-9) * dx), kInfinity);
  EXPECT_EQ(energy.max_feasible_step(x, 0.01 * dx), 1);
}

TEST(StrainLimitStiffness, DoublesOnlyWhileTheTightestTriangleStaysAtTheLimit) {
  const double tight = 1e-6;  // below 1e-4 δ = 5e-6
  const double loose = 1e-3;
  EXPECT_EQ(update_strain_limit_stiffness(10, tight, tight, kBand, 1e3), 20);
  EXPECT_EQ(update_strain_limit_stiffness(10, loose, tight, kBand, 1e3), 10);
  EXPECT_EQ(update_strain_limit_stiffness(10, tight, loose, kBand, 1e3), 10);
  EXPECT_EQ(update_strain_limit_stiffness(800, tight, tight, kBand, 1e3), 1e3);
  EXPECT_NEAR(initial_strain_limit_stiffness(2e3, kBand), 2e3 * 0.05 * 0.05, 1e-12);
}

TEST(StrainLimitEnergy, RejectsBadParameters) {
  const TriMesh mesh = square();
  EXPECT_THROW(StrainLimitEnergy(mesh, {0.98, 1.0}, kStiffness), InputError);
  EXPECT_THROW(StrainLimitEnergy(mesh, {1.05, 0.0}, kStiffness), InputError);
  EXPECT_THROW(StrainLimitEnergy(mesh, kBand, 0), InputError);
  TriMesh degenerate = mesh;
  degenerate.vertices.row(2) = degenerate.vertices.row(1);
  EXPECT_THROW(StrainLimitEnergy(degenerate, kBand, kStiffness), InputError);
  const StrainLimitEnergy energy(mesh, kBand, kStiffness);
  VectorXd x = mesh.vertices.transpose().reshaped();
  x[2] = std::nan("");
  EXPECT_THROW(static_cast<void>(energy.value(x)), NumericalError);
}

}  // namespace
}  // namespace psq
