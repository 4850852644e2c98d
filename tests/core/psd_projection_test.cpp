#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>

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

TEST(PsdProjection, FixedSizeBlocksProjectLikeDynamicOnes) {
  const Eigen::MatrixXd a = Eigen::MatrixXd::Random(12, 12);
  Eigen::Matrix<double, 12, 12> fixed = a + a.transpose();
  Eigen::MatrixXd dynamic = fixed;
  ASSERT_LT(Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(dynamic).eigenvalues().minCoeff(), 0.0);
  project_to_psd(fixed);
  project_to_psd(dynamic);
  EXPECT_LT((fixed - dynamic).norm(), 1e-12 * dynamic.norm());
  EXPECT_GT(Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(Eigen::MatrixXd(fixed))
                .eigenvalues()
                .minCoeff(),
            -1e-12 * dynamic.norm());
}

}  // namespace
}  // namespace psq
