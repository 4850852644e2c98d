#include "engine/core/psd_projection.hpp"

#include <Eigen/Eigenvalues>

namespace psq {

void project_to_psd(Eigen::Ref<Eigen::MatrixXd> symmetric) {
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(symmetric);
  const Eigen::VectorXd& lambda = eig.eigenvalues();
  if (lambda.minCoeff() >= 0.0) return;
  const Eigen::VectorXd clamped = lambda.cwiseMax(0.0);
  symmetric = eig.eigenvectors() * clamped.asDiagonal() * eig.eigenvectors().transpose();
}

}  // namespace psq
