#include "engine/core/psd_projection.hpp"

#include <Eigen/Eigenvalues>
#include <array>
#include <cmath>

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

/// Orthonormal basis (columns) of the motions of the given points with no common translation:
/// Helmert's contrasts, column block k − 1 moving points 0..k−1 by 1/√(k(k+1)) and point k by
/// −k/√(k(k+1)), each along one axis.
Eigen::Matrix<double, 12, Eigen::Dynamic, 0, 12, 9> relative_motion_basis(
    const std::array<int, 4>& points, int count) {
  Eigen::Matrix<double, 12, Eigen::Dynamic, 0, 12, 9> basis =
      Eigen::Matrix<double, 12, Eigen::Dynamic, 0, 12, 9>::Zero(12, 3 * (count - 1));
  for (int k = 1; k < count; ++k) {
    const double scale = 1.0 / std::sqrt(double(k) * (k + 1));
    for (int axis = 0; axis < 3; ++axis) {
      const int column = 3 * (k - 1) + axis;
      for (int j = 0; j < k; ++j) basis(3 * points[j] + axis, column) = scale;
      basis(3 * points[k] + axis, column) = -k * scale;
    }
  }
  return basis;
}

}  // namespace

void project_to_psd(Eigen::Ref<Eigen::MatrixXd> symmetric) {
  clamp_negative_eigenvalues(symmetric);
}

void project_translation_invariant_to_psd(Eigen::Matrix<double, 12, 12>& hessian) {
  std::array<int, 4> points{};
  int count = 0;
  for (int p = 0; p < 4; ++p)
    if (!hessian.middleRows<3>(3 * p).isZero(0.0)) points[count++] = p;
  // One point alone cannot move relative to anything: its block is zero but for rounding.
  if (count < 2) {
    hessian.setZero();
    return;
  }
  const auto basis = relative_motion_basis(points, count);
  Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, 9, 9> relative =
      basis.transpose() * hessian * basis;
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, 9, 9>>
      eig(relative);
  const auto& lambda = eig.eigenvalues();
  if (lambda.minCoeff() >= 0.0) return;
  const auto modes = (basis * eig.eigenvectors()).eval();
  hessian = modes * lambda.cwiseMax(0.0).asDiagonal() * modes.transpose();
}

}  // namespace psq
