#pragma once
#include <Eigen/Core>
#include <array>

namespace psq {

/// Replaces a symmetric matrix by its closest positive semi-definite matrix (negative
/// eigenvalues clamped to zero), so Newton directions stay descent directions.
void project_to_psd(Eigen::Ref<Eigen::MatrixXd> symmetric);

/// The same projection for the 12×12 Hessian of a function of four points that a common
/// translation leaves unchanged (a contact pair's barrier: distances and the edge-edge
/// mollifier). Such a Hessian maps every translation to zero, so in an orthonormal basis that
/// splits the translations off it is 0 ⊕ R with R of size 3(m − 1), m the number of points it
/// depends on (those whose rows are not all zero: 2 for a point-point distance, 3 for a
/// point-edge one). Projection commutes with an orthogonal change of basis, so projecting R
/// gives the full projection up to rounding, with an eigensolver of at most 9×9 instead of
/// 12×12 (its speed-up: docs/benchmarks.md).
void project_translation_invariant_to_psd(Eigen::Matrix<double, 12, 12>& hessian);

/// Such a 12×12 Hessian as a solve that holds the `fixed` points sees it: their rows and
/// columns zeroed and the block of the points that move projected. The system never holds the
/// fixed rows, so projecting the whole block would clamp curvature against motions the solve
/// cannot make, and would cost a 9×9 eigensolver where a point against a triangle of a fixed
/// collider needs a 3×3 one. The moving block is not translation invariant once a point is
/// fixed, so it is projected as it is. With no point fixed: project_translation_invariant_to_psd.
void project_moving_block_to_psd(Eigen::Matrix<double, 12, 12>& hessian,
                                 const std::array<bool, 4>& fixed);

}  // namespace psq
