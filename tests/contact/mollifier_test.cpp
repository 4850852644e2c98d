#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <random>

#include "engine/contact/edge_edge_mollifier.hpp"
#include "support/derivative_check.hpp"
#include "support/random_geometry.hpp"

namespace psq {
namespace {

using Eigen::Vector3d;
using Eigen::VectorXd;

StencilDerivatives<12> cross_norm_of(const VectorXd& x) {
  return edge_edge_cross_squared_norm(x.segment<3>(0), x.segment<3>(3), x.segment<3>(6),
                                      x.segment<3>(9));
}

/// Edges of lengths la and lb at angle θ, in a generic position.
VectorXd edges_at_angle(double theta, double la, double lb, std::mt19937& rng) {
  const Vector3d u = test::random_point(rng).normalized();
  const Vector3d w = u.cross(test::random_point(rng)).normalized();
  const Vector3d v = std::cos(theta) * u + std::sin(theta) * w;
  const Vector3d ea0 = test::random_point(rng);
  const Vector3d eb0 = test::random_point(rng);
  VectorXd x(12);
  x << ea0, ea0 + la * u, eb0, eb0 + lb * v;
  return x;
}

TEST(EdgeEdgeMollifier, ThresholdIsAThousandthOfTheRestEdgeLengthsSquaredProduct) {
  const Vector3d o(0.5, -1, 2);
  EXPECT_DOUBLE_EQ(
      edge_edge_mollifier_threshold(o, o + Vector3d(0, 2, 0), o, o + Vector3d(0, 0, 3)),
      1e-3 * 4 * 9);
}

TEST(EdgeEdgeMollifier, RisesFromZeroToOneAndStaysThere) {
  const double eps = 0.036;
  EXPECT_EQ(edge_edge_mollifier(0, eps), 0);
  EXPECT_DOUBLE_EQ(edge_edge_mollifier(eps / 2, eps), 0.75);
  EXPECT_EQ(edge_edge_mollifier(eps, eps), 1);
  EXPECT_EQ(edge_edge_mollifier(3 * eps, eps), 1);
  EXPECT_EQ(edge_edge_mollifier_first_derivative(3 * eps, eps), 0);
  EXPECT_EQ(edge_edge_mollifier_second_derivative(3 * eps, eps), 0);
  double previous = 0;
  for (int i = 1; i <= 100; ++i) {
    const double m = edge_edge_mollifier(eps * i / 100, eps);
    EXPECT_GT(m, previous);
    previous = m;
  }
  // C¹ at the threshold: the slope from below tends to the zero slope above.
  EXPECT_NEAR(edge_edge_mollifier_first_derivative(eps * (1 - 1e-9), eps), 0, 1e-6 / eps);
}

TEST(EdgeEdgeMollifier, ScalarDerivativesMatchFiniteDifferences) {
  const double eps = 0.036, h = 1e-7 * eps;
  for (double c : {0.01 * eps, 0.3 * eps, 0.8 * eps}) {
    const double fd1 =
        (edge_edge_mollifier(c + h, eps) - edge_edge_mollifier(c - h, eps)) / (2 * h);
    const double fd2 = (edge_edge_mollifier_first_derivative(c + h, eps) -
                        edge_edge_mollifier_first_derivative(c - h, eps)) /
                       (2 * h);
    EXPECT_NEAR(edge_edge_mollifier_first_derivative(c, eps), fd1, 1e-6 * std::abs(fd1));
    EXPECT_NEAR(edge_edge_mollifier_second_derivative(c, eps), fd2, 1e-6 * std::abs(fd2));
  }
}

TEST(EdgeEdgeMollifier, CrossNormIsTheSquaredSineScaledByTheLengths) {
  std::mt19937 rng(3);
  for (double theta : {0.0, 1e-3, 0.4, 1.2, M_PI / 2}) {
    const double la = 1.3, lb = 0.7;
    const StencilDerivatives<12> c = cross_norm_of(edges_at_angle(theta, la, lb, rng));
    const double expected = la * la * lb * lb * std::sin(theta) * std::sin(theta);
    EXPECT_NEAR(c.value, expected, 1e-14 * la * la * lb * lb) << "θ = " << theta;
  }
}

TEST(EdgeEdgeMollifier, CrossNormDerivativesMatchFiniteDifferences) {
  std::mt19937 rng(4);
  for (double theta : {1e-3, 0.4, 1.2}) {
    const VectorXd x = edges_at_angle(theta, 1.1, 0.8, rng);
    const test::DerivativeErrors errors = test::derivative_errors(cross_norm_of, x, 1e-6);
    EXPECT_LT(errors.gradient, 1e-7) << "θ = " << theta;
    EXPECT_LT(errors.hessian, 1e-7) << "θ = " << theta;
  }
}

TEST(EdgeEdgeMollifier, MollifierOfTheStencilMatchesFiniteDifferencesBelowTheThreshold) {
  std::mt19937 rng(5);
  const double la = 1.1, lb = 0.8;
  const double eps = 1e-3 * la * la * lb * lb;
  const auto mollifier = [eps](const VectorXd& y) {
    return edge_edge_mollifier(y.segment<3>(0), y.segment<3>(3), y.segment<3>(6), y.segment<3>(9),
                               eps);
  };
  for (double theta : {0.005, 0.015, 0.025}) {  // sin²θ below 1e-3: mollified
    const VectorXd x = edges_at_angle(theta, la, lb, rng);
    const StencilDerivatives<12> m = mollifier(x);
    ASSERT_LT(m.value, 1);
    ASSERT_GT(m.value, 0);
    const test::DerivativeErrors errors = test::derivative_errors(mollifier, x, 1e-7);
    EXPECT_LT(errors.gradient, 1e-6) << "θ = " << theta;
    EXPECT_LT(errors.hessian, 1e-6) << "θ = " << theta;
  }
}

TEST(EdgeEdgeMollifier, IsExactlyOneForEdgesFarFromParallel) {
  std::mt19937 rng(6);
  const StencilDerivatives<12> m = [&] {
    const VectorXd x = edges_at_angle(0.5, 1, 1, rng);
    return edge_edge_mollifier(x.segment<3>(0), x.segment<3>(3), x.segment<3>(6), x.segment<3>(9),
                               1e-3);
  }();
  EXPECT_EQ(m.value, 1);
  EXPECT_EQ(m.gradient.norm(), 0);
  EXPECT_EQ(m.hessian.norm(), 0);
}

}  // namespace
}  // namespace psq
