#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <array>
#include <cstdlib>
#include <vector>

#include "engine/core/psd_projection.hpp"

namespace psq {
namespace {

TEST(PsdProjection, ClampsNegativeEigenvaluesAndKeepsEigenvectors) {
  // Q diag(3, -2, 1) Qᵀ with a random orthogonal Q projects to Q diag(3, 0, 1) Qᵀ.
  const Eigen::Matrix3d q = Eigen::HouseholderQR<Eigen::Matrix3d>(Eigen::Matrix3d::Random()).householderQ();
  Eigen::MatrixXd m = q * Eigen::Vector3d(3, -2, 1).asDiagonal() * q.transpose();
  project_to_psd(m);
  const Eigen::Matrix3d expected = q * Eigen::Vector3d(3, 0, 1).asDiagonal() * q.transpose();
  EXPECT_LT((m - expected).norm(), 1e-12);
}

TEST(PsdProjection, LeavesPositiveSemiDefiniteMatricesUnchanged) {
  const Eigen::MatrixXd a = Eigen::MatrixXd::Random(6, 10);
  Eigen::MatrixXd m = a * a.transpose();
  const Eigen::MatrixXd before = m;
  project_to_psd(m);
  EXPECT_EQ(m, before);
}

/// D, which maps the 12 coordinates of four points to the positions of the given points
/// relative to the first of them.
Eigen::MatrixXd relative_positions(const std::vector<int>& points) {
  const int n = 3 * (static_cast<int>(points.size()) - 1);
  Eigen::MatrixXd differences = Eigen::MatrixXd::Zero(n, 12);
  for (int k = 1; k < static_cast<int>(points.size()); ++k)
    for (int axis = 0; axis < 3; ++axis) {
      differences(3 * (k - 1) + axis, 3 * points[k] + axis) = 1;
      differences(3 * (k - 1) + axis, 3 * points[0] + axis) = -1;
    }
  return differences;
}

/// The Hessian Dᵀ A D of a function of those relative positions, with A a random symmetric
/// matrix: translation-invariant, and indefinite for most A.
Eigen::Matrix<double, 12, 12> translation_invariant_hessian(const std::vector<int>& points,
                                                            unsigned seed) {
  std::srand(seed);
  const Eigen::MatrixXd differences = relative_positions(points);
  const Eigen::MatrixXd a = Eigen::MatrixXd::Random(differences.rows(), differences.rows());
  return differences.transpose() * (a + a.transpose()) * differences;
}

double smallest_eigenvalue(const Eigen::MatrixXd& m) {
  return Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(m).eigenvalues().minCoeff();
}

TEST(PsdProjection, TranslationInvariantBlocksProjectLikeTheFullEigensolver) {
  // Four points, and the fewer a point-point or point-edge distance depends on (in any slots).
  const std::vector<std::vector<int>> cases = {{0, 1, 2, 3}, {0, 2, 3}, {1, 3}, {3, 0, 1}};
  unsigned seed = 1;
  for (const std::vector<int>& points : cases) {
    Eigen::Matrix<double, 12, 12> reduced = translation_invariant_hessian(points, seed++);
    Eigen::MatrixXd full = reduced;
    ASSERT_LT(smallest_eigenvalue(full), -1e-3 * full.norm());
    project_translation_invariant_to_psd(reduced);
    project_to_psd(full);
    EXPECT_LT((reduced - full).norm(), 1e-12 * full.norm()) << points.size() << " points";
    EXPECT_GT(smallest_eigenvalue(reduced), -1e-12 * full.norm());
  }
}

TEST(PsdProjection, TranslationInvariantPositiveSemiDefiniteBlocksStayUnchanged) {
  const Eigen::MatrixXd a = Eigen::MatrixXd::Random(9, 9);
  const Eigen::MatrixXd differences = relative_positions({0, 1, 2, 3});
  Eigen::Matrix<double, 12, 12> m = differences.transpose() * a * a.transpose() * differences;
  const Eigen::Matrix<double, 12, 12> before = m;
  project_translation_invariant_to_psd(m);
  EXPECT_EQ(m, before);
}

TEST(PsdProjection, MovingBlocksProjectLikeTheFullEigensolverOnTheMovingRows) {
  // The solve never sees a fixed point's rows: the reference zeroes them, then projects all 12.
  struct Case {
    std::vector<int> points;
    std::array<bool, 4> fixed;
  };
  const std::vector<Case> cases = {
      {{0, 1, 2, 3}, {false, true, true, true}},   // a point against a collider's triangle
      {{0, 1, 2, 3}, {false, false, true, true}},  // a shell edge against a collider's edge
      {{0, 1, 2, 3}, {true, false, false, false}},  // a pinned point against a shell triangle
      {{0, 2, 3}, {false, true, true, false}},      // a point against a collider's edge
      {{1, 3}, {false, false, false, true}}};      // a point against a collider's vertex
  unsigned seed = 11;
  for (const Case& c : cases) {
    Eigen::Matrix<double, 12, 12> moving = translation_invariant_hessian(c.points, seed++);
    for (int p = 0; p < 4; ++p)
      if (c.fixed[p]) {
        moving.middleRows<3>(3 * p).setZero();
        moving.middleCols<3>(3 * p).setZero();
      }
    Eigen::MatrixXd full = moving;
    ASSERT_LT(smallest_eigenvalue(full), -1e-3 * full.norm());
    moving = translation_invariant_hessian(c.points, seed - 1);
    project_moving_block_to_psd(moving, c.fixed);
    project_to_psd(full);
    EXPECT_LT((moving - full).norm(), 1e-12 * full.norm()) << c.points.size() << " points";
  }
}

TEST(PsdProjection, MovingBlocksWithNothingFixedProjectAsTranslationInvariantOnes) {
  Eigen::Matrix<double, 12, 12> moving = translation_invariant_hessian({0, 1, 2, 3}, 7);
  Eigen::Matrix<double, 12, 12> invariant = moving;
  // A fixed point the pair does not depend on fixes nothing.
  Eigen::Matrix<double, 12, 12> unused = translation_invariant_hessian({0, 1, 2}, 8);
  Eigen::Matrix<double, 12, 12> unused_reference = unused;
  project_moving_block_to_psd(moving, {false, false, false, false});
  project_translation_invariant_to_psd(invariant);
  EXPECT_EQ(moving, invariant);
  project_moving_block_to_psd(unused, {false, false, false, true});
  project_translation_invariant_to_psd(unused_reference);
  EXPECT_EQ(unused, unused_reference);
}

TEST(PsdProjection, MovingBlocksOfFixedPointsOnlyVanish) {
  Eigen::Matrix<double, 12, 12> m = translation_invariant_hessian({0, 1, 2, 3}, 9);
  project_moving_block_to_psd(m, {true, true, true, true});
  EXPECT_TRUE(m.isZero(0.0));
}

}  // namespace
}  // namespace psq
