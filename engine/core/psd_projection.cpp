#include "engine/core/psd_projection.hpp"

#include <Eigen/Eigenvalues>
#include <array>
#include <cmath>

namespace psq {
namespace {

/// Clamps the negative eigenvalues of `symmetric` to zero; returns whether there were any (a
/// positive semi-definite matrix is left exactly as it was).
template <class Symmetric>
bool clamp_negative_eigenvalues(Symmetric& symmetric) {
  Eigen::SelfAdjointEigenSolver<typename Symmetric::PlainObject> eig(symmetric);
  const auto& lambda = eig.eigenvalues();
  if (lambda.minCoeff() >= 0.0) return false;
  symmetric =
      eig.eigenvectors() * lambda.cwiseMax(0.0).asDiagonal() * eig.eigenvectors().transpose();
  return true;
}

/// Orthonormal basis (columns) of the motions of the given points with no common translation:
/// Helmert's contrasts, column block k − 1 moving points 0..k−1 by 1/√(k(k+1)) and point k by
/// −k/√(k(k+1)), each along one axis. Fixed sizes, so that Eigen's products are unrolled
/// rather than run through its general matrix kernel.
template <int Relative>
Eigen::Matrix<double, 12, Relative> relative_motion_basis(const std::array<int, 4>& points) {
  Eigen::Matrix<double, 12, Relative> basis = Eigen::Matrix<double, 12, Relative>::Zero();
  for (int k = 1; k <= Relative / 3; ++k) {
    const double scale = 1.0 / std::sqrt(double(k) * (k + 1));
    for (int axis = 0; axis < 3; ++axis) {
      const int column = 3 * (k - 1) + axis;
      for (int j = 0; j < k; ++j) basis(3 * points[j] + axis, column) = scale;
      basis(3 * points[k] + axis, column) = -k * scale;
    }
  }
  return basis;
}

/// Projects `hessian` through its block R over the relative motions of `points`.
template <int Relative>
void project_relative_block(Eigen::Matrix<double, 12, 12>& hessian,
                            const std::array<int, 4>& points) {
  const Eigen::Matrix<double, 12, Relative> basis = relative_motion_basis<Relative>(points);
  Eigen::Matrix<double, Relative, Relative> relative = basis.transpose() * hessian * basis;
  if (clamp_negative_eigenvalues(relative)) hessian = basis * relative * basis.transpose();
}

/// Projects the block of `hessian` over the `Size / 3` given points, zeroing every other entry.
template <int Size>
void project_point_block(Eigen::Matrix<double, 12, 12>& hessian, const std::array<int, 4>& points) {
  constexpr int kPoints = Size / 3;
  Eigen::Matrix<double, Size, Size> block;
  for (int a = 0; a < kPoints; ++a)
    for (int b = 0; b < kPoints; ++b)
      block.template block<3, 3>(3 * a, 3 * b) = hessian.block<3, 3>(3 * points[a], 3 * points[b]);
  clamp_negative_eigenvalues(block);
  hessian.setZero();
  for (int a = 0; a < kPoints; ++a)
    for (int b = 0; b < kPoints; ++b)
      hessian.block<3, 3>(3 * points[a], 3 * points[b]) = block.template block<3, 3>(3 * a, 3 * b);
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
  switch (count) {
    case 2: project_relative_block<3>(hessian, points); break;
    case 3: project_relative_block<6>(hessian, points); break;
    default: project_relative_block<9>(hessian, points); break;
  }
}

void project_moving_block_to_psd(Eigen::Matrix<double, 12, 12>& hessian,
                                 const std::array<bool, 4>& fixed) {
  std::array<int, 4> moving{};
  int count = 0;
  bool holds_one = false;
  for (int p = 0; p < 4; ++p) {
    // A point the pair does not depend on (its rows are zero) needs no row in the projection.
    if (hessian.middleRows<3>(3 * p).isZero(0.0)) continue;
    if (fixed[p])
      holds_one = true;
    else
      moving[count++] = p;
  }
  if (!holds_one) {
    project_translation_invariant_to_psd(hessian);
    return;
  }
  switch (count) {
    case 0: hessian.setZero(); break;
    case 1: project_point_block<3>(hessian, moving); break;
    case 2: project_point_block<6>(hessian, moving); break;
    default: project_point_block<9>(hessian, moving); break;
  }
}

}  // namespace psq
