#include "engine/core/psd_projection.hpp"

#include <Eigen/Eigenvalues>

namespace psq {
namespace {

template <class Symmetric>
void clamp_negative_eigenvalues(Symmetric& symmetric) {
  Eigen::SelfAdjointEigenSolver<typename Symmetric::PlainObject> eig(symmetric);
  const auto& lambda = eig.eigenvalues();
  if (lambda.minCoeff() >= 0.0) return;
  symmetric =
      eig.eigenvectors() * lambda.cwiseMax(0.0).asDiagonal() * eig.eigenvectors().transpose();
}

}  // namespace

void project_to_psd(Eigen::Ref<Eigen::MatrixXd> symmetric) {
  clamp_negative_eigenvalues(symmetric);
}

void project_to_psd(Eigen::Matrix<double, 12, 12>& symmetric) {
  clamp_negative_eigenvalues(symmetric);
}

}  // namespace psq
