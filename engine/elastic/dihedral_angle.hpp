#pragma once
// Signed dihedral angle of a hinge (two triangles sharing an edge) and its first and second
// derivatives with respect to the four vertex positions.

#include <Eigen/Core>
#include <numbers>
#include <optional>

namespace psq {

/// Positions of a hinge's vertices as columns: x0 = v0, x1 = v1 (the shared edge),
/// x2 = opposite0, x3 = opposite1. Face 0 is (x0, x1, x2), face 1 is (x1, x0, x3), both in
/// their own orientation (see Hinge in engine/mesh/topology.hpp).
using HingePositions = Eigen::Matrix<double, 3, 4>;
using HingeVector = Eigen::Matrix<double, 12, 1>;
using HingeMatrix = Eigen::Matrix<double, 12, 12>;
/// Derivatives with respect to (x1, x2, x3) with x0 held fixed.
using HingeRelativeVector = Eigen::Matrix<double, 9, 1>;
using HingeRelativeMatrix = Eigen::Matrix<double, 9, 9>;

/// θ = atan2(ê·(n0 × n1), n0·n1) ∈ (−π, π], with n0 = (x1−x0)×(x2−x0) and
/// n1 = (x3−x0)×(x1−x0) the face normals and ê the unit edge x0→x1. θ = 0 for a flat hinge;
/// θ > 0 when the faces bend away from their normals (a sphere with outward normals).
/// Returns 0 when the edge or a face normal is exactly zero, where θ is undefined.
double dihedral_angle(const HingePositions& x);

/// θ − θ̄ for two dihedral angles in [−π, π], wrapped to [−π, π]: the value of
/// std::remainder(θ − θ̄, 2π) (for |θ − θ̄| in (π, 2π] the shift by 2π is exact, Sterbenz; only
/// the sign of a zero at θ − θ̄ = ±2π differs), without its cost: remainder took 3.2% of the
/// samples of `perf record ./build/tests/bench_progressive --scenes twist --preview-only 1`.
inline double angle_difference(double theta, double rest_theta) {
  constexpr double pi = std::numbers::pi;
  const double d = theta - rest_theta;
  if (d > pi) return d - 2.0 * pi;
  if (d < -pi) return d + 2.0 * pi;
  return d;
}

/// True when the edge has zero length or a face is collapsed (the sine of its angle at x0 is
/// below 1e-12, so its normal is rounding noise): θ is meaningless and has no derivatives.
bool is_degenerate_hinge(const HingePositions& x);

/// ∇θ (12 entries, vertex by vertex). With heights h_i = |n_i|/|e| of the opposite vertices
/// and α_i = (x_{2+i} − x0)·e/|e|² the position of their foot points along the edge:
///   ∂θ/∂x2 = −n0/(h0|n0|),  ∂θ/∂x3 = −n1/(h1|n1|),
///   ∂θ/∂x1 = −α0 ∂θ/∂x2 − α1 ∂θ/∂x3,  ∂θ/∂x0 = −(∂θ/∂x1 + ∂θ/∂x2 + ∂θ/∂x3).
/// Throws NumericalError for a degenerate hinge (is_degenerate_hinge).
HingeVector dihedral_angle_gradient(const HingePositions& x);

/// θ and ∇θ from one evaluation of the hinge's edge and normals (a bending gradient needs both).
/// Throws NumericalError for a degenerate hinge.
struct DihedralAngleAndGradient {
  double angle;
  HingeVector gradient;
};
DihedralAngleAndGradient dihedral_angle_and_gradient(const HingePositions& x);

/// θ, or nothing for a degenerate hinge (is_degenerate_hinge), from one evaluation of the
/// hinge's edge and normals.
std::optional<double> regular_dihedral_angle(const HingePositions& x);

/// ∂²θ/∂(x1,x2,x3)² with x0 fixed: the differential of the gradient formulas above
/// (normals n_i/|n_i|², edge length and foot parameters α_i differentiated in closed form).
/// θ is translation invariant, so this 9×9 block determines the full Hessian.
/// Throws NumericalError for a degenerate hinge.
HingeRelativeMatrix dihedral_angle_relative_hessian(const HingePositions& x);

/// ∇²θ (12×12), the expansion of dihedral_angle_relative_hessian.
HingeMatrix dihedral_angle_hessian(const HingePositions& x);

/// The 12×12 Hessian of a translation-invariant function f(x0..x3) = f̃(x1−x0, x2−x0, x3−x0)
/// from its 9×9 Hessian with x0 fixed: H = Tᵀ H̃ T with T = [−I I 0 0; −I 0 I 0; −I 0 0 I].
/// H is PSD exactly when H̃ is, which lets hinge terms project the smaller matrix.
HingeMatrix expand_translation_invariant(const HingeRelativeMatrix& relative);

}  // namespace psq
