#include "engine/elastic/dihedral_angle.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>
#include <utility>
#include <vector>

#include "elastic/elastic_test_meshes.hpp"
#include "engine/core/error.hpp"
#include "support/finite_difference.hpp"

namespace psq {
namespace {

using test::fd_gradient;
using test::fd_jacobian;
using test::relative_error;

Eigen::VectorXd as_vector(const HingePositions& x) { return x.reshaped(); }
HingePositions as_hinge(const Eigen::VectorXd& v) { return v.reshaped(3, 4); }

TEST(DihedralAngle, EqualsTheConstructedFoldAngle) {
  std::mt19937 rng(1);
  for (double fold : test::kFolds)
    EXPECT_NEAR(dihedral_angle(test::folded_hinge(fold, rng)), fold, 1e-12);
}

TEST(DihedralAngle, ChangesSignWhenTheMeshOrientationIsReversed) {
  // Reversing both triangles turns face 0 into (x1, x0, x2): the hinge becomes (x1, x0, x2, x3).
  std::mt19937 rng(2);
  for (double fold : test::kFolds) {
    const HingePositions x = test::folded_hinge(fold, rng);
    HingePositions reversed;
    reversed << x.col(1), x.col(0), x.col(2), x.col(3);
    EXPECT_NEAR(dihedral_angle(reversed), -fold, 1e-12);
  }
}

TEST(DihedralAngle, GradientMatchesFiniteDifferences) {
  std::mt19937 rng(3);
  for (double fold : test::kFolds) {
    const HingePositions x = test::folded_hinge(fold, rng);
    const Eigen::VectorXd fd = fd_gradient(
        [](const Eigen::VectorXd& v) { return dihedral_angle(as_hinge(v)); }, as_vector(x), 1e-6);
    EXPECT_LT(relative_error(dihedral_angle_gradient(x), fd), 1e-6) << "fold " << fold;
  }
}

TEST(DihedralAngle, HessianMatchesFiniteDifferencesOfTheGradient) {
  std::mt19937 rng(4);
  for (double fold : test::kFolds) {
    const HingePositions x = test::folded_hinge(fold, rng);
    const Eigen::MatrixXd fd = fd_jacobian(
        [](const Eigen::VectorXd& v) -> Eigen::VectorXd {
          return dihedral_angle_gradient(as_hinge(v));
        },
        as_vector(x), 1e-6);
    EXPECT_LT(relative_error(dihedral_angle_hessian(x), fd), 1e-6) << "fold " << fold;
  }
}

TEST(DihedralAngle, GradientIsOrthogonalToRigidMotions) {
  // θ is invariant under translations (Σ g_i = 0) and rotations (Σ x_i × g_i = 0).
  std::mt19937 rng(5);
  for (double fold : test::kFolds) {
    const HingePositions x = test::folded_hinge(fold, rng);
    const HingeVector g = dihedral_angle_gradient(x);
    Eigen::Vector3d force = Eigen::Vector3d::Zero(), torque = Eigen::Vector3d::Zero();
    for (int i = 0; i < 4; ++i) {
      force += g.segment<3>(3 * i);
      torque += x.col(i).cross(g.segment<3>(3 * i));
    }
    EXPECT_LT(force.norm(), 1e-12 * g.norm());
    EXPECT_LT(torque.norm(), 1e-12 * g.norm() * x.norm());
  }
}

TEST(DihedralAngle, ExpansionOfTheRelativeHessianAnnihilatesTranslations) {
  const HingeRelativeMatrix a = HingeRelativeMatrix::Random();
  const HingeRelativeMatrix relative = a + a.transpose();
  const HingeMatrix h = expand_translation_invariant(relative);
  EXPECT_TRUE((h.bottomRightCorner<9, 9>() == relative));
  for (int axis = 0; axis < 3; ++axis) {
    HingeVector translation = HingeVector::Zero();
    for (int i = 0; i < 4; ++i) translation[3 * i + axis] = 1.0;
    EXPECT_LT((h * translation).norm(), 1e-12 * h.norm());
  }
  EXPECT_LT((h - h.transpose()).norm(), 1e-14 * h.norm());
}

TEST(DihedralAngle, DegenerateHingeHasNoDerivatives) {
  HingePositions x;
  x.col(0) << 0, 0, 0;
  x.col(1) << 1, 0, 0;
  x.col(2) << 0.5, 0, 0;  // face 0 collapsed onto the edge
  x.col(3) << 0.5, -1, 0;
  EXPECT_TRUE(is_degenerate_hinge(x));
  EXPECT_EQ(dihedral_angle(x), 0.0);
  EXPECT_THROW(dihedral_angle_gradient(x), NumericalError);
  EXPECT_THROW(dihedral_angle_relative_hessian(x), NumericalError);
  EXPECT_THROW(dihedral_angle_and_gradient(x), NumericalError);
  EXPECT_FALSE(regular_dihedral_angle(x).has_value());
}

TEST(DihedralAngle, FusedEvaluationsEqualTheSeparateOnes) {
  // One hinge frame shared by angle and gradient gives bit for bit the same numbers.
  std::mt19937 rng(6);
  for (double fold : test::kFolds) {
    const HingePositions x = test::folded_hinge(fold, rng);
    const auto [angle, gradient] = dihedral_angle_and_gradient(x);
    EXPECT_EQ(angle, dihedral_angle(x));
    EXPECT_TRUE((gradient == dihedral_angle_gradient(x)));
    ASSERT_TRUE(regular_dihedral_angle(x).has_value());
    EXPECT_EQ(*regular_dihedral_angle(x), dihedral_angle(x));
  }
}

}  // namespace
}  // namespace psq

namespace psq {
namespace {

// angle_difference has the value of std::remainder(θ − θ̄, 2π) for angles in [−π, π] (== also
// equates −0 and +0, which it returns for θ − θ̄ = −2π): at the wrap points ±π, just past them,
// and on random pairs.
TEST(AngleDifference, EqualsTheRemainderOfTheDifference) {
  const double pi = std::numbers::pi;
  std::vector<std::pair<double, double>> pairs{
      {pi, 0.0},  {-pi, 0.0}, {pi, -pi},  {-pi, pi},  {0.0, pi},  {0.0, -pi},
      {3.0, -3.0}, {-3.0, 3.0}, {pi, -1e-300}, {std::nextafter(pi, 0.0), -pi}, {1e-17, -1e-17}};
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> angle(-pi, pi);
  for (int i = 0; i < 100000; ++i) pairs.emplace_back(angle(rng), angle(rng));
  for (const auto& [theta, rest] : pairs) {
    const double expected = std::remainder(theta - rest, 2.0 * pi);
    const double actual = angle_difference(theta, rest);
    ASSERT_EQ(expected, actual) << "θ = " << theta << ", θ̄ = " << rest << ": " << expected << " vs " << actual;
  }
}

}  // namespace
}  // namespace psq
