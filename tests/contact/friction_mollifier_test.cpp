#include "engine/contact/friction_mollifier.hpp"

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <cmath>

#include "support/finite_difference.hpp"

namespace psq {
namespace {

using Eigen::VectorXd;
using test::fd_gradient;
using test::fd_jacobian;
using test::relative_error;

constexpr double kEps = 1e-3;

TEST(FrictionMollifier, MeetsTheSlidingLawContinuouslyAtTheThreshold) {
  // f₀(0) = ε/3 (the formula's constant), f₀(ε) = ε from both sides; f₁ reaches 1 at ε and
  // f₁′ reaches 0, so the ramp joins the sliding law with value, slope and curvature.
  EXPECT_NEAR(friction_mollifier(0, kEps), kEps / 3, 1e-18);
  // Just below ε the ramp differs from y only at third order in ε − y.
  EXPECT_NEAR(friction_mollifier(kEps * (1 - 1e-9), kEps), kEps * (1 - 1e-9), 1e-18);
  EXPECT_EQ(friction_mollifier(kEps, kEps), kEps);
  EXPECT_NEAR(friction_mollifier_derivative(kEps * (1 - 1e-9), kEps), 1, 1e-8);
  EXPECT_NEAR(friction_mollifier_second_derivative(kEps * (1 - 1e-9), kEps), 0, 1e-5 / kEps);
  for (double y : {2 * kEps, 10 * kEps, 1.0}) {
    EXPECT_EQ(friction_mollifier(y, kEps), y);
    EXPECT_EQ(friction_mollifier_derivative(y, kEps), 1);
    EXPECT_EQ(friction_mollifier_second_derivative(y, kEps), 0);
  }
}

TEST(FrictionMollifier, DerivativesMatchFiniteDifferencesOnBothBranches) {
  for (double y : {0.1 * kEps, 0.5 * kEps, 0.9 * kEps, 1.5 * kEps, 20 * kEps}) {
    const double h = 1e-6 * kEps;
    const double df = (friction_mollifier(y + h, kEps) - friction_mollifier(y - h, kEps)) / (2 * h);
    EXPECT_NEAR(friction_mollifier_derivative(y, kEps), df, 1e-7) << y;
    const double d2f =
        (friction_mollifier_derivative(y + h, kEps) - friction_mollifier_derivative(y - h, kEps)) /
        (2 * h);
    EXPECT_NEAR(friction_mollifier_second_derivative(y, kEps), d2f, 1e-6 / kEps) << y;
    EXPECT_NEAR(friction_mollifier_derivative_over_norm(y, kEps) * y,
                friction_mollifier_derivative(y, kEps), 1e-15);
  }
  // f₁/y stays finite at 0, with the slope of the ramp there: f₁(y) ≈ 2y/ε.
  EXPECT_EQ(friction_mollifier_derivative_over_norm(0, kEps), 2 / kEps);
}

TEST(FrictionMollifier, GradientAndHessianOfTheNormMatchFiniteDifferences) {
  const auto f = [](const VectorXd& u) {
    return friction_mollifier(Eigen::Vector2d(u).norm(), kEps);
  };
  const auto g = [](const VectorXd& u) -> VectorXd {
    return friction_mollifier_gradient(Eigen::Vector2d(u), kEps);
  };
  for (double scale : {0.05, 0.4, 0.95, 1.3, 7.0}) {
    const VectorXd u = scale * kEps * Eigen::Vector2d(0.6, -0.8);
    const double h = 1e-7 * kEps;
    EXPECT_LT(relative_error(g(u), fd_gradient(f, u, h)), 1e-7) << scale;
    const Eigen::Matrix2d hessian = friction_mollifier_hessian(Eigen::Vector2d(u), kEps);
    EXPECT_LT(relative_error(hessian, fd_jacobian(g, u, h)), 1e-6) << scale;
  }
}

TEST(FrictionMollifier, HessianIsTheRampStiffnessAtRestAndPositiveSemiDefinite) {
  // Near u = 0 the gradient is (2/ε − ‖u‖/ε²) u: its Jacobian at 0 is (2/ε) I.
  EXPECT_LT(relative_error(friction_mollifier_hessian(Eigen::Vector2d::Zero(), kEps),
                           (2 / kEps) * Eigen::Matrix2d::Identity()),
            1e-15);
  for (int i = 0; i < 200; ++i) {
    const Eigen::Vector2d u = 3 * kEps * Eigen::Vector2d::Random();
    const Eigen::Matrix2d hessian = friction_mollifier_hessian(u, kEps);
    EXPECT_GE(Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d>(hessian).eigenvalues().minCoeff(),
              -1e-12 / kEps);
  }
}

}  // namespace
}  // namespace psq
